// The event and error log: the daemon's `event` notifications (every client sees every error),
// what errors.list kept from before this page connected, and the refusals of this page's own
// requests, which also pop up as a toast.

import {$, el, fmtTime, toast} from './ui.js';

const kMaxEntries = 500;

export class EventLog {
  constructor(rpc) {
    this.rpc = rpc;
    this.box = $('#log');
    this.lastSeq = 0;
    rpc.on('event', (event) => this.daemonEvent(event));
    rpc.on(
        'connection.closing',
        (params) => this.add('warning', 'connection', params?.reason ?? 'closing'));
    rpc.on('error', (error) => this.add('error', 'rpc', error?.message ?? 'error'));
    $('#log-clear')?.addEventListener('click', () => this.box.replaceChildren());
  }

  // Fetches what happened while this page was away; seq numbers keep an event from showing twice.
  async catchUp() {
    try {
      const result = await this.rpc.call('errors.list', {since: this.lastSeq});
      for (const event of result.events ?? [])
        this.daemonEvent(event);
    } catch (e) {
      this.add('error', 'errors.list', e.message);
    }
  }

  daemonEvent(event) {
    if (!event || typeof event.seq !== 'number' || event.seq <= this.lastSeq) return;
    this.lastSeq = event.seq;
    this.add(event.level ?? 'info', event.kind ?? '', event.message ?? '', event.time);
  }

  add(level, kind, message, time = Date.now() / 1000) {
    const entry =
        el('div', {class: `log-entry log-${level}`, dataset: {level, kind}},
           el('span', {class: 'log-time'}, fmtTime(time)), el('span', {class: 'log-kind'}, kind),
           el('span', {class: 'log-message'}, message));
    const atBottom = this.box.scrollTop + this.box.clientHeight >= this.box.scrollHeight - 4;
    this.box.append(entry);
    while (this.box.children.length > kMaxEntries)
      this.box.firstChild.remove();
    if (atBottom) this.box.scrollTop = this.box.scrollHeight;
  }

  // A request this page made was refused: say why, where the operator looks and in the log.
  refused(method, error) {
    const message = `${method}: ${error.message}`;
    this.add('error', 'refused', message);
    toast(message, 'error');
  }
}
