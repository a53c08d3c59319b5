// The study form: document <-> fields, the tolerance, output and target tables, and problems shown
// next to the field their JSON pointer names (schemas/problem.schema.json).
//
// Fields carry data-path ("design.geometry.pitch_mm"); every field and container also carries
// data-pointer ("/design/geometry/pitch_mm", "/tolerances/2/sd", "/tolerances/2"), refreshed when
// rows move, so a problem finds its field or, failing that, the nearest enclosing row or fieldset.
// Members the form does not edit (correlations, a fixed error set, losses, life ...) are kept from
// the loaded document and sent as they were.

const clone = v => (v === undefined ? undefined : JSON.parse(JSON.stringify(v)));

function getPath(obj, path) {
  return path.split('.').reduce((o, k) => (o && typeof o === 'object' ? o[k] : undefined), obj);
}
function setPath(obj, path, value) {
  const keys = path.split('.');
  let o = obj;
  for (const k of keys.slice(0, -1)) {
    if (!o[k] || typeof o[k] !== 'object' || Array.isArray(o[k])) o[k] = {};
    o = o[k];
  }
  o[keys[keys.length - 1]] = value;
}
function deletePath(obj, path) {
  const keys = path.split('.');
  const stack = [obj];
  for (const k of keys.slice(0, -1)) {
    const next = stack[stack.length - 1][k];
    if (!next || typeof next !== 'object') return;
    stack.push(next);
  }
  delete stack[stack.length - 1][keys[keys.length - 1]];
  // drop objects left empty by the deletion (not the root)
  for (let i = stack.length - 1; i > 0; i--) {
    if (Object.keys(stack[i]).length) break;
    delete stack[i - 1][keys[i - 1]];
  }
}

// A number from an <input>: undefined when blank; the text itself when it is not a number, so the
// API names the problem (the page does not second-guess the service's validation).
function readNumber(input, integer) {
  const raw = input.value.trim();
  if (raw === '') {
    // type=number reports "" for unparsable text: send what was typed, if anything
    return input.validity && input.validity.badInput ? 'not a number' : undefined;
  }
  const v = Number(raw);
  if (!Number.isFinite(v)) return raw;
  return integer && Number.isInteger(v) ? v : v;
}

// A list of numbers from a text <input> ("-0.02, 0, 0.02" or space-separated): undefined when
// blank; the text itself when an item is not a number, so the API names the problem.
function readList(input) {
  const raw = input.value.trim();
  if (raw === '') return undefined;
  const items = raw.split(/[\s,;]+/).filter(x => x !== '');
  const values = items.map(Number);
  return values.every(Number.isFinite) ? values : raw;
}

export const DISTRIBUTIONS = {
  shorthand: { label: 'tol ± (Cpk)', keys: ['tol', 'cpk', 'nominal'] },
  normal: { label: 'normal', keys: ['mean', 'sd'] },
  truncnormal: { label: 'truncated normal', keys: ['mean', 'sd', 'lower', 'upper'] },
  uniform: { label: 'uniform', keys: ['lower', 'upper'] },
  triangular: { label: 'triangular', keys: ['lower', 'mode', 'upper'] },
  lognormal: { label: 'lognormal', keys: ['mu', 'sigma'] },
  rayleigh: { label: 'Rayleigh', keys: ['sigma'] },
  exponential: { label: 'exponential', keys: ['scale', 'location'] },
  gamma: { label: 'gamma', keys: ['shape', 'scale', 'location'] },
  weibull: { label: 'Weibull', keys: ['shape', 'scale', 'location'] },
  beta: { label: 'beta', keys: ['alpha', 'beta', 'lower', 'upper'] },
  gumbel: { label: 'Gumbel (largest)', keys: ['location', 'scale'] },
  histogram: { label: 'histogram', keys: ['edges', 'weights'], lists: ['edges', 'weights'] },
};
// A parameter the form takes as a list of numbers (a histogram's edges and weights).
const isList = (dist, k) => (DISTRIBUTIONS[dist].lists || []).includes(k);
const TOL_KEYS = ['tol', 'tol_um', 'tol_mrad', 'tol_um_per_300mm'];

