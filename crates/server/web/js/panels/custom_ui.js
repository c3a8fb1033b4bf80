// Custom UIs (simUI) as HTML. A user action calls simUI.interact(ui, id, value) on the
// server, which queues the widget's callback for its script, as a click in CoppeliaSim.

import { $, el, showError } from '../dom.js';
import { send } from '../net.js';

const uiState = new Map();  // ui handle -> {sig, root, inputs: Map(id -> update fn)}

export function showUis(uis) {
  const box = $('ui-windows');
  const seen = new Set();
  for (const ui of uis) {
    seen.add(ui.handle);
    // Rebuild only when the structure changed; otherwise update values in place so a
    // slider being dragged is not replaced under the pointer.
    const sig = JSON.stringify(ui, (k, v) => (k === 'value' || k === 'checked' ? undefined : v));
    let st = uiState.get(ui.handle);
    if (!st || st.sig !== sig) {
      st?.root.remove();
      st = { sig, inputs: new Map() };
      st.root = el('div', { class: 'ui-window', 'data-ui': String(ui.handle) },
        el('div', { class: 'title', text: ui.title }), buildContainer(ui, ui.content, st));
      uiState.set(ui.handle, st);
      box.append(st.root);
    }
    st.root.hidden = !ui.visible;
    for (const w of walkWidgets(ui.content)) st.inputs.get(w.id)?.(w);
  }
  for (const [h, st] of uiState) if (!seen.has(h)) { st.root.remove(); uiState.delete(h); }
  box.classList.toggle('muted', uiState.size === 0);
  if (uiState.size === 0) box.textContent = 'No custom UI yet.';
  else for (const n of [...box.childNodes]) if (n.nodeType === Node.TEXT_NODE) n.remove();
}

function* walkWidgets(c) {
  for (const row of c.rows) for (const w of row) {
    yield w;
    if (w.content) yield* walkWidgets(w.content);
  }
}

function buildContainer(ui, c, st) {
  const box = el('div', { class: `ui-box ${c.layout}` });
  if (c.layout === 'grid' || c.layout === 'form') {
    const cols = Math.max(1, ...c.rows.map((r) => r.length));
    box.style.gridTemplateColumns = `repeat(${cols}, auto)`;
  }
  for (const row of c.rows) for (const w of row) box.append(buildWidget(ui, w, st));
  return box;
}

function buildWidget(ui, w, st) {
  const act = (value) => send({ op: 'ui', ui: ui.handle, widget: w.id, value }, (r) => { if (!r.ok) showError(r.text); });
  const attrs = { 'data-ui-widget': String(w.id), 'data-type': w.type };
  let e;
  switch (w.type) {
    case 'hslider':
    case 'vslider': {
      e = el('input', { ...attrs, type: 'range', min: w.minimum, max: w.maximum, step: 1 });
      let busy = false;
      e.addEventListener('pointerdown', () => { busy = true; });
      e.addEventListener('pointerup', () => { busy = false; });
      // simUI reports every position while dragging; coalesce to what the server takes.
      let last = null;
      e.addEventListener('input', () => { const v = parseInt(e.value, 10); if (v !== last) { last = v; act(v); } });
      e.addEventListener('change', () => { busy = false; const v = parseInt(e.value, 10); if (v !== last) { last = v; act(v); } });
      st.inputs.set(w.id, (nw) => { if (!busy && document.activeElement !== e) { e.value = nw.value; last = nw.value; } });
      break;
    }
    case 'button':
      e = el('button', { ...attrs, text: w.text, type: 'button' });
      e.addEventListener('click', () => act(null));
      break;
    case 'label':
      // Qt rich text is shown as plain text: never as HTML from a script.
      e = el('span', { ...attrs, text: w.text.replace(/<[^>]*>/g, '') });
      st.inputs.set(w.id, (nw) => { e.textContent = nw.text.replace(/<[^>]*>/g, ''); });
      break;
    case 'edit':
      e = el('input', { ...attrs, type: 'text' });
      e.addEventListener('keydown', (ev) => { if (ev.key === 'Enter') act(e.value); });
      st.inputs.set(w.id, (nw) => { if (document.activeElement !== e) e.value = nw.value; });
      break;
    case 'checkbox': {
      const input = el('input', { type: 'checkbox' });
      e = el('label', attrs, input, ` ${w.text}`);
      input.addEventListener('change', () => act(input.checked ? 2 : 0));
      st.inputs.set(w.id, (nw) => { input.checked = nw.value === 2; input.indeterminate = nw.value === 1; });
      break;
    }
    case 'radiobutton': {
      const input = el('input', { type: 'radio', name: `ui${ui.handle}` });
      e = el('label', attrs, input, ` ${w.text}`);
      input.addEventListener('click', () => act(null));
      st.inputs.set(w.id, (nw) => { input.checked = nw.checked; });
      break;
    }
    case 'spinbox':
      e = el('input', { ...attrs, type: 'number', min: w.minimum, max: w.maximum, step: w.float ? w.step : Math.max(1, Math.round(w.step)) });
      e.addEventListener('change', () => act(w.float ? parseFloat(e.value) : parseInt(e.value, 10)));
      st.inputs.set(w.id, (nw) => { if (document.activeElement !== e) e.value = nw.value; });
      break;
    case 'group':
      e = el('fieldset', attrs, w.flat ? null : el('legend', { text: w.text }), buildContainer(ui, w.content, st));
      break;
    case 'stretch':
      e = el('div', { ...attrs, class: 'stretch' });
      break;
    default:
      e = el('span', { ...attrs, class: 'muted', text: `(${w.type})` });
  }
  if (!w.enabled) { e.classList.add('disabled'); if ('disabled' in e) e.disabled = true; }
  if (!w.visible) e.hidden = true;
  return e;
}
