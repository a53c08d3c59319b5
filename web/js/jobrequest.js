// The request editor shared by the optimisation and allocation views: examples (one click each,
// from web/examples/index.json), a few settings as labelled fields kept in step with the request,
// the whole request as JSON, the API's problems (each with its JSON pointer; next to its field when
// a field edits that member), and submit. The job then runs in the page's job view.

import { api, ApiError, describe } from './api.js';

export function h(tag, attrs = {}, ...children) {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs)) {
    if (v === undefined || v === null || v === false) continue;
    if (k === 'text') e.textContent = v; else e.setAttribute(k, v === true ? '' : String(v));
  }
  for (const c of children.flat()) if (c !== null && c !== undefined) e.append(c instanceof Node ? c : String(c));
  return e;
}

const toPointer = path => `/${path.split('.').join('/')}`;
function getPath(doc, path) {
  let o = doc;
  for (const k of path.split('.')) { if (!o || typeof o !== 'object') return undefined; o = o[k]; }
  return o;
}
function setPath(doc, path, v) {
  const keys = path.split('.');
  let o = doc;
  for (const k of keys.slice(0, -1)) { if (!o[k] || typeof o[k] !== 'object') o[k] = {}; o = o[k]; }
  o[keys[keys.length - 1]] = v;
}
// Deletes the member and the objects it leaves empty (an analytic allocation must not get a
// "monte_carlo": {} from a field that was cleared).
function deletePath(doc, path) {
  const keys = path.split('.');
  const chain = [doc];
  for (const k of keys.slice(0, -1)) { const o = chain[chain.length - 1][k]; if (!o || typeof o !== 'object') return; chain.push(o); }
  delete chain[chain.length - 1][keys[keys.length - 1]];
  for (let i = chain.length - 1; i > 0; i--) if (!Object.keys(chain[i]).length) delete chain[i - 1][keys[i - 1]];
}