// The shorthand's key for a parameter: tol_um for *_um, tol_mrad for *_mrad, ...
export function tolKey(parameter) {
  if (/_um_per_300mm$/.test(parameter)) return 'tol_um_per_300mm';
  if (/_um$/.test(parameter)) return 'tol_um';
  if (/_mrad$/.test(parameter)) return 'tol_mrad';
  return 'tol';
}
export function unitOf(name) {
  if (/_um_per_300mm$/.test(name)) return 'µm/300 mm';
  if (/_um$/.test(name)) return 'µm';
  if (/_mrad$/.test(name)) return 'mrad';
  if (/_N_per_um$/.test(name)) return 'N/µm';
  return '';
}
const perItem = p => /^roller\.|\.start_index_mrad$/.test(p);

let fieldSeq = 0;
function input(type, attrs) {
  const e = document.createElement('input');
  e.type = type;
  if (type === 'number') e.step = 'any';
  for (const [k, v] of Object.entries(attrs)) e.setAttribute(k, v);
  return e;
}
function select(options, value, attrs = {}) {
  const s = document.createElement('select');
  for (const [v, label, title] of options) {
    const o = document.createElement('option');
    o.value = v;
    o.textContent = label;
    if (title) o.title = title;
    s.appendChild(o);
  }
  for (const [k, v] of Object.entries(attrs)) s.setAttribute(k, v);
  if (value !== undefined) s.value = value;
  return s;
}
function button(text, label) {
  const b = document.createElement('button');
  b.type = 'button';
  b.textContent = text;
  if (label) b.setAttribute('aria-label', label);
  return b;
}

export class StudyForm {
  // info: {parameters: [{name, description}], outputs: [{name, description}]} from study.schema.json
  constructor(form, info) {
    this.form = form;
    this.info = info;
    this.base = {};
    this.listeners = { design: [], change: [] };
    this.tolBody = form.querySelector('#tolerances tbody');
    this.outBody = form.querySelector('#outputs tbody');
    this.targetBody = form.querySelector('#targets tbody');
    this.fields = [...form.querySelectorAll('[data-path]')];
    for (const f of this.fields) f.dataset.pointer = '/' + f.dataset.path.split('.').join('/');
    this.buildOutputs();
    form.querySelector('#add-tolerance').addEventListener('click', () => {
      const used = new Set(this.tolRows().map(r => r.param.value));
      const free = info.parameters.find(p => !used.has(p.name));
      const row = this.addTolerance({ parameter: free ? free.name : info.parameters[0].name, tol_um: 1 });
      this.renumber();
      row.param.focus();
      this.changed();
    });
    form.querySelector('#add-target').addEventListener('click', () => {
      const row = this.addTarget({ output: this.checkedOutputs()[0] || 'backlash_um', standard_error: 0.05 });
      this.renumber();
      row.output.focus();
      this.changed();
    });
    const sobol = form.querySelector('#f-sobol');
    sobol.addEventListener('change', () => this.syncSobol());
    form.addEventListener('input', e => this.onEdit(e));
    form.addEventListener('change', e => this.onEdit(e));
  }

  on(event, fn) { this.listeners[event].push(fn); }
  changed(design) {
    if (design) this.listeners.design.forEach(f => f());
    this.listeners.change.forEach(f => f());
  }
  onEdit(e) {
    const t = e.target;
    if (!(t instanceof HTMLElement) || !t.dataset) return;
    this.clearFieldProblems(t, 'submit');
    if (e.type === 'input' && t.tagName === 'SELECT') return;
    this.changed(t.hasAttribute('data-design'));
  }

  syncSobol() {
    const on = this.form.querySelector('#f-sobol').checked;
    for (const id of ['#f-sobol-n', '#f-sobol-b']) this.form.querySelector(id).disabled = !on;
  }

