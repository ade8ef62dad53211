// Small DOM helpers shared by the page's modules: element lookup and creation, number and time
// formats, toasts, and the role gate that disables what the session may not call.

export const $ = (selector, root = document) => root.querySelector(selector);
export const $$ = (selector, root = document) => Array.from(root.querySelectorAll(selector));

// el('button', {id: 'x', class: 'big', onclick: fn}, 'text', child, ...)
export function el(tag, attrs = {}, ...children) {
  const node = document.createElement(tag);
  for (const [key, value] of Object.entries(attrs)) {
    if (value === undefined || value === null || value === false) continue;
    if (key.startsWith('on') && typeof value === 'function')
      node.addEventListener(key.slice(2), value);
    else if (key === 'class')
      node.className = value;
    else if (key === 'dataset')
      Object.assign(node.dataset, value);
    else if (key in node && typeof value !== 'string')
      node[key] = value;
    else
      node.setAttribute(key, value === true ? '' : value);
  }
  for (const child of children.flat()) {
    if (child === null || child === undefined || child === false) continue;
    node.append(child instanceof Node ? child : document.createTextNode(String(child)));
  }
  return node;
}

// Writes text only when it changed: status updates arrive ten times a second, and rewriting
// unchanged text costs layout on a tablet.
export function setText(node, text) {
  if (node && node.textContent !== text) node.textContent = text;
}

// A function that runs fn at the next animation frame, once however often it is called
// before then: views redraw at most once a frame.
export function onNextFrame(fn) {
  let pending = false;
  return () => {
    if (pending) return;
    pending = true;
    requestAnimationFrame(() => {
      pending = false;
      fn();
    });
  };
}

export function fmt(value, digits = 3) {
  return typeof value === 'number' && Number.isFinite(value) ? value.toFixed(digits) : '—';
}

export function fmtDuration(seconds) {
  if (typeof seconds !== 'number' || !Number.isFinite(seconds)) return '—';
  const s = Math.max(0, Math.round(seconds));
  const h = Math.floor(s / 3600);
  const m = Math.floor((s % 3600) / 60);
  const sec = String(s % 60).padStart(2, '0');
  return h > 0 ? `${h}:${String(m).padStart(2, '0')}:${sec}` : `${m}:${sec}`;
}

export function fmtTime(epochSeconds) {
  if (typeof epochSeconds !== 'number') return '';
  return new Date(epochSeconds * 1000).toLocaleTimeString();
}

let toastBox = null;
// A short-lived message over the page; errors stay longer than notes.
export function toast(message, level = 'error') {
  toastBox ??= $('#toasts');
  if (!toastBox) return;
  const node = el('div', {class: `toast toast-${level}`, role: 'alert'}, message);
  node.addEventListener('click', () => node.remove());
  toastBox.append(node);
  while (toastBox.children.length > 4)
    toastBox.firstChild.remove();
  setTimeout(() => node.remove(), level === 'error' ? 8000 : 3500);
}

// Every control that calls a method carries data-method="name"; those the session's role may
// not call are disabled (and say why), so an observer sees the screen but cannot press it.
let allowed = null;
export function setAllowedMethods(methods) {
  allowed = methods ? new Set(methods) : null;
  applyGate(document);
}

export function mayCall(method) { return allowed === null || allowed.has(method); }

export function applyGate(root) {
  for (const node of $$('[data-method]', root)) {
    const ok = mayCall(node.dataset.method);
    node.disabled = !ok;
    node.classList.toggle('gated', !ok);
    if (!ok)
      node.title = `your role may not call ${node.dataset.method}`;
    else if (node.title.startsWith('your role'))
      node.title = '';
  }
}

// A button that asks for a second press instead of a modal dialog: window.confirm() would stop
// the page's script, and with it the DRO and the WebSocket, while it is open.
export function confirmPress(button, action, label = 'Sure?') {
  if (button.dataset.confirming === '1') {
    delete button.dataset.confirming;
    button.textContent = button.dataset.label;
    button.classList.remove('confirm');
    action();
    return;
  }
  button.dataset.label = button.textContent;
  button.dataset.confirming = '1';
  button.textContent = label;
  button.classList.add('confirm');
  setTimeout(() => {
    if (button.dataset.confirming !== '1') return;
    delete button.dataset.confirming;
    button.textContent = button.dataset.label;
    button.classList.remove('confirm');
  }, 4000);
}
