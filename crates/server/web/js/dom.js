// Page helpers shared by the panels: number formatting, element lookup and creation,
// the status badges, the error toast and command replies.

export const fmt = (v, n = 3) => (Number.isFinite(v) ? v.toFixed(n) : '–');
export const $ = (id) => document.getElementById(id);

// Creates an element with attributes/properties and children.
export function el(tag, props = {}, ...children) {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(props)) {
    if (k === 'class') e.className = v;
    else if (k === 'text') e.textContent = v;
    else if (k.startsWith('data-') || k === 'title' || k === 'for') e.setAttribute(k, v);
    else e[k] = v;
  }
  for (const c of children) if (c != null) e.append(c);
  return e;
}

export function setBadge(e, text, cls) { e.textContent = text; e.className = `badge ${cls || ''}`; }

export function showError(text) {
  const e = $('error');
  e.textContent = text;
  e.hidden = false;
  clearTimeout(showError.timer);
  showError.timer = setTimeout(() => { e.hidden = true; }, 6000);
}

export function setReply(e, r) {
  e.textContent = r.text;
  e.className = `reply ${r.ok ? '' : 'bad'}`;
}