// opts: {prefix (ids), collection, noun, examples: [{file, label}], fields: [{path, label, type:
// 'int'|'number'|'enum', options?, placeholder?, hint?}], submitLabel, onSubmitted(response, doc)}
export function requestEditor(body, opts) {
  const { prefix } = opts;
  const text = h('textarea', { id: `${prefix}-request`, rows: 18, spellcheck: 'false', 'aria-describedby': `${prefix}-hint` });
  const note = h('p', { id: `${prefix}-note`, class: 'hint', role: 'status', 'aria-live': 'polite' });
  const problems = h('div', { id: `${prefix}-problems`, class: 'error-summary', role: 'alert', tabindex: '-1', hidden: true });
  const submit = h('button', { type: 'button', class: 'primary', id: `${prefix}-submit` }, opts.submitLabel);
  const exBar = h('div', { class: 'examples', role: 'group', 'aria-label': `${opts.noun} examples` });
  const inputs = [];

  const parse = () => JSON.parse(text.value);
  const setDoc = (doc, message) => {
    text.value = JSON.stringify(doc, null, 2);
    syncFields(doc);
    clearProblems();
    if (message) note.textContent = message;
  };
  const syncFields = doc => {
    for (const f of inputs) {
      if (f === document.activeElement) continue;
      const v = getPath(doc, f.dataset.path);
      f.value = v === undefined || v === null ? '' : String(v);
    }
  };

  for (const ex of opts.examples) {
    const b = h('button', { type: 'button', 'data-example': ex.file }, ex.label);
    b.addEventListener('click', async () => {
      try { setDoc(await api.example(ex.file), `Loaded ${ex.file}.`); } catch (e) { note.textContent = `Cannot load ${ex.file}: ${describe(e)}`; }
    });
    exBar.appendChild(b);
  }

  const grid = h('div', { class: 'grid' });
  for (const fd of opts.fields) {
    const id = `${prefix}-f-${fd.path.replace(/\./g, '-')}`;
    let input;
    if (fd.type === 'enum') {
      input = h('select', { id }, h('option', { value: '' }, fd.placeholder || '(default)'), fd.options.map(o => h('option', { value: o }, o)));
    } else {
      input = h('input', { id, type: 'number', step: fd.type === 'int' ? '1' : 'any', inputmode: fd.type === 'int' ? 'numeric' : undefined, placeholder: fd.placeholder, 'aria-describedby': fd.hint ? `${id}-hint` : undefined });
    }
    input.dataset.path = fd.path;
    input.dataset.type = fd.type;
    input.dataset.pointer = toPointer(fd.path);
    inputs.push(input);
    const apply = () => {
      let doc;
      try { doc = parse(); } catch (e) { note.textContent = `The request is not JSON (${e.message}): fix it before using the fields.`; return; }
      const raw = input.value.trim();
      if (raw === '') deletePath(doc, fd.path);
      else setPath(doc, fd.path, fd.type === 'enum' ? raw : Number(raw));
      text.value = JSON.stringify(doc, null, 2);
      clearFieldProblem(input);
    };
    input.addEventListener('input', apply);
    input.addEventListener('change', apply);
    grid.append(h('div', { class: 'field' }, h('label', { for: id }, fd.label), input, fd.hint ? h('small', { id: `${id}-hint`, class: 'hint' }, fd.hint) : null));
  }
  text.addEventListener('input', () => { try { syncFields(parse()); } catch { /* still typing */ } });

  function clearFieldProblem(input) {
    const m = input.parentElement.querySelector('.problem-msg');
    if (m) m.remove();
    input.removeAttribute('aria-invalid');
    const hint = input.id + '-hint';
    if (input.getAttribute('aria-describedby')) {
      const ids = input.getAttribute('aria-describedby').split(' ').filter(x => x === hint);
      if (ids.length) input.setAttribute('aria-describedby', ids.join(' ')); else input.removeAttribute('aria-describedby');
    }
  }
  function clearProblems() {
    problems.hidden = true;
    problems.textContent = '';
    text.removeAttribute('aria-invalid');
    for (const f of inputs) clearFieldProblem(f);
  }
  function showProblems(headline, list) {
    problems.textContent = '';
    problems.append(h('h3', { class: 'h4' }, headline));
    const ul = h('ul', {});
    list.forEach((p, i) => {
      const line = `${p.pointer || '(the request)'}: ${p.message}`;
      if (p.link) { // a field elsewhere on the page (the API token): a link to it, nothing attached
        const a = h('a', { href: `#${p.link.id}` }, p.message);
        a.addEventListener('click', e => { e.preventDefault(); p.link.focus(); });
        ul.append(h('li', { 'data-pointer': '' }, a));
        return;
      }
      const field = inputs.find(f => f.dataset.pointer === p.pointer);
      if (field) {
        const msg = h('p', { class: 'problem-msg error', id: `${field.id}-problem` }, p.message);
        msg.dataset.text = p.message;
        field.after(msg);
        field.setAttribute('aria-invalid', 'true');
        field.setAttribute('aria-describedby', `${field.getAttribute('aria-describedby') || ''} ${msg.id}`.trim());
        const a = h('a', { href: `#${field.id}` }, line);
        a.addEventListener('click', e => { e.preventDefault(); field.focus(); });
        ul.append(h('li', { 'data-pointer': p.pointer }, a));
      } else {
        ul.append(h('li', { 'data-pointer': p.pointer || '' }, line));
      }
      if (i === 0 && !field) text.setAttribute('aria-invalid', 'true');
    });
    problems.append(ul);
    problems.hidden = false;
    problems.focus();
  }

  submit.addEventListener('click', async () => {
    clearProblems();
    let doc;
    try { doc = parse(); } catch (e) { showProblems('The request is not JSON', [{ pointer: '', message: e.message }]); return; }
    submit.disabled = true;
    try {
      const r = await api.submit(opts.collection, doc);
      note.textContent = r.status === 200 ? 'Answered from the cache.' : 'Accepted: the job runs below.';
      await opts.onSubmitted(r, doc);
    } catch (e) {
      if (e instanceof ApiError && e.unauthorized) showProblems(e.tokenSent ? 'The API token was refused' : 'The service needs an API token', [{ pointer: '', message: describe(e), link: document.getElementById('api-token') }]);
      else if (e instanceof ApiError && e.errors.length) showProblems(`${e.problem.title} (${e.status}): ${e.errors.length === 1 ? 'a problem' : `${e.errors.length} problems`} in the request`, e.errors);
      else showProblems(e.status === 503 ? `The service is busy${e.problem && e.problem.retry_after_s ? `: retry in ${e.problem.retry_after_s} s` : ''}` : 'The request was not accepted', [{ pointer: '', message: describe(e) }]);
    } finally {
      submit.disabled = false;
    }
  });

  body.append(
    h('h3', { class: 'h4' }, 'Start from an example'), exBar, note,
    problems,
    h('fieldset', {}, h('legend', {}, 'Settings (written into the request below)'), grid),
    h('label', { for: text.id }, `${opts.noun} request (JSON)`),
    h('p', { id: `${prefix}-hint`, class: 'hint' }, 'As ', h('a', { href: `/v1/schemas/${opts.schema}` }, opts.schema),
      ' describes it; edit anything here. Problems are listed above with their JSON pointers.'),
    text, h('div', { class: 'actions' }, submit));
  return { setDoc, getDoc: parse, textarea: text };
}