  // ---- outputs and specs -------------------------------------------------------------------
  buildOutputs() {
    this.outRows = new Map();
    for (const o of this.info.outputs) {
      const tr = document.createElement('tr');
      const id = `out-${o.name}`;
      const th = document.createElement('th');
      th.scope = 'row';
      const cb = input('checkbox', { id, 'data-output': o.name });
      const lab = document.createElement('label');
      lab.htmlFor = id;
      lab.textContent = o.name;
      lab.title = o.description;
      th.append(cb, ' ', lab);
      const small = document.createElement('small');
      small.className = 'hint block';
      small.textContent = o.description;
      th.appendChild(small);
      tr.appendChild(th);
      const cells = {};
      for (const k of ['lower', 'upper']) {
        const td = document.createElement('td');
        const inp = input('number', { 'aria-label': `${o.name} ${k} specification limit`, 'data-pointer': `/specs/${o.name}/${k}`, 'data-spec': k });
        td.appendChild(inp);
        tr.appendChild(td);
        cells[k] = inp;
      }
      tr.dataset.pointer = `/specs/${o.name}`;
      this.outBody.appendChild(tr);
      this.outRows.set(o.name, { tr, cb, ...cells });
    }
  }
  checkedOutputs() {
    return this.info.outputs.map(o => o.name).filter(n => this.outRows.get(n).cb.checked);
  }

  // ---- tolerance rows ----------------------------------------------------------------------
  tolRows() { return [...this.tolBody.rows].map(tr => tr._row); }

  addTolerance(t) {
    const tr = document.createElement('tr');
    const row = { tr, values: {} };
    tr._row = row;
    const num = document.createElement('td');
    num.className = 'num';
    const known = this.info.parameters.some(p => p.name === t.parameter);
    const params = this.info.parameters.map(p => [p.name, p.name, p.description]);
    if (!known) params.push([t.parameter, t.parameter, '']);
    row.param = select(params, t.parameter, {});
    const dist = t.distribution || 'shorthand';
    row.dist = select(Object.entries(DISTRIBUTIONS).map(([k, d]) => [k, d.label]), dist, {});
    row.paramsCell = document.createElement('td');
    row.paramsCell.className = 'params';
    row.shared = input('checkbox', {});
    row.shared.checked = !!t.shared;
    row.remove = button('Remove', '');
    for (const k of Object.keys(t)) if (!['parameter', 'distribution', 'shared'].includes(k)) row.values[TOL_KEYS.includes(k) ? 'tol' : k] = t[k];
    const cells = [num, row.param, row.dist, row.paramsCell, row.shared, row.remove].map(c => {
      if (c.tagName === 'TD') return c;
      const td = document.createElement('td');
      td.appendChild(c);
      return td;
    });
    tr.append(...cells);
    this.tolBody.appendChild(tr);
    row.param.addEventListener('change', () => { this.renderParams(row); this.renumber(); });
    row.dist.addEventListener('change', () => { this.captureParams(row); this.renderParams(row); this.renumber(); });
    row.remove.addEventListener('click', () => {
      const next = tr.nextElementSibling || tr.previousElementSibling;
      tr.remove();
      this.renumber();
      (next ? next._row.remove : this.form.querySelector('#add-tolerance')).focus();
      this.changed();
    });
    this.renderParams(row);
    return row;
  }

  captureParams(row) {
    for (const inp of row.paramsCell.querySelectorAll('input')) {
      const v = inp.dataset.list ? readList(inp) : readNumber(inp);
      if (v === undefined) delete row.values[inp.dataset.key];
      else row.values[inp.dataset.key] = v;
    }
  }

  renderParams(row) {
    this.captureParams(row);
    row.paramsCell.textContent = '';
    const d = DISTRIBUTIONS[row.dist.value];
    const unit = unitOf(row.param.value);
    row.inputs = {};
    for (const k of d.keys) {
      const id = `tolp${++fieldSeq}`;
      const wrap = document.createElement('span');
      wrap.className = 'param';
      const lab = document.createElement('label');
      lab.htmlFor = id;
      lab.textContent = k === 'tol' ? `tol ±${unit ? ` (${unit})` : ''}` : k;
      const list = isList(row.dist.value, k);
      const inp = list ? input('text', { id, 'data-key': k, 'data-list': '1' }) : input('number', { id, 'data-key': k });
      if (k === 'cpk') inp.placeholder = '1';
      if (k === 'nominal' || k === 'mean' || k === 'location') inp.placeholder = '0';
      if (list) inp.placeholder = k === 'edges' ? '-2, -1, 0, 1, 2' : '1, 3, 3, 1';
      const v = row.values[k];
      if (v !== undefined) inp.value = Array.isArray(v) ? v.join(', ') : String(v);
      wrap.append(lab, inp);
      row.paramsCell.appendChild(wrap);
      row.inputs[k] = inp;
    }
    row.shared.disabled = !perItem(row.param.value);
    if (row.shared.disabled) row.shared.checked = false;
  }

