// The open program: its text with the running line highlighted and followed, the line picked
// for "run from line", progress, elapsed and remaining time, the run controls and the wait
// prompt (tool change, input, spindle at speed).
//
// The text is drawn as a window of lines over a spacer as tall as the whole program, so a
// program of a million lines scrolls as easily as one of ten.

import {$, el, fmtDuration, onNextFrame, setText} from './ui.js';

const kLineHeight = 22;  // px, as .prog-line in style.css
const kOverscan = 200;   // lines drawn above and below the visible ones

export function setupProgram(ctx) {
  const view = new ProgramText($('#program-text'), (line) => ctx.selectLine(line));
  ctx.programText = view;
  ctx.selectedLine = null;
  ctx.selectLine = (line) => {
    ctx.selectedLine = line;
    view.select(line);
    setText($('#selected-line'), line ? String(line) : '…');
    $('#run-from-line').dataset.line = line ?? '';
  };
  ctx.selectLine(null);

  $('#run').addEventListener('click', () => ctx.run('program.run'));
  $('#pause').addEventListener('click', () => ctx.run('program.pause'));
  $('#resume').addEventListener('click', () => ctx.run('program.resume'));
  $('#abort').addEventListener('click', () => ctx.run('program.abort'));
  $('#step').addEventListener('click', () => ctx.run('program.step'));
  $('#run-from-line').addEventListener('click', () => {
    if (!ctx.selectedLine) {
      ctx.log.refused(
          'program.run', {message: 'pick a line first: in the program text or on the preview'});
      return;
    }
    ctx.run('program.run', {from_line: ctx.selectedLine});
  });
  $('#wait-done').addEventListener('click', () => {
    const wait = ctx.store.status.wait;
    if (wait?.kind === 'tool_change') ctx.run('tool.change_done', {tool: wait.tool});
    else if (wait?.kind === 'input' || wait?.kind === 'spindle_at_speed')
      ctx.run('wait.done', {kind: wait.kind});
  });

  let shownPath = null;
  ctx.on('program-opened', () => (shownPath = null));
  ctx.on('connected', () => (shownPath = null));
  ctx.store.subscribe((status) => {
    const program = status.program ?? {};
    const path = program.path ?? '';
    if (path !== shownPath && !program.opening) {
      shownPath = path;
      loadText(view, path);
      ctx.selectLine(null);
    }
    const name = path ? path.split('/').pop() : 'no program open';
    setText(
        $('#program-name'),
        program.opening ? `opening ${program.opening.split('/').pop()}…` : name);
    $('#program-name').title = path;
    const running = status.exec === 'running' || status.exec === 'paused';
    view.setCurrent(running || program.line > 0 ? program.line : 0, running);
    const ratio = Math.min(1, Math.max(0, program.progress ?? 0));
    const progress = $('#progress');
    setText(progress, `${Math.round(ratio * 100)} %`);
    progress.dataset.ratio = ratio.toFixed(4);
    $('#progress-bar').style.width = `${(ratio * 100).toFixed(1)}%`;
    setText($('#elapsed'), fmtDuration(program.elapsed_s));
    // Why there is no estimate (still working it out, a line the planner refused) goes in the
    // tooltip: it can be a long message, and the side column has no room for it.
    const remaining = $('#remaining');
    const known = typeof program.remaining_s === 'number';
    setText(remaining, known ? fmtDuration(program.remaining_s) : '—');
    remaining.title = known ? '' : (program.remaining_reason ?? '');
    setText($('#program-result'), program.result ? `last run: ${program.result}` : '');
    setText($('#program-error'), program.error ?? '');
    for (const [id, active] of [
             ['run', status.exec === 'idle'], ['pause', status.exec === 'running'],
             ['resume', status.exec === 'paused'], ['abort', running],
             ['step', status.exec !== 'running'], ['run-from-line', status.exec === 'idle']]) {
      $(`#${id}`).classList.toggle('inactive', !active);
    }
    showWait(status.wait);
  });
}

function showWait(wait) {
  const box = $('#wait-prompt');
  box.hidden = !wait;
  if (!wait) return;
  setText($('#wait-message'), wait.message || wait.kind);
  // A user M code ends by itself; the other waits can be answered.
  const done = $('#wait-done');
  const labels = {
    tool_change: `T${wait.tool} is in`,
    input: 'Go on without the input',
    spindle_at_speed: 'Go on below speed',
  };
  done.hidden = !(wait.kind in labels);
  done.dataset.method = wait.kind === 'tool_change' ? 'tool.change_done' : 'wait.done';
  setText(done, labels[wait.kind] ?? 'Done');
}

