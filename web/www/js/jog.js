// Jogging: continuous (press and hold a button or a key) and incremental, at a chosen speed.
// A continuous jog is kept alive by a jog.heartbeat every 100 ms while something is held; when
// the page stops sending them (tab closed, network lost, browser frozen) cncd-web and the daemon
// stop the jog on their own. Here it stops on release, on leaving the button, on a cancelled
// pointer, when the window loses focus and when the page is hidden. Keys: web/www/KEYS.md.

import {$, applyGate, el} from './ui.js';

const kHeartbeatMs = 100;
export const kJogKeys = {
  ArrowRight: ['X', 1],
  ArrowLeft: ['X', -1],
  ArrowUp: ['Y', 1],
  ArrowDown: ['Y', -1],
  PageUp: ['Z', 1],
  PageDown: ['Z', -1],
};

export function setupJog(ctx) {
  const jog = new Jogger(ctx);
  ctx.jogger = jog;
  buildPad(ctx, jog, ['X', 'Y', 'Z']);
  ctx.on('info', (info) => buildPad(ctx, jog, info?.machine?.axes ?? ['X', 'Y', 'Z']));
  ctx.on('connection', (up) => {
    if (!up) jog.forget();
  });
  ctx.store.subscribe((status) => {
    const speed = $('#jog-speed');
    if (!speed.dataset.touched && status.units) {
      speed.value = status.units === 'inch' ? '20' : '500';
      speed.dataset.touched = 'units';
    }
    setText('#jog-units', `${status.units ?? ''}/min`);
  });
  $('#jog-speed').addEventListener('change', (event) => (event.target.dataset.touched = 'user'));
  $('#jog-mode').addEventListener('change', () => {
    jog.stopAll();
    document.body.classList.toggle('jog-increment', $('#jog-mode').value === 'increment');
  });

  window.addEventListener('blur', () => jog.stopAll());
  document.addEventListener('visibilitychange', () => {
    if (document.hidden) jog.stopAll();
  });
  window.addEventListener('pagehide', () => jog.stopAll());
  document.addEventListener('keydown', (event) => {
    if (event.key === 'Escape') {
      jog.stopAll();
      return;
    }
    const map = kJogKeys[event.key];
    if (!map || !keyboardJogging(event)) return;
    event.preventDefault();
    if (event.repeat) return;
    if ($('#jog-mode').value === 'increment')
      jog.increment(map[0], map[1]);
    else
      jog.start(map[0], map[1], `key:${event.key}`);
  });
  document.addEventListener('keyup', (event) => {
    const map = kJogKeys[event.key];
    if (!map) return;
    jog.stopSource(`key:${event.key}`);
  });
}

function setText(selector, text) {
  const node = $(selector);
  if (node && node.textContent !== text) node.textContent = text;
}

// Keys jog unless the operator types somewhere (MDI, a table cell) or turned them off.
function keyboardJogging(event) {
  if (!$('#jog-keys').checked) return false;
  if (event.ctrlKey || event.altKey || event.metaKey) return false;
  const target = event.target;
  return !(
      target instanceof HTMLElement &&
      target.closest('input, textarea, select, [contenteditable]'));
}

function buildPad(ctx, jog, axes) {
  const pad = $('#jog-pad');
  if (pad.dataset.axes === axes.join()) return;
  pad.dataset.axes = axes.join();
  const buttons = [];
  for (const letter of axes) {
    for (const [sign, dir] of [['minus', -1], ['plus', 1]]) {
      const a = letter.toLowerCase();
      const button =
          el('button', {
            id: `jog-${a}-${sign}`,
            class: 'jog-button',
            type: 'button',
            dataset: {method: 'jog.start', axis: letter, dir: String(dir)},
            style: `grid-area: ${a}${sign}`
          },
             `${letter}${dir > 0 ? '+' : '−'}`);
      const stop = () => jog.stopSource(`button:${button.id}`);
      button.addEventListener('pointerdown', (event) => {
        if (event.button !== 0 || button.disabled) return;
        event.preventDefault();
        if ($('#jog-mode').value === 'increment')
          jog.increment(letter, dir);
        else
          jog.start(letter, dir, `button:${button.id}`);
      });
      for (const type of ['pointerup', 'pointerleave', 'pointercancel', 'lostpointercapture']) {
        button.addEventListener(type, stop);
      }
      button.addEventListener('contextmenu', (event) => event.preventDefault());
      buttons.push(button);
    }
  }
  pad.replaceChildren(...buttons);
  pad.classList.toggle('xyz', axes.join() === 'X,Y,Z');
  applyGate(pad);
}

class Jogger {
  constructor(ctx) {
    this.ctx = ctx;
    this.active = new Map();  // axis -> source holding it
    this.timer = null;
  }

  velocity(dir) {
    const perMinute = Number($('#jog-speed').value);
    return (dir * (Number.isFinite(perMinute) && perMinute > 0 ? perMinute : 100)) / 60;
  }

  start(axis, dir, source) {
    if (this.active.has(axis)) return;
    this.active.set(axis, source);
    this.beat();
    this.ctx.call('jog.start', {axis, velocity: this.velocity(dir)}).catch(() => {
      if (this.active.get(axis) === source) this.active.delete(axis);
      this.beat();
    });
    document.getElementById(source.slice('button:'.length))?.classList.add('held');
  }

  increment(axis, dir) {
    const distance = Number($('#jog-increment').value);
    this.ctx.run(
        'jog.increment', {axis, distance: dir * distance, velocity: Math.abs(this.velocity(1))});
  }

  stopSource(source) {
    for (const [axis, holder] of this.active) {
      if (holder === source) this.stop(axis);
    }
  }

  stop(axis) {
    const source = this.active.get(axis);
    if (source === undefined) return;
    this.active.delete(axis);
    if (source.startsWith('button:'))
      document.getElementById(source.slice(7))?.classList.remove('held');
    this.beat();
    this.ctx.run('jog.stop', {axis});
  }

  stopAll() {
    for (const axis of [...this.active.keys()])
      this.stop(axis);
  }

  // The connection went: cncd-web stops its jogs when the WebSocket closes.
  forget() {
    this.active.clear();
    for (const node of document.querySelectorAll('.jog-button.held'))
      node.classList.remove('held');
    this.beat();
  }

  // Heartbeats run while any jog is held, and only then.
  beat() {
    if (this.active.size > 0 && this.timer === null) {
      this.timer = setInterval(() => {
        this.ctx.rpc.call('jog.heartbeat', {}).catch(() => {});
      }, kHeartbeatMs);
    } else if (this.active.size === 0 && this.timer !== null) {
      clearInterval(this.timer);
      this.timer = null;
    }
  }
}