  // ---- target rows -------------------------------------------------------------------------
  targetRows() { return [...this.targetBody.rows].map(tr => tr._row); }

  addTarget(t) {
    const tr = document.createElement('tr');
    const row = { tr };
    tr._row = row;
    const num = document.createElement('td');
    num.className = 'num';
    const names = this.info.outputs.map(o => [o.name, o.name]);
    if (!this.info.outputs.some(o => o.name === t.output)) names.push([t.output, t.output]);
    row.output = select(names, t.output);
    const kind = ['standard_error', 'cv', 'yield_interval_width'].find(k => k in t) || 'standard_error';
    row.kind = select([['standard_error', 'standard error of the mean'], ['cv', 'coefficient of variation of the mean'], ['yield_interval_width', 'width of the 95 % yield interval']], kind);
    row.value = input('number', {});
    if (t[kind] !== undefined) row.value.value = String(t[kind]);
    row.remove = button('Remove', '');
    tr.append(num, ...[row.output, row.kind, row.value, row.remove].map(c => { const td = document.createElement('td'); td.appendChild(c); return td; }));
    this.targetBody.appendChild(tr);
    row.kind.addEventListener('change', () => this.renumber());
    row.remove.addEventListener('click', () => {
      const next = tr.nextElementSibling || tr.previousElementSibling;
      tr.remove();
      this.renumber();
      (next ? next._row.remove : this.form.querySelector('#add-target')).focus();
      this.changed();
    });
    return row;
  }

  // Row numbers, accessible names and JSON pointers follow the rows' order.
  renumber() {
    this.tolRows().forEach((row, i) => {
      const n = i + 1;
      row.tr.dataset.pointer = `/tolerances/${i}`;
      row.tr.cells[0].textContent = String(n);
      row.param.setAttribute('aria-label', `Tolerance ${n} parameter`);
      row.param.dataset.pointer = `/tolerances/${i}/parameter`;
      row.dist.setAttribute('aria-label', `Tolerance ${n} distribution`);
      row.dist.dataset.pointer = `/tolerances/${i}/distribution`;
      row.shared.setAttribute('aria-label', `Tolerance ${n}: one value for every roller or start`);
      row.shared.dataset.pointer = `/tolerances/${i}/shared`;
      row.remove.setAttribute('aria-label', `Remove tolerance ${n} (${row.param.value})`);
      for (const [k, inp] of Object.entries(row.inputs)) {
        const key = k === 'tol' ? tolKey(row.param.value) : k;
        inp.dataset.pointer = `/tolerances/${i}/${key}`;
        inp.setAttribute('aria-label', `Tolerance ${n} ${k === 'tol' ? 'tolerance' : k}`);
      }
    });
    this.targetRows().forEach((row, i) => {
      const n = i + 1;
      row.tr.dataset.pointer = `/monte_carlo/targets/${i}`;
      row.tr.cells[0].textContent = String(n);
      row.output.setAttribute('aria-label', `Target ${n} output`);
      row.output.dataset.pointer = `/monte_carlo/targets/${i}/output`;
      row.kind.setAttribute('aria-label', `Target ${n} statistic`);
      row.value.setAttribute('aria-label', `Target ${n} value`);
      row.value.dataset.pointer = `/monte_carlo/targets/${i}/${row.kind.value}`;
      row.remove.setAttribute('aria-label', `Remove target ${n}`);
    });
    let j = 0;
    for (const [, r] of this.outRows) {
      if (r.cb.checked) r.cb.dataset.pointer = `/outputs/${j++}`;
      else delete r.cb.dataset.pointer;
    }
  }

