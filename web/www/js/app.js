// The dashboard's entry point: one WebSocket to cncd-web, the status subscription, and the
// panels wired to a shared context. On each (re)connection the page asks who it is
// (web.session), what machine this is (system.info), subscribes to the status and catches up
// with the event log.

import {setupDiag} from './diag.js';
import {setupDro} from './dro.js';
import {setupFiles} from './files.js';
import {setupHeader} from './header.js';
import {setupJobs} from './jobs.js';
import {setupJog} from './jog.js';
import {EventLog} from './log.js';
import {setupMdi} from './mdi.js';
import {setupPreview} from './preview.js';
import {setupProgram} from './program.js';
import {RpcClient, wsUrl} from './rpc.js';
import {StatusStore} from './store.js';
import {setupTables} from './tables.js';
import {$, $$, setAllowedMethods} from './ui.js';

const kStatusIntervalMs = 100;

function makeContext() {
  const rpc = new RpcClient(wsUrl());
  const hooks = new Map();
  const ctx = {
    rpc,
    store: new StatusStore(),
    log: new EventLog(rpc),
    session: null,
    lease: null,    // {user, address, since} of whoever holds the control lease, or null
    myLease: null,  // the lease as this page took it
    on(name, fn) {
      if (!hooks.has(name)) hooks.set(name, []);
      hooks.get(name).push(fn);
    },
    emit(name, ...args) {
      for (const fn of hooks.get(name) ?? []) {
        try {
          fn(...args);
        } catch (e) {
          console.error(`${name} hook failed:`, e);
        }
      }
    },
    // A request whose refusal is shown (toast and log) unless quiet; rejects as well.
    async call(method, params, {quiet = false} = {}) {
      try {
        return await rpc.call(method, params);
      } catch (e) {
        if (!quiet) ctx.log.refused(method, e);
        throw e;
      }
    },
    // The same for buttons, which have nothing more to do with a refusal.
    run(method, params) { ctx.call(method, params).catch(() => {}); },
    setLease(lease, taken = false) {
      ctx.lease = lease && typeof lease === 'object' && lease.user ? lease : null;
      if (taken)
        ctx.myLease = ctx.lease;
      else if (!ctx.holdsLease())
        ctx.myLease = null;
      ctx.emit('lease');
    },
    holdsLease() {
      const lease = ctx.lease;
      if (!lease) return false;
      if (lease.session && ctx.session?.session) return lease.session === ctx.session.session;
      const mine = ctx.myLease;
      return Boolean(mine) && mine.user === lease.user && mine.address === lease.address &&
          mine.since === lease.since;
    },
  };
  return ctx;
}

async function onConnected(ctx) {
  const {rpc} = ctx;
  ctx.emit('connection', true);
  try {
    ctx.session = await ctx.call('web.session', undefined, {quiet: true});
    setAllowedMethods(ctx.session.methods ?? []);
    ctx.emit('session', ctx.session);
    ctx.setLease(ctx.session.lease ?? null);
  } catch (e) {
    ctx.log.add('error', 'session', `web.session: ${e.message}`);
  }
  try {
    ctx.store.info = await ctx.call('system.info', undefined, {quiet: true});
    ctx.emit('info', ctx.store.info);
    document.title = `${ctx.store.info.machine?.name ?? 'cncd'} — cncd`;
    $('#machine-name').textContent = ctx.store.info.machine?.name ?? '';
  } catch (e) {
    ctx.log.add('error', 'system.info', e.message);
  }
  try {
    await rpc.call('status.subscribe', {interval_ms: kStatusIntervalMs});
  } catch (e) {
    ctx.log.add('error', 'status.subscribe', e.message);
  }
  ctx.log.catchUp();
  ctx.emit('connected');
}

// A WebSocket that closes at once may mean the session has expired: then back to the login page.
async function checkSession() {
  try {
    const response = await fetch('/api/session', {credentials: 'same-origin'});
    if (response.status === 401) location.href = '/login.html';
  } catch {
    // the server is away: the client keeps reconnecting
  }
}

function setupTabs() {
  const tabs = $$('.tab');
  const show = (name) => {
    for (const tab of tabs)
      tab.classList.toggle('active', tab.dataset.tab === name);
    for (const panel of $$('.panel'))
      panel.classList.toggle('active', panel.dataset.panel === name);
    try {
      localStorage.setItem('cncd.tab', name);
    } catch {
      // no storage: the first tab next time
    }
    window.dispatchEvent(new Event('resize'));
  };
  for (const tab of tabs)
    tab.addEventListener('click', () => show(tab.dataset.tab));
  let first = 'preview';
  try {
    first = localStorage.getItem('cncd.tab') ?? first;
  } catch {
    // as above
  }
  show(tabs.some((tab) => tab.dataset.tab === first) ? first : 'preview');
  // On a wide screen the program and the log are pinned beside the tabs: their tab is hidden,
  // so another one takes the place.
  const wide = window.matchMedia('(min-width: 1400px)');
  const unpin = () => {
    const active = $('.tab.active');
    if (wide.matches && active?.classList.contains('pinnable')) show('preview');
  };
  wide.addEventListener('change', unpin);
  unpin();
}

function main() {
  const ctx = makeContext();
  window.cncd = ctx;  // for the browser's console
  setupTabs();
  setupHeader(ctx);
  setupDro(ctx);
  setupProgram(ctx);
  setupPreview(ctx);
  setupJog(ctx);
  setupMdi(ctx);
  setupFiles(ctx);
  setupTables(ctx);
  setupJobs(ctx);
  setupDiag(ctx);
  ctx.rpc.on('status.update', (update) => ctx.store.apply(update));
  ctx.rpc.on('lease.changed', (lease) => ctx.setLease(lease ?? null));
  ctx.rpc.onOpen.push(() => onConnected(ctx));
  ctx.rpc.onClose.push(() => {
    ctx.emit('connection', false);
    ctx.setLease(null);
    checkSession();
  });
  ctx.emit('connection', false);
  ctx.rpc.connect();
}

main();
