// The header, always on screen: estop, reset, power, home all, the machine's state and mode,
// who is logged in, the control lease (who holds it, take it, give it back) and the link state.

import {$, confirmPress, setText} from './ui.js';

export function setupHeader(ctx) {
  const {rpc} = ctx;
  // Estop goes out even while another request waits, and is never gated by role or lease.
  // Sent on pointerdown, the earliest moment; a click (keyboard, a script) sends it too unless
  // the press just did.
  const estop = $('#estop');
  let sentAt = 0;
  const sendEstop = () => {
    sentAt = performance.now();
    ctx.run('machine.estop');
  };
  estop.addEventListener('pointerdown', (event) => {
    event.preventDefault();
    sendEstop();
  });
  estop.addEventListener('click', () => {
    if (performance.now() - sentAt > 600) sendEstop();
  });
  $('#reset').addEventListener('click', () => ctx.run('machine.reset'));
  $('#power').addEventListener('click', () => {
    ctx.run(ctx.store.status.state === 'on' ? 'machine.off' : 'machine.on');
  });
  $('#home-all').addEventListener('click', () => ctx.run('machine.home'));
  $('#lease-take').addEventListener('click', async () => {
    const lease = ctx.lease;
    const force = lease !== null && !ctx.holdsLease();
    try {
      const result = await ctx.call('lease.take', {force});
      ctx.setLease(result && 'user' in result ? result : (result?.lease ?? ctx.lease), true);
    } catch {
      // refused: already shown
    }
  });
  $('#lease-release').addEventListener('click', () => ctx.run('lease.release'));
  $('#logout').addEventListener('click', (event) => {
    confirmPress(event.currentTarget, async () => {
      rpc.close();
      await fetch('/api/logout', {method: 'POST', credentials: 'same-origin'}).catch(() => {});
      location.href = '/login.html';
    }, 'Log out?');
  });

  ctx.on('session', (session) => {
    setText($('#user'), session ? `${session.user} (${session.role})` : '');
  });
  ctx.on('lease', () => showLease(ctx));
  ctx.on('connection', (up) => {
    const conn = $('#conn');
    conn.classList.toggle('up', up);
    setText(conn, up ? 'connected' : 'reconnecting…');
    document.body.classList.toggle('offline', !up);
  });

  ctx.store.subscribe((status) => {
    const state = status.state ?? '—';
    const stateBox = $('#state');
    setText(stateBox, state);
    stateBox.dataset.state = state;
    setText($('#mode'), status.mode ?? '—');
    const exec = status.exec === 'idle' ? (status.motion ?? 'idle') : (status.exec ?? '');
    setText($('#exec'), exec);
    const power = $('#power');
    const on = state === 'on';
    setText(power, on ? 'Off' : 'On');
    power.dataset.method = on ? 'machine.off' : 'machine.on';
    power.classList.toggle('active', on);
    const fault = $('#fault');
    setText(fault, status.fault ?? '');
    fault.hidden = !status.fault;
    // One hand on the machine: who jogs now, when it is not this page (the panel's MPG or
    // buttons at the machine, or another client); the daemon refuses other jogs meanwhile.
    const hand = status.manual_holder;
    const handBox = $('#manual-holder');
    handBox.hidden = !hand || (!hand.panel && ctx.holdsLease());
    const what = hand?.axis ? ` ${hand.axis}` : hand?.joint != null ? ` joint ${hand.joint}` : '';
    if (hand) setText(handBox, `jogging: ${hand.by}${what}`);
    const homed = status.homed ?? [];
    $('#home-all').classList.toggle('active', homed.length > 0 && homed.every(Boolean));
  });
}

function showLease(ctx) {
  const lease = ctx.lease;
  const mine = ctx.holdsLease();
  const holder = $('#lease-holder');
  holder.classList.toggle('mine', mine);
  holder.classList.toggle('other', lease !== null && !mine);
  if (lease === null)
    setText(holder, 'control: free');
  else
    setText(holder, `control: ${lease.user}@${lease.address}${mine ? ' (you)' : ''}`);
  const take = $('#lease-take');
  setText(take, lease !== null && !mine ? 'Take over' : 'Take control');
  take.hidden = mine;
  $('#lease-release').hidden = !mine;
  document.body.classList.toggle('has-lease', mine);
}