  // ---- document in and out -----------------------------------------------------------------
  load(doc) {
    this.clearProblems();
    this.base = clone(doc) || {};
    for (const f of this.fields) {
      const v = getPath(this.base, f.dataset.path);
      if (f.type === 'checkbox') f.checked = v === undefined ? f.dataset.default === 'true' : !!v;
      else f.value = v === undefined || v === null ? '' : String(v);
    }
    const sobol = this.base.sensitivity && this.base.sensitivity.sobol;
    this.form.querySelector('#f-sobol').checked = !!sobol;
    this.form.querySelector('#f-sobol-n').value = sobol && typeof sobol === 'object' && sobol.samples !== undefined ? String(sobol.samples) : '';
    this.form.querySelector('#f-sobol-b').value = sobol && typeof sobol === 'object' && sobol.bootstrap !== undefined ? String(sobol.bootstrap) : '';
    this.syncSobol();
    this.tolBody.textContent = '';
    for (const t of this.base.tolerances || []) this.addTolerance(t);
    this.targetBody.textContent = '';
    for (const t of (this.base.monte_carlo && this.base.monte_carlo.targets) || []) this.addTarget(t);
    const outs = new Set(this.base.outputs || []);
    for (const [name, r] of this.outRows) {
      r.cb.checked = outs.has(name);
      const s = (this.base.specs || {})[name] || {};
      r.lower.value = s.lower !== undefined ? String(s.lower) : '';
      r.upper.value = s.upper !== undefined ? String(s.upper) : '';
    }
    this.renumber();
    const note = this.form.querySelector('#passthrough-note');
    const kept = [];
    if (this.base.correlations) kept.push(`correlations (${this.base.correlations.length})`);
    if (this.base.errors) kept.push('a fixed error set (errors)');
    if (this.base.design) for (const k of ['thinning', 'materials', 'losses', 'stiffness', 'life', 'column', 'description']) if (k in this.base.design) kept.push(`design.${k}`);
    if (this.base.assembly) for (const k of Object.keys(this.base.assembly)) if (!['mode', 'angles_per_revolution', 'measuring_load_N'].includes(k)) kept.push(`assembly.${k}`);
    note.hidden = !kept.length;
    note.textContent = kept.length ? `Also sent as loaded (edit the exported JSON to change): ${kept.join(', ')}.` : '';
    this.changed(true);
  }

  toRequest() {
    const doc = clone(this.base) || {};
    for (const f of this.fields) {
      const path = f.dataset.path, type = f.dataset.type;
      let v;
      if (type === 'bool') v = f.checked;
      else if (type === 'int' || type === 'number') v = readNumber(f, type === 'int');
      else v = f.value === '' ? undefined : f.value;
      if (v === undefined) deletePath(doc, path);
      else setPath(doc, path, v);
    }
    if (this.form.querySelector('#f-sobol').checked) {
      const s = {};
      const n = readNumber(this.form.querySelector('#f-sobol-n'), true), b = readNumber(this.form.querySelector('#f-sobol-b'), true);
      if (n !== undefined) s.samples = n;
      if (b !== undefined) s.bootstrap = b;
      const old = doc.sensitivity && typeof doc.sensitivity.sobol === 'object' ? doc.sensitivity.sobol : {};
      if (old.sampler) s.sampler = old.sampler;
      setPath(doc, 'sensitivity.sobol', Object.keys(s).length ? s : true);
    } else if (doc.sensitivity) {
      delete doc.sensitivity.sobol;
    }
    doc.tolerances = this.tolRows().map(row => {
      this.captureParams(row);
      const t = { parameter: row.param.value };
      if (row.dist.value !== 'shorthand') t.distribution = row.dist.value;
      for (const k of DISTRIBUTIONS[row.dist.value].keys) {
        const v = isList(row.dist.value, k) ? readList(row.inputs[k]) : readNumber(row.inputs[k]);
        if (v !== undefined) t[k === 'tol' ? tolKey(row.param.value) : k] = v;
      }
      if (row.shared.checked) t.shared = true;
      return t;
    });
    const outs = this.checkedOutputs();
    if (outs.length) doc.outputs = outs;
    else delete doc.outputs;
    const specs = {};
    for (const [name, r] of this.outRows) {
      const s = {};
      for (const k of ['lower', 'upper']) {
        const v = readNumber(r[k]);
        if (v !== undefined) s[k] = v;
      }
      if (Object.keys(s).length) specs[name] = s;
    }
    if (Object.keys(specs).length) doc.specs = specs;
    else delete doc.specs;
    const targets = this.targetRows().map(row => {
      const t = { output: row.output.value };
      const v = readNumber(row.value);
      t[row.kind.value] = v === undefined ? null : v;
      return t;
    });
    if (targets.length) setPath(doc, 'monte_carlo.targets', targets);
    else if (doc.monte_carlo) deletePath(doc, 'monte_carlo.targets');
    this.renumber();
    return doc;
  }