async function loadText(view, path) {
  if (!path) {
    view.setLines([], 'no program open');
    return;
  }
  view.setLines([], 'loading…');
  const name = path.split('/').pop();
  try {
    const response =
        await fetch(`/api/programs/${encodeURIComponent(name)}`, {credentials: 'same-origin'});
    if (!response.ok) {
      view.setLines(
          [], `the text of ${name} is not in the program directory (HTTP ${response.status})`);
      return;
    }
    const text = await response.text();
    const lines = text.split('\n');
    if (lines.length > 1 && lines[lines.length - 1] === '') lines.pop();
    view.setLines(lines, '');
  } catch (e) {
    view.setLines([], `could not load the text: ${e.message}`);
  }
}

class ProgramText {
  constructor(box, onPick) {
    this.box = box;
    this.lines = [];
    this.current = 0;
    this.selected = null;
    this.spacer = el('div', {class: 'prog-spacer'});
    this.window = el('div', {class: 'prog-window'});
    this.note = el('div', {class: 'prog-note'});
    box.replaceChildren(this.note, this.spacer);
    this.spacer.append(this.window);
    this.drawn = [0, 0];
    this.schedule = onNextFrame(() => this.draw());
    box.addEventListener('scroll', () => this.schedule());
    box.addEventListener('click', (event) => {
      const line = event.target.closest('[data-line]');
      if (line) onPick(Number(line.dataset.line));
    });
    new ResizeObserver(() => this.schedule()).observe(box);
  }

  setLines(lines, note) {
    this.lines = lines;
    setText(this.note, note);
    this.note.hidden = !note;
    this.spacer.style.height = `${lines.length * kLineHeight}px`;
    this.drawn = [0, 0];
    this.window.replaceChildren();
    this.box.scrollTop = 0;
    this.draw();
  }

  draw() {
    // Lines drawn stay as they are while the visible ones are among them: rows are rebuilt
    // once every few hundred lines of scrolling, not at each line the program runs.
    const top = Math.floor(this.box.scrollTop / kLineHeight);
    const visible = Math.ceil(this.box.clientHeight / kLineHeight) + 1;
    const bottom = Math.min(this.lines.length, top + visible);
    if (this.drawn[1] > this.drawn[0] && top >= this.drawn[0] && bottom <= this.drawn[1]) return;
    if (this.lines.length === 0 && this.drawn[1] === 0) return;
    const first = Math.max(0, top - kOverscan);
    const last = Math.min(this.lines.length, top + visible + kOverscan);
    this.drawn = [first, last];
    const rows = [];
    for (let i = first; i < last; ++i) {
      const n = i + 1;
      const row =
          el('div', {class: 'prog-line', dataset: {line: String(n)}},
             el('span', {class: 'prog-num'}, String(n)),
             el('span', {class: 'prog-code'}, this.lines[i]));
      if (n === this.current) row.classList.add('current');
      if (n === this.selected) row.classList.add('selected');
      rows.push(row);
    }
    this.window.style.top = `${first * kLineHeight}px`;
    this.window.replaceChildren(...rows);
  }

  row(n) { return n > 0 ? this.window.querySelector(`[data-line="${n}"]`) : null; }

  setCurrent(line, follow) {
    if (line === this.current) return;
    this.row(this.current)?.classList.remove('current');
    this.current = line;
    this.row(line)?.classList.add('current');
    if (follow && line > 0) this.reveal(line);
  }

  select(line) {
    this.row(this.selected)?.classList.remove('selected');
    this.selected = line;
    this.row(line)?.classList.add('selected');
    if (line) this.reveal(line);
  }

  // Scrolls the line to the middle when it is out of view (drawing it, so it can be marked).
  reveal(line) {
    const top = (line - 1) * kLineHeight;
    const view = this.box;
    if (top >= view.scrollTop && top + kLineHeight <= view.scrollTop + view.clientHeight) return;
    view.scrollTop = Math.max(0, top - view.clientHeight / 2);
    this.draw();
  }
}
