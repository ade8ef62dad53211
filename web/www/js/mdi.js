// MDI: one block at a time, with a history recalled by the up and down arrows (kept in the
// browser across reloads). The answer comes when the block has finished; a block the
// interpreter rejects shows its error in the log and as a toast.

import {$, el} from './ui.js';

const kHistoryKey = 'cncd.mdi.history';
const kHistoryMax = 100;

export function setupMdi(ctx) {
  const input = $('#mdi-input');
  const list = $('#mdi-history');
  let history = [];
  try {
    history =
        JSON.parse(localStorage.getItem(kHistoryKey) ?? '[]').filter((x) => typeof x === 'string');
  } catch {
    history = [];
  }
  let cursor = history.length;  // history.length = the line being typed
  let draft = '';

  const show = () => {
    list.replaceChildren(...history.map(
        (line, i) => el('li', {class: 'mdi-entry', dataset: {index: String(i)}}, line)));
    list.scrollTop = list.scrollHeight;
  };
  show();

  const send = async () => {
    const line = input.value.trim();
    if (!line) return;
    if (history[history.length - 1] !== line) history.push(line);
    while (history.length > kHistoryMax)
      history.shift();
    try {
      localStorage.setItem(kHistoryKey, JSON.stringify(history));
    } catch {
      // private mode: the history lives as long as the page
    }
    cursor = history.length;
    draft = '';
    input.value = '';
    show();
    const entry = list.lastElementChild;
    entry?.classList.add('running');
    try {
      await ctx.call('mdi.execute', {line});
      entry?.classList.add('ok');
    } catch {
      entry?.classList.add('failed');
    } finally {
      entry?.classList.remove('running');
    }
  };

  $('#mdi-send').addEventListener('click', send);
  input.addEventListener('keydown', (event) => {
    if (event.key === 'Enter') {
      event.preventDefault();
      send();
    } else if (event.key === 'ArrowUp') {
      event.preventDefault();
      if (cursor === history.length) draft = input.value;
      if (cursor > 0) input.value = history[--cursor];
    } else if (event.key === 'ArrowDown') {
      event.preventDefault();
      if (cursor < history.length) {
        ++cursor;
        input.value = cursor === history.length ? draft : history[cursor];
      }
    }
  });
  list.addEventListener('click', (event) => {
    const entry = event.target.closest('.mdi-entry');
    if (!entry) return;
    input.value = entry.textContent;
    cursor = Number(entry.dataset.index);
    input.focus();
  });
}
