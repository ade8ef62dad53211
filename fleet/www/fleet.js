// The fleet page: cncd-fleet's table of machines, kept current over /ws. Every text from a
// machine (its name, program, alarm) goes into the page as text, never as markup, and a link
// is made only of an http:// or https:// URL.
const rows = new Map();  // machine id -> {tr, cells, row}
const tbody = document.getElementById('rows');
const link = document.getElementById('link');
const filter = document.getElementById('filter');

const CELLS = ['name', 'online', 'state', 'program', 'progress', 'remaining', 'parts', 'alarm'];

function el(tag, cls, text) {
  const e = document.createElement(tag);
  if (cls) e.className = cls;
  if (text !== undefined) e.textContent = text;
  return e;
}

function safeLink(url) {
  if (typeof url !== 'string') return null;
  try {
    const u = new URL(url);
    return u.protocol === 'http:' || u.protocol === 'https:' ? u.href : null;
  } catch (e) {
    return null;
  }
}

function duration(seconds) {
  if (typeof seconds !== 'number' || !isFinite(seconds) || seconds < 0) return '';
  const s = Math.round(seconds);
  const h = Math.floor(s / 3600), m = Math.floor((s % 3600) / 60), r = s % 60;
  const two = n => String(n).padStart(2, '0');
  return h > 0 ? `${h}:${two(m)}:${two(r)}` : `${m}:${two(r)}`;
}

function clock(unix) {
  if (typeof unix !== 'number' || !isFinite(unix)) return '';
  const d = new Date(unix * 1000);
  const today = new Date();
  return d.toDateString() === today.toDateString() ? d.toLocaleTimeString() : d.toLocaleString();
}

// What the row says of the machine, in one word, and its colour (data-status).
function status(m) {
  if (m.online === 'offline') return ['offline', 'offline'];
  if (m.cncd === 'unreachable') return ['away', 'cncd away'];
  if (m.state === 'estop') return ['estop', 'estop'];
  if (m.exec === 'running') return ['running', 'running'];
  if (m.exec === 'paused') return ['paused', 'paused'];
  if (m.state === 'off') return ['off', 'off'];
  if (m.state === 'on') return ['idle', m.exec ? `on · ${m.exec}` : 'on'];
  return ['unknown', m.state || '–'];
}

function make(id) {
  const tr = el('tr', 'machine');
  tr.dataset.id = id;
  const cells = {};
  for (const name of CELLS) {
    cells[name] = el('td', name);
    tr.appendChild(cells[name]);
  }
  return {tr, cells, row: null};
}

function fill(entry, m) {
  const c = entry.cells;
  entry.row = m;
  const [key, word] = status(m);
  entry.tr.dataset.status = key;
  c.name.replaceChildren(el('span', 'title', m.name));
  const href = safeLink(m.dashboard);
  if (href) {
    const a = el('a', 'dashboard', 'dashboard ↗');
    a.href = href;
    a.target = '_blank';
    a.rel = 'noopener noreferrer';
    c.name.appendChild(a);
  }
  if (m.name !== m.id) c.name.appendChild(el('div', 'id', m.id));
  c.online.textContent = m.online || 'unknown';
  c.online.dataset.online = m.online || 'unknown';
  c.state.textContent = word;
  const program = typeof m.program === 'string' ? m.program : '';
  c.program.textContent = program.split('/').pop();
  c.program.title = program;
  const running = m.exec === 'running' || m.exec === 'paused';
  const progress = typeof m.progress === 'number' ? Math.max(0, Math.min(1, m.progress)) : null;
  if (progress !== null && (running || progress > 0)) {
    const bar = el('div', 'bar');
    const fillBar = el('div');
    fillBar.style.width = `${(progress * 100).toFixed(1)}%`;
    bar.appendChild(fillBar);
    c.progress.replaceChildren(bar, el('span', 'pct', `${Math.round(progress * 100)} %`));
  } else {
    c.progress.replaceChildren();
  }
  c.remaining.textContent = running ? duration(m.remaining_s) : '';
  c.parts.textContent = typeof m.parts === 'number' ? String(m.parts) : '';
  const alarm = m.alarm;
  if (alarm && typeof alarm.message === 'string') {
    c.alarm.replaceChildren(el('span', 'when', clock(alarm.time)),
                            el('span', 'text', alarm.message));
    c.alarm.title = alarm.message;
  } else {
    c.alarm.replaceChildren();
    c.alarm.title = '';
  }
  applyFilter(entry);
}

function applyFilter(entry) {
  const q = filter.value.trim().toLowerCase();
  const m = entry.row;
  entry.tr.hidden = q !== '' && !`${m.name} ${m.id} ${m.program || ''}`.toLowerCase().includes(q);
}

function place() {
  const sorted = [...rows.values()].sort((a, b) =>
    a.row.name.localeCompare(b.row.name) || a.row.id.localeCompare(b.row.id));
  sorted.forEach((entry, i) => {
    if (tbody.children[i] !== entry.tr) tbody.insertBefore(entry.tr, tbody.children[i] || null);
  });
  document.getElementById('empty').hidden = rows.size > 0;
  const count = key => sorted.filter(e => e.tr.dataset.status === key).length;
  document.getElementById('count-machines').textContent = rows.size;
  document.getElementById('count-running').textContent = count('running');
  document.getElementById('count-estop').textContent = count('estop');
  document.getElementById('count-offline').textContent = count('offline');
}

function update(machines, removed) {
  for (const m of machines) {
    if (!m || typeof m.id !== 'string') continue;
    if (typeof m.name !== 'string') m.name = m.id;
    let entry = rows.get(m.id);
    if (!entry) rows.set(m.id, entry = make(m.id));
    fill(entry, m);
  }
  for (const id of removed || []) {
    const entry = rows.get(id);
    if (entry) {
      entry.tr.remove();
      rows.delete(id);
    }
  }
  place();
}

function setLink(state, text) {
  link.dataset.state = state;
  link.textContent = text;
}

let retry = 1000;
function connect() {
  const scheme = location.protocol === 'https:' ? 'wss://' : 'ws://';
  const ws = new WebSocket(scheme + location.host + '/ws');
  ws.onopen = () => { retry = 1000; };
  ws.onmessage = e => {
    const msg = JSON.parse(e.data);
    if (msg.type === 'snapshot') {
      for (const entry of rows.values()) entry.tr.remove();
      rows.clear();
      update(msg.machines || [], []);
      setLink(msg.broker && msg.broker.connected ? 'open' : 'broker-away',
              msg.broker && msg.broker.connected ? 'live' : 'broker away');
    } else if (msg.type === 'update') {
      update(msg.machines || [], msg.removed || []);
    } else if (msg.type === 'broker') {
      setLink(msg.connected ? 'open' : 'broker-away', msg.connected ? 'live' : 'broker away');
    }
    window.fleetFrames = (window.fleetFrames || 0) + 1;
  };
  ws.onclose = () => {
    setLink('closed', 'reconnecting');
    setTimeout(connect, retry);
    retry = Math.min(retry * 2, 30000);
  };
}

filter.addEventListener('input', () => rows.forEach(applyFilter));
connect();
