// The job history: the machine's last runs (jobs.history) and their sums (jobs.stats), newest
// first, loaded when the page connects, when a run ends and on Reload.

import {$, el, fmtDuration} from './ui.js';

const kShown = 100;

export function setupJobs(ctx) {
  const load = () => loadJobs(ctx);
  ctx.on('connected', load);
  $('#jobs-refresh').addEventListener('click', load);
  // A run's row is written as it ends: its result shows when the status does.
  let result = null;
  ctx.store.subscribe((status) => {
    const now = status.program?.result ?? null;
    if (now !== result && now) load();
    result = now;
  });
  ctx.rpc.on('event', (event) => {
    if (event?.kind === 'jobs') load();
  });
}

const dateTime = (epoch) =>
    typeof epoch === 'number' ? new Date(epoch * 1000).toLocaleString() : '—';
const baseName = (path) => String(path ?? '').split('/').pop();
// Who started a run, without the process that passed it on ("... via uid 998 pid 812").
const who = (by) => String(by ?? '').split(' via ')[0];

async function loadJobs(ctx) {
  const note = $('#jobs-note');
  try {
    const [history, stats] = await Promise.all([
      ctx.call('jobs.history', {limit: kShown}, {quiet: true}),
      ctx.call('jobs.stats', undefined, {quiet: true}),
    ]);
    note.textContent = '';
    showStats(stats);
    $('#job-rows').replaceChildren(...(history.jobs ?? []).map(jobRow));
  } catch (e) {
    note.textContent = `The job history cannot be read: ${e.message}`;
  }
}

function showStats(stats) {
  const by = stats.by_result ?? {};
  const counts = Object.keys(by).sort().map((result) => `${by[result]} ${result}`).join(', ');
  $('#jobs-stats').textContent = `${stats.jobs ?? 0} runs (${counts || 'none'}), ` +
      `${stats.parts ?? 0} parts, ${fmtDuration(stats.cycle_s)} of cycle time`;
}

function jobRow(job) {
  const why = job.error ? `${job.error_line ? `line ${job.error_line}: ` : ''}${job.error}` : '';
  const from = job.from_line ? ` (from line ${job.from_line})` : '';
  return el('tr', {class: `job job-${job.result}`, dataset: {job: String(job.id)}},
            el('td', {}, dateTime(job.started)),
            el('td', {title: job.program ?? ''}, baseName(job.program) + from),
            el('td', {class: 'job-result'}, job.result ?? ''),
            el('td', {class: 'num'}, fmtDuration(job.cycle_s)),
            el('td', {class: 'num'}, fmtDuration(job.estimate_s)),
            el('td', {class: 'num'}, String(job.parts ?? 0)),
            el('td', {title: job.started_by ?? ''}, who(job.started_by)),
            el('td', {class: 'job-why'}, why));
}
