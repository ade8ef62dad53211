// JSON-RPC 2.0 over the /ws WebSocket: request ids, answers matched by id (they may come in
// another order than the requests), notifications to listeners, and reconnection with back-off.
// Large frames (a toolpath preview is several MiB) are parsed and decoded by a worker so that
// the DRO and the estop button keep answering meanwhile.

const kLargeFrame = 256 * 1024;

export class RpcError extends Error {
  constructor(method, error) {
    super(error?.message ?? String(error));
    this.method = method;
    this.code = error?.code;
  }
}

export class RpcClient {
  constructor(url) {
    this.url = url;
    this.ws = null;
    this.nextId = 1;
    this.pending = new Map();    // id -> {resolve, reject, method}
    this.listeners = new Map();  // notification method -> [fn]
    this.onOpen = [];
    this.onClose = [];
    this.retryMs = 500;
    this.worker = null;
    this.workerJobs = 0;
    this.stopped = false;
  }

  on(method, fn) {
    if (!this.listeners.has(method)) this.listeners.set(method, []);
    this.listeners.get(method).push(fn);
  }

  get connected() { return this.ws !== null && this.ws.readyState === WebSocket.OPEN; }

  connect() {
    this.stopped = false;
    const ws = new WebSocket(this.url);
    this.ws = ws;
    ws.addEventListener('open', () => {
      this.retryMs = 500;
      for (const fn of this.onOpen)
        fn();
    });
    ws.addEventListener('message', (event) => this.receive(event.data));
    ws.addEventListener('close', (event) => {
      if (this.ws !== ws) return;
      this.ws = null;
      for (const [, p] of this.pending)
        p.reject(new RpcError(p.method, {code: -1, message: 'connection lost'}));
      this.pending.clear();
      for (const fn of this.onClose)
        fn(event);
      if (this.stopped) return;
      setTimeout(() => this.connect(), this.retryMs);
      this.retryMs = Math.min(this.retryMs * 2, 5000);
    });
  }

  close() {
    this.stopped = true;
    this.ws?.close();
  }

  // Resolves with the result, rejects with an RpcError carrying the daemon's (or cncd-web's)
  // code and message.
  call(method, params) {
    if (!this.connected) {
      return Promise.reject(new RpcError(method, {code: -1, message: 'not connected to cncd-web'}));
    }
    const id = this.nextId++;
    const request = {jsonrpc: '2.0', id, method};
    if (params !== undefined) request.params = params;
    return new Promise((resolve, reject) => {
      this.pending.set(id, {resolve, reject, method});
      this.ws.send(JSON.stringify(request));
    });
  }

  // A notification to the server (no answer expected): the jog heartbeat.
  notify(method, params) {
    if (!this.connected) return;
    const request = {jsonrpc: '2.0', method};
    if (params !== undefined) request.params = params;
    this.ws.send(JSON.stringify(request));
  }

  receive(text) {
    if (typeof text !== 'string') return;
    if (text.length >= kLargeFrame) {
      this.parseInWorker(text);
      return;
    }
    let message;
    try {
      message = JSON.parse(text);
    } catch (e) {
      console.warn('cncd-web sent a frame that is not JSON', e);
      return;
    }
    this.dispatch(message);
  }

  dispatch(message) {
    if (Array.isArray(message)) {
      for (const m of message)
        this.dispatch(m);
      return;
    }
    if (message.id !== undefined && message.id !== null &&
        (message.result !== undefined || message.error)) {
      const p = this.pending.get(message.id);
      if (!p) return;
      this.pending.delete(message.id);
      if (message.error)
        p.reject(new RpcError(p.method, message.error));
      else
        p.resolve(message.result);
      return;
    }
    if (message.error) {
      // An error without an id (-32700, a refused connection): nobody waits for it by id.
      for (const fn of this.listeners.get('error') ?? [])
        fn(message.error);
      return;
    }
    for (const fn of this.listeners.get(message.method) ?? [])
      fn(message.params);
  }

  parseInWorker(text) {
    if (this.worker === null) {
      this.worker = new Worker(new URL('./decode_worker.js', import.meta.url), {type: 'module'});
      this.worker.addEventListener('message', (event) => this.dispatch(event.data));
      this.worker.addEventListener(
          'error', (event) => console.error('decode worker:', event.message));
    }
    this.worker.postMessage(text);
  }
}

// ws:// or wss:// to this page's own host, as the server checks the Origin against it.
export function wsUrl() {
  const scheme = location.protocol === 'https:' ? 'wss:' : 'ws:';
  return `${scheme}//${location.host}/ws`;
}
