// The machine's status as the page knows it: the first status.update holds every field, later
// ones are JSON merge patches (RFC 7386) of it. Views subscribe and are redrawn at most once an
// animation frame, however many updates came in meanwhile.

import {onNextFrame} from './ui.js';

export class StatusStore {
  constructor() {
    this.status = {};
    this.info = null;  // system.info's answer
    this.views = [];
    this.connected = false;
    this.schedule = onNextFrame(() => {
      for (const fn of this.views) {
        try {
          fn(this.status, this);
        } catch (e) {
          console.error('status view failed:', e);
        }
      }
    });
  }

  // fn(status, store) runs after each batch of updates.
  subscribe(fn) { this.views.push(fn); }

  apply(update) {
    this.status = update.full ? structuredClone(update.changed) :
                                mergeKeepingNull(this.status, update.changed);
    this.schedule();
  }

  replace(status) {
    this.status = status ?? {};
    this.schedule();
  }
}

// The daemon's patches send a field that became null as null (it is a value here: "no wait",
// "unknown"), so null is kept rather than taken as a deletion.
function mergeKeepingNull(target, patch) {
  if (patch === null || typeof patch !== 'object' || Array.isArray(patch)) return patch;
  const out = target !== null && typeof target === 'object' && !Array.isArray(target) ? target : {};
  for (const [key, value] of Object.entries(patch))
    out[key] = mergeKeepingNull(out[key], value);
  return out;
}