  // The design alone, for POST /v1/designs/analyze (its pointers lack the /design prefix).
  designDoc() { return this.toRequest().design || {}; }

  // ---- problems ----------------------------------------------------------------------------
  // The element a pointer names: the field itself, or the nearest enclosing row or fieldset.
  locate(pointer) {
    let p = pointer;
    while (p) {
      const e = this.form.querySelector(`[data-pointer="${CSS.escape(p)}"]`);
      if (e) return { element: e, exact: p === pointer };
      p = p.slice(0, p.lastIndexOf('/'));
    }
    return { element: null, exact: false };
  }

  // problems: [{pointer, message, code?}] as the API gives them, pointers relative to prefix
  // ("/design" for the analyze endpoint). source: "submit" or "analyze"; kind: "error" or "warning".
  // Returns the problems with the element each was put next to.
  showProblems(problems, { prefix = '', source = 'submit', kind = 'error' } = {}) {
    const placed = [];
    for (const pr of problems) {
      const pointer = prefix + (pr.pointer || '');
      const { element } = pointer ? this.locate(pointer) : { element: null };
      if (element) this.attach(element, pr, pointer, source, kind);
      placed.push({ ...pr, pointer, element });
    }
    return placed;
  }

  attach(element, pr, pointer, source, kind) {
    const isField = /^(INPUT|SELECT|TEXTAREA)$/.test(element.tagName);
    const host = isField ? element.closest('.field, td, th') || element.parentElement : element;
    let box = [...host.children].find(c => c.classList.contains('problems'));
    if (!box) {
      box = document.createElement('div');
      box.className = 'problems';
      if (element.tagName === 'FIELDSET') element.insertBefore(box, element.children[1] || null);
      else if (element.tagName === 'TR') {
        const td = element.cells[element.cells.length - 1];
        td.appendChild(box);
      } else host.appendChild(box);
    }
    if ([...box.children].some(c => c.dataset.text === pr.message && c.dataset.pointer === pointer)) return;
    const msg = document.createElement('p');
    msg.className = `problem-msg ${kind}`;
    msg.id = `problem${++fieldSeq}`;
    msg.dataset.source = source;
    msg.dataset.pointer = pointer;
    msg.dataset.text = pr.message;
    msg.textContent = pr.message;
    if (!isField || element.dataset.pointer !== pointer) {
      const code = document.createElement('code');
      code.textContent = pointer;
      msg.prepend(code, ' ');
    }
    box.appendChild(msg);
    const target = isField ? element : element.querySelector('input, select');
    if (target) {
      const ids = new Set((target.getAttribute('aria-describedby') || '').split(/\s+/).filter(Boolean));
      ids.add(msg.id);
      target.setAttribute('aria-describedby', [...ids].join(' '));
      if (kind === 'error') target.setAttribute('aria-invalid', 'true');
    }
  }

  clearProblems(source) {
    for (const m of [...this.form.querySelectorAll('.problem-msg')]) {
      if (source && m.dataset.source !== source) continue;
      this.detach(m);
    }
  }
  clearFieldProblems(field, source) {
    const p = field.dataset && field.dataset.pointer;
    if (!p) return;
    for (const m of [...this.form.querySelectorAll('.problem-msg')]) if (m.dataset.source === source && m.dataset.pointer === p) this.detach(m);
  }
  detach(m) {
    const id = m.id;
    for (const t of this.form.querySelectorAll(`[aria-describedby~="${id}"]`)) {
      const ids = t.getAttribute('aria-describedby').split(/\s+/).filter(x => x && x !== id);
      if (ids.length) t.setAttribute('aria-describedby', ids.join(' '));
      else t.removeAttribute('aria-describedby');
      if (!ids.some(x => { const e = document.getElementById(x); return e && e.classList.contains('error'); })) t.removeAttribute('aria-invalid');
    }
    const box = m.parentElement;
    m.remove();
    if (box && !box.children.length) box.remove();
  }
}

// Parameter and output lists (with descriptions) from study.schema.json.
export function schemaInfo(studySchema) {
  const defs = studySchema.$defs || {};
  const list = d => ((defs[d] && defs[d].oneOf) || []).filter(x => 'const' in x).map(x => ({ name: x.const, description: x.description || '' }));
  return { parameters: list('design_parameter'), outputs: list('output_name') };
}
