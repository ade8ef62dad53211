// The program directory: list (size, date, estimated time), upload, download, rename, delete
// and open. Uploads go by HTTP (PUT /api/programs/NAME, streamed by cncd-web into a temporary
// file), everything else by the WebSocket's files.* methods.

import {$, applyGate, confirmPress, el, fmtDuration, mayCall, toast} from './ui.js';

export function setupFiles(ctx) {
  const refresh = () => listFiles(ctx);
  ctx.refreshFiles = refresh;
  ctx.on('connected', refresh);
  $('#files-refresh').addEventListener('click', refresh);
  $('#upload-input').addEventListener('change', async (event) => {
    const input = event.target;
    for (const file of Array.from(input.files ?? []))
      await upload(ctx, file);
    input.value = '';
    refresh();
  });
  $('#file-list').addEventListener('click', (event) => {
    const row = event.target.closest('[data-file]');
    const button = event.target.closest('button');
    if (!row || !button) return;
    const name = row.dataset.file;
    if (button.classList.contains('file-open'))
      openFile(ctx, name);
    else if (button.classList.contains('file-rename'))
      startRename(ctx, row, name);
    else if (button.classList.contains('file-delete')) {
      confirmPress(button, async () => {
        try {
          await ctx.call('files.delete', {name});
        } finally {
          refresh();
        }
      }, 'Delete?');
    }
  });
}

async function listFiles(ctx) {
  let files;
  try {
    const result = await ctx.call('files.list', undefined, {quiet: true});
    files = Array.isArray(result) ? result : (result?.files ?? []);
  } catch (e) {
    // files.list is also served over HTTP: the same list, with the session cookie.
    try {
      const response = await fetch('/api/programs', {credentials: 'same-origin'});
      if (!response.ok) throw new Error(`HTTP ${response.status}`);
      files = await response.json();
    } catch (e2) {
      ctx.log.refused('files.list', {message: `${e.message}; ${e2.message}`});
      return;
    }
  }
  files.sort((a, b) => a.name.localeCompare(b.name));
  const openName = (ctx.store.status.program?.path ?? '').split('/').pop();
  $('#file-list').replaceChildren(...files.map((file) => fileRow(file, file.name === openName)));
  applyGate($('#file-list'));
}

function fileRow(file, isOpen) {
  const size = file.size >= 1048576 ? `${(file.size / 1048576).toFixed(1)} MB` :
      file.size >= 1024 ? `${(file.size / 1024).toFixed(1)} kB` :
                          `${file.size} B`;
  const date = typeof file.mtime === 'number' ? new Date(file.mtime * 1000).toLocaleString() :
                                                (file.mtime ?? '');
  const estimate = typeof file.estimate_s === 'number' ? fmtDuration(file.estimate_s) : '—';
  return el(
      'tr', {class: isOpen ? 'file-row open' : 'file-row', dataset: {file: file.name}},
      el('td', {class: 'file-name'}, file.name), el('td', {class: 'file-size'}, size),
      el('td', {class: 'file-date'}, date), el('td', {class: 'file-estimate'}, estimate),
      el('td', {class: 'file-actions'},
         el('button', {class: 'file-open', type: 'button', dataset: {method: 'files.open'}},
            'Open'),
         el('a', {
           class: 'file-download button',
           href: `/api/programs/${encodeURIComponent(file.name)}`,
           download: file.name
         },
            'Download'),
         el('button', {class: 'file-rename', type: 'button', dataset: {method: 'files.rename'}},
            'Rename'),
         el('button', {class: 'file-delete', type: 'button', dataset: {method: 'files.delete'}},
            'Delete')));
}

async function openFile(ctx, name) {
  const status = $('#files-status');
  status.textContent = `opening ${name}…`;
  try {
    await ctx.call('files.open', {name});
    status.textContent = `${name} is open`;
    ctx.emit('program-opened', name);
  } catch (e) {
    status.textContent = `${name}: ${e.message}`;
  }
  ctx.refreshFiles();
}

async function upload(ctx, file) {
  const status = $('#files-status');
  if (!mayCall('files.rename')) {
    ctx.log.refused('upload', {message: 'uploading needs the setter role'});
    return;
  }
  status.textContent = `uploading ${file.name} (${file.size} bytes)…`;
  try {
    const response = await fetch(`/api/programs/${encodeURIComponent(file.name)}`, {
      method: 'PUT',
      body: file,
      credentials: 'same-origin',
      headers: {'Content-Type': 'application/octet-stream'},
    });
    if (!response.ok) {
      let reason = `HTTP ${response.status}`;
      try {
        reason = (await response.json()).error ?? reason;
      } catch {
        // not JSON: the status says enough
      }
      status.textContent = `${file.name}: ${reason}`;
      ctx.log.refused('upload', {message: `${file.name}: ${reason}`});
      return;
    }
    status.textContent = `${file.name} uploaded`;
    ctx.log.add('info', 'upload', `${file.name} uploaded (${file.size} bytes)`);
    toast(`${file.name} uploaded`, 'info');
  } catch (e) {
    status.textContent = `${file.name}: ${e.message}`;
    ctx.log.refused('upload', e);
  }
}

function startRename(ctx, row, name) {
  const cell = row.querySelector('.file-name');
  const input = el('input', {
    class: 'file-rename-input',
    type: 'text',
    value: name,
    'aria-label': `new name for ${name}`
  });
  cell.replaceChildren(input);
  input.focus();
  input.select();
  let done = false;
  const finish = async (commit) => {
    if (done) return;
    done = true;
    const to = input.value.trim();
    if (commit && to && to !== name) {
      try {
        await ctx.call('files.rename', {from: name, to});
      } catch {
        // shown in the log
      }
    }
    ctx.refreshFiles();
  };
  input.addEventListener('keydown', (event) => {
    if (event.key === 'Enter')
      finish(true);
    else if (event.key === 'Escape')
      finish(false);
  });
  input.addEventListener('blur', () => finish(true));
}
