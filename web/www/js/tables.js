// The tool table and the work offsets (G54 .. G59.3), editable by roles that may call tool.set
// and offsets.set: each row is saved on its own, and the daemon writes the file atomically
// before the answer.

import {$, applyGate, el, fmt, mayCall, toast} from './ui.js';

export function setupTables(ctx) {
  const load = () => {
    loadTools(ctx);
    loadOffsets(ctx);
  };
  ctx.on('connected', load);
  $('#tables-refresh').addEventListener('click', load);
  $('#tool-add').addEventListener('click', () => {
    const body = $('#tool-rows');
    const used =
        Array.from(body.querySelectorAll('[data-tool]')).map((row) => Number(row.dataset.tool));
    const number = used.length ? Math.max(...used) + 1 : 1;
    body.append(toolRow(ctx, {number, pocket: number, offset: {}, diameter: 0, comment: ''}, true));
  });
  // Reloads after a change made elsewhere (G10 in a program, another client), announced as an
  // event.
  ctx.rpc.on('event', (event) => {
    if (event?.kind === 'tools') loadTools(ctx);
    if (event?.kind === 'offsets' || event?.kind === 'parameters') loadOffsets(ctx);
  });
}

function axesOf(ctx) {
  return (ctx.store.info?.machine?.axes ?? ['X', 'Y', 'Z']).map((a) => a.toLowerCase());
}

function numberInput(name, value, digits = 4) {
  return el('input', {
    type: 'number',
    step: 'any',
    class: `cell-${name}`,
    dataset: {field: name},
    value: typeof value === 'number' ? String(Number(value.toFixed(digits))) : ''
  });
}

// Asks `method` for a table and fills the page's with fill(result, axes); what fails is said
// in `note`.
async function loadTable(ctx, method, note, fill) {
  try {
    fill(await ctx.call(method, undefined, {quiet: true}), axesOf(ctx));
  } catch (e) {
    $(note).textContent = `${method}: ${e.message}`;
  }
}

function loadTools(ctx) {
  return loadTable(ctx, 'tool.list', '#tool-path', (result, axes) => {
    $('#tool-head')
        .replaceChildren(
            el('tr', {}, el('th', {}, 'T'), el('th', {}, 'pocket'),
               ...axes.map((a) => el('th', {}, `${a.toUpperCase()} offset`)),
               el('th', {}, 'diameter'), el('th', {}, 'comment'), el('th')));
    $('#tool-rows')
        .replaceChildren(...(result.tools ?? []).map((tool) => toolRow(ctx, tool, false)));
    $('#tool-path').textContent = `${result.path ?? ''} (${result.units ?? ''})`;
    gateTable($('#tool-table'), 'tool.set');
  });
}

function toolRow(ctx, tool, isNew) {
  const axes = axesOf(ctx);
  const save =
      el('button', {type: 'button', class: 'row-save', dataset: {method: 'tool.set'}},
         isNew ? 'Add' : 'Save');
  const row =
      el('tr', {dataset: {tool: String(tool.number)}},
         el('td', {}, isNew ? numberInput('number', tool.number, 0) : `T${tool.number}`),
         el('td', {}, numberInput('pocket', tool.pocket, 0)),
         ...axes.map((a) => el('td', {}, numberInput(`offset-${a}`, tool.offset?.[a] ?? 0))),
         el('td', {}, numberInput('diameter', tool.diameter)), el('td', {}, el('input', {
                                                                    type: 'text',
                                                                    class: 'cell-comment',
                                                                    dataset: {field: 'comment'},
                                                                    value: tool.comment ?? '',
                                                                    maxlength: '200'
                                                                  })),
         el('td', {}, save));
  save.addEventListener('click', async () => {
    const value = (field) => row.querySelector(`[data-field="${field}"]`)?.value ?? '';
    const number = isNew ? Number(value('number')) : tool.number;
    const params = {number, comment: value('comment')};
    const pocket = value('pocket');
    if (pocket !== '') params.pocket = Number(pocket);
    const diameter = value('diameter');
    if (diameter !== '') params.diameter = Number(diameter);
    params.offset = {};
    for (const a of axes) {
      const v = value(`offset-${a}`);
      if (v !== '') params.offset[a] = Number(v);
    }
    try {
      await ctx.call('tool.set', params);
      toast(`T${number} saved`, 'info');
      loadTools(ctx);
    } catch {
      // the reason is in the log
    }
  });
  applyGate(row);
  if (!mayCall('tool.set'))
    for (const input of row.querySelectorAll('input'))
      input.disabled = true;
  return row;
}

function loadOffsets(ctx) {
  return loadTable(ctx, 'offsets.get', '#offsets-g92', (result, axes) => {
    $('#offsets-head')
        .replaceChildren(
            el('tr', {}, el('th', {}, 'system'), ...axes.map((a) => el('th', {}, a.toUpperCase())),
               el('th', {}, 'rotation °'), el('th')));
    $('#offsets-rows').replaceChildren(...(result.systems ?? []).map((system) => {
      const save = el(
          'button', {type: 'button', class: 'row-save', dataset: {method: 'offsets.set'}}, 'Save');
      const row =
          el('tr',
             {class: system.name === result.active ? 'active' : '', dataset: {system: system.name}},
             el('th', {}, system.name),
             ...axes.map((a) => el('td', {}, numberInput(`origin-${a}`, system.origin?.[a] ?? 0))),
             el('td', {}, numberInput('rotation', system.rotation ?? 0)), el('td', {}, save));
      save.addEventListener('click', async () => {
        const origin = {};
        for (const a of axes) {
          const v = row.querySelector(`[data-field="origin-${a}"]`).value;
          if (v !== '') origin[a] = Number(v);
        }
        const rotation = row.querySelector('[data-field="rotation"]').value;
        const params = {system: system.name, origin};
        if (rotation !== '') params.rotation = Number(rotation);
        try {
          await ctx.call('offsets.set', params);
          toast(`${system.name} saved`, 'info');
          loadOffsets(ctx);
        } catch {
          // the reason is in the log
        }
      });
      return row;
    }));
    const g92 = result.g92 ?? {};
    $('#offsets-g92').textContent =
        `G92: ${axes.map((a) => `${a.toUpperCase()} ${fmt(g92[a], 4)}`).join('  ')}` +
        ` · active ${result.active ?? ''} (${result.units ?? ''})`;
    gateTable($('#offsets-table'), 'offsets.set');
  });
}

function gateTable(table, method) {
  applyGate(table);
  const ok = mayCall(method);
  for (const input of table.querySelectorAll('input'))
    input.disabled = !ok;
  table.classList.toggle('read-only', !ok);
}
