// The DRO (work and machine position, on a machine with TCP the tool tip in the part's frame
// and the TCP state, distance to go), velocity, active codes, tool, spindle, coolant, and the
// override sliders.

import {$, el, fmt, setText} from './ui.js';

export function setupDro(ctx) {
  buildAxes(ctx, ['X', 'Y', 'Z']);
  ctx.on('info', (info) => buildAxes(ctx, info?.machine?.axes ?? ['X', 'Y', 'Z']));
  for (const name of ['feed', 'rapid', 'spindle'])
    setupOverride(ctx, name);
  ctx.store.subscribe((status) => showDro(ctx, status));
}

function buildAxes(ctx, axes) {
  if (ctx.droAxes?.join() === axes.join()) return;
  ctx.droAxes = axes;
  const body = $('#dro-rows');
  body.replaceChildren(...axes.map((letter) => {
    const a = letter.toLowerCase();
    return el(
        'tr', {class: 'dro-row', dataset: {axis: a}}, el('th', {class: 'dro-axis'}, letter),
        el('td', {id: `dro-${a}`, class: 'dro-work'}, '—'),
        el('td', {id: `dro-mach-${a}`, class: 'dro-mach'}, '—'),
        el('td', {id: `dro-tip-${a}`, class: 'dro-tip'}, '—'),
        el('td', {
          id: `dro-dtg-${a}`,
          class: 'dro-dtg',
          title: 'distance to go on this axis in the move under way (along the path: below)'
        },
           '—'));
  }));
}

function showDro(ctx, status) {
  const work = status.work_position?.actual ?? {};
  const mach = status.position?.actual ?? {};
  const toGo = status.axes_to_go ?? {};
  const digits = status.units === 'inch' ? 4 : 3;
  // A machine with TCP: the tool tip in the part's frame, null elsewhere.
  const tip = status.tool_tip?.actual ?? null;
  $('.dro-table').classList.toggle('has-tip', tip !== null);
  for (const letter of ctx.droAxes) {
    const a = letter.toLowerCase();
    setText($(`#dro-${a}`), fmt(work[a], digits));
    if (a === 'x') {
      const th = $('#dro-rows .dro-row[data-axis="x"] .dro-axis');
      if (th) setText(th, status.diameter_mode ? 'X \u2300' : letter);
      $('#dro-x')?.setAttribute('title', status.diameter_mode ? 'X as a diameter (G7)' : '');
    }
    setText($(`#dro-mach-${a}`), fmt(mach[a], digits));
    if (tip) setText($(`#dro-tip-${a}`), fmt(tip[a], digits));
    setText($(`#dro-dtg-${a}`), fmt(toGo[a], digits));
  }
  const homed = status.homed ?? [];
  for (const [i, row] of Array.from(document.querySelectorAll('.dro-row')).entries()) {
    row.classList.toggle('unhomed', homed[i] === false);
  }
  const units = status.units ?? '';
  setText($('#dro-dtg'), `${fmt(status.distance_to_go, digits)} ${units}`);
  setText($('#velocity'), `${fmt((status.velocity ?? NaN) * 60, 1)} ${units}/min`);
  setText($('#feed-rate'), `F ${fmt(status.feed_rate, 1)}`);
  setText($('#coord-system'), status.offsets?.coord_system ?? '');
  showTcp(status.tcp);
  setText($('#active-codes'), [...(status.gcodes ?? []), ...(status.mcodes ?? [])].join(' '));
  const tool = status.tool ?? {};
  let toolText = tool.number ? `T${tool.number}` : 'T0 (none)';
  if (tool.entry) {
    toolText += ` Ø${fmt(tool.entry.diameter, digits)}`;
    if (tool.entry.comment) toolText += ` ${tool.entry.comment}`;
  }
  if (tool.prepared > 0 && tool.prepared !== tool.number) toolText += ` · next T${tool.prepared}`;
  setText($('#tool'), toolText);
  const sp = status.spindle ?? {};
  const dir = sp.direction > 0 ? 'CW' : sp.direction < 0 ? 'CCW' : 'stopped';
  const spindle = $('#spindle');
  setText(
      spindle,
      `${dir} · cmd ${fmt(sp.commanded_rpm, 0)} · act ${fmt(sp.actual_rpm, 0)} rpm` +
          (sp.direction ? (sp.at_speed ? ' · at speed' : ' · not at speed') : ''));
  spindle.classList.toggle('warn', Boolean(sp.direction) && !sp.at_speed);
  const coolant = status.coolant ?? {};
  setText(
      $('#coolant'),
      [coolant.flood && 'flood', coolant.mist && 'mist'].filter(Boolean).join(' + ') || 'off');
  for (const name of ['feed', 'rapid', 'spindle'])
    showOverride(name, status.overrides?.[name]);
}

// TCP as the motion runs it; the interpreter's state for the next move when that differs
// (after M428 or M429, before the next move runs).
function showTcp(tcp) {
  const box = $('#tcp-state');
  box.hidden = !tcp;
  if (!tcp) return;
  const word = (on) => (on ? 'on' : 'off');
  const next = tcp.programmed !== tcp.motion ? ` (next move: ${word(tcp.programmed)})` : '';
  setText(box, `TCP ${word(tcp.motion)}${next}`);
  box.classList.toggle('on', tcp.motion);
  box.title = `tool centre point control: the motion runs with it ${word(tcp.motion)}, ` +
      `the next move the interpreter reads ${word(tcp.programmed)} (M428 on, M429 off)`;
}

function setupOverride(ctx, name) {
  const slider = $(`#override-${name}`);
  const label = $(`#override-${name}-value`);
  slider.addEventListener('input', () => setText(label, `${slider.value} %`));
  const hold = () => (slider.dataset.held = '1');
  const release = () => delete slider.dataset.held;
  slider.addEventListener('pointerdown', hold);
  slider.addEventListener('pointerup', release);
  slider.addEventListener('pointercancel', release);
  slider.addEventListener('change', async () => {
    release();
    try {
      await ctx.call(`override.${name}`, {value: Number(slider.value) / 100});
    } catch {
      showOverride(name, ctx.store.status.overrides?.[name], true);
    }
  });
  $(`#override-${name}-reset`)?.addEventListener('click', () => {
    ctx.run(`override.${name}`, {value: 1});
  });
}

function showOverride(name, ratio, force = false) {
  const slider = $(`#override-${name}`);
  if (typeof ratio !== 'number' || (!force && slider.dataset.held)) return;
  if (!force && document.activeElement === slider && slider.matches(':active')) return;
  const percent = Math.round(ratio * 100);
  if (percent > Number(slider.max)) slider.max = String(percent);
  if (String(percent) !== slider.value) slider.value = String(percent);
  setText($(`#override-${name}-value`), `${percent} %`);
}
