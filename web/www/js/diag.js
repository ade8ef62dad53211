// Diagnostics: servo-thread statistics (cycles, overruns, wake-up latency percentiles), failed
// Modbus requests, the daemon's client connections, each joint's drive and switches, and
// homing one joint at a time.

import {$, applyGate, el, setText} from './ui.js';

export function setupDiag(ctx) {
  ctx.store.subscribe((status) => {
    showServo(status.rt, status.clients);
    showDrives(ctx, status);
  });
}

const us = (ns) => (typeof ns === 'number' ? `${(ns / 1000).toFixed(1)} µs` : '—');

function showServo(rt, clients) {
  const box = $('#servo-stats');
  if (!rt) return;
  const rows = [
    ['cycles', String(rt.cycles ?? '—')],
    ['overruns', String(rt.overruns ?? '—')],
    ['wake-up p50', us(rt.wake_error_p50_ns)],
    ['wake-up p99', us(rt.wake_error_p99_ns)],
    ['wake-up p99.9', us(rt.wake_error_p999_ns)],
    ['wake-up max', us(rt.wake_error_max_ns)],
    ['real-time priority', rt.realtime ? 'yes' : 'no'],
    ['memory locked', rt.memory_locked ? 'yes' : 'no'],
    ['Modbus errors', String(rt.modbus_errors ?? '—')],
    ['clients of cncd', String(clients ?? '—')],
  ];
  if (box.children.length !== rows.length) {
    box.replaceChildren(...rows.map(
        ([name]) =>
            el('div', {class: 'stat'}, el('span', {class: 'stat-name'}, name),
               el('span', {class: 'stat-value', dataset: {stat: name}}))));
  }
  rows.forEach(([, value], i) => setText(box.children[i].lastChild, value));
  box.classList.toggle('has-overruns', (rt.overruns ?? 0) > 0);
}

const kFlags = [
  ['min_limit', 'min-limit'],
  ['max_limit', 'max-limit'],
  ['home_switch', 'home-switch'],
  ['at_min_soft_limit', 'at-soft-min'],
  ['at_max_soft_limit', 'at-soft-max'],
  ['drive_fault', 'drive-fault'],
  ['stale', 'stale'],
  ['fault', 'fault'],
];

function showDrives(ctx, status) {
  const joints = status.joints ?? [];
  const body = $('#drive-rows');
  if (body.children.length !== joints.length) {
    const axes = ctx.store.info?.machine?.axes ?? [];
    body.replaceChildren(...joints.map(
        (_, i) =>
            el('tr', {dataset: {joint: String(i)}},
               el('td', {}, `${i}${axes.length === joints.length ? ` (${axes[i]})` : ''}`),
               el('td', {class: 'drive-driver'}), el('td', {class: 'drive-enabled'}),
               el('td', {class: 'drive-homed'}), el('td', {class: 'drive-flags'}),
               el('td', {},
                  el('button', {
                    id: `home-joint-${i}`,
                    class: 'home-joint',
                    dataset: {method: 'machine.home'},
                    onclick: () => ctx.run('machine.home', {joints: [i]})
                  },
                     'Home')))));
    applyGate(body);
  }
  joints.forEach((joint, i) => {
    const row = body.children[i];
    setText(row.querySelector('.drive-driver'), joint.driver ?? '');
    setText(row.querySelector('.drive-enabled'), joint.enabled ? 'on' : 'off');
    setText(row.querySelector('.drive-homed'), joint.homed ? 'homed' : 'unhomed');
    const flags = kFlags.filter(([key]) => joint[key]).map(([, name]) => name);
    setText(row.querySelector('.drive-flags'), flags.join(' ') || 'ok');
    row.classList.toggle('bad', Boolean(joint.fault || joint.drive_fault || joint.stale));
  });
}
