// The optimisation view: appears only when the service's contract (GET /v1/openapi.json) lists
// POST /v1/optimizations. The request is edited as JSON (schemas/optimization.schema.json, served
// at /v1/schemas/), submitted and followed by the same job view as studies (progress, cancel), and
// the Pareto front is drawn as a scatter whose points are buttons: click (or Enter) shows that
// point's design and figures.
//
// paretoPoints() and pointTable() are the only places that read the result's shape
// (schemas/optimization-result.schema.json).

import { api, ApiError, describe } from './api.js';
import { scatter, fmt } from './plots.js';

const COLLECTION = 'optimizations';

function h(tag, attrs = {}, ...children) {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs)) {
    if (v === undefined || v === null || v === false) continue;
    if (k === 'text') e.textContent = v; else e.setAttribute(k, String(v));
  }
  for (const c of children.flat()) if (c !== null && c !== undefined) e.append(c instanceof Node ? c : String(c));
  return e;
}

// The Pareto front of a result (schemas/optimization-result.schema.json): pareto.points, sorted by
// objective_a, each with variables, objectives, constraints, figures and design. x = objective_a,
// y = objective_b (efficiency and stiffness for the issue's sweep), read from the point's figures.
export function paretoPoints(result) {
  const pareto = result && result.pareto;
  if (!pareto || !Array.isArray(pareto.points)) return [];
  const a = pareto.objective_a, b = pareto.objective_b;
  const value = (p, name) => {
    if (p.figures && typeof p.figures[name] === 'number') return p.figures[name];
    const o = (p.objectives || []).find(x => x.name === name);
    return o ? o.value : null;
  };
  return pareto.points.map((p, i) => ({
    x: value(p, a), y: value(p, b), xKey: a, yKey: b, index: i, point: p,
    feasible: (p.constraints || []).every(c => c.satisfied),
  })).filter(p => typeof p.x === 'number' && typeof p.y === 'number');
}

function pointTable(point) {
  const rows = [];
  for (const [k, v] of Object.entries(point.variables || {})) if (v !== null) rows.push([k, v, '']);
  for (const [k, v] of Object.entries(point.figures || {})) if (v !== null) rows.push([k, v, '']);
  for (const c of point.constraints || []) rows.push([`${c.name} (${c.bound} ${fmt(c.limit)}${c.unit && c.unit !== '-' ? ` ${c.unit}` : ''})`, c.value, c.satisfied ? 'holds' : 'violated']);
  return h('table', { class: 'numbers', id: 'pareto-point-table' },
    h('caption', {}, 'The selected design'),
    h('tbody', {}, rows.map(([k, v, note]) => h('tr', { class: note === 'violated' ? 'violated' : undefined },
      h('th', { scope: 'row' }, k),
      h('td', { 'data-key': k, 'data-value': typeof v === 'number' ? String(v) : undefined }, `${typeof v === 'number' ? fmt(v) : String(v)}${note ? ` (${note})` : ''}`)))));
}

let useDesign = null; // (design) => loads it into the study form; set by setupOptimization

export function renderOptimizationResult(container, job) {
  container.textContent = '';
  const r = job.result || {};
  const pts = paretoPoints(r);
  container.append(h('p', {}, h('a', { href: job.links.self }, 'Result as JSON')));
  const summary = h('p', {}, `Method ${r.method}, ${r.status}${r.feasible === false ? ` (infeasible: ${(r.violated || []).join(', ')})` : ''}; ${r.evaluations} evaluations, stop: ${r.stop_reason}${r.cancelled ? ' (cancelled: best so far)' : ''}.`);
  container.append(summary);
  if (!pts.length) {
    container.append(h('p', { class: 'hint' }, 'No Pareto front in this result (not a sweep): its best design is below.'));
    if (r.best) container.append(h('div', { class: 'table-box' }, pointTable(r.best)), h('details', {}, h('summary', {}, 'Design as JSON'), h('pre', { class: 'json' }, JSON.stringify(r.best.design, null, 2))));
    return;
  }
  const detail = h('div', { class: 'table-box', id: 'pareto-detail' }, h('p', { class: 'hint' }, 'Click a point (or Tab to it and press Enter) to see its design.'));
  const svg = scatter({
    points: pts.map(p => ({ x: p.x, y: p.y, feasible: p.feasible, label: `${p.xKey} ${fmt(p.x)}, ${p.yKey} ${fmt(p.y)}` })),
    xLabel: pts[0].xKey, yLabel: pts[0].yKey,
    title: 'Pareto front', desc: `${pts.length} non-dominated designs`,
    onSelect: i => {
      detail.textContent = '';
      const design = pts[i].point.design;
      const use = design && useDesign ? h('button', { type: 'button', id: 'pareto-use' }, 'Study this design’s tolerances') : null;
      if (use) use.addEventListener('click', () => useDesign(design));
      detail.append(pointTable(pts[i].point), use || '', h('details', {}, h('summary', {}, 'Design as JSON'), h('pre', { class: 'json' }, JSON.stringify(design || pts[i].point, null, 2))));
    },
  });
  svg.id = 'pareto-plot';
  container.append(h('div', { class: 'figure-row' }, h('figure', { class: 'plot-box' }, svg), detail));
}

// ctx: {jobs (the JobView), form (the StudyForm), examples (the manifest's list), rememberRequest}
export function setupOptimization(openapi, ctx) {
  const paths = (openapi && openapi.paths) || {};
  const section = document.getElementById('optimization');
  if (!paths[`/v1/${COLLECTION}`]) return false;
  section.hidden = false;
  document.getElementById('nav-optimization').hidden = false;
  const body = document.getElementById('optimization-body');
  const text = h('textarea', { id: 'opt-request', rows: 16, spellcheck: 'false', 'aria-describedby': 'opt-hint' });
  const problems = h('div', { id: 'opt-problems', class: 'problems', role: 'alert' });
  const submit = h('button', { type: 'button', class: 'primary', id: 'opt-submit' }, 'Run optimisation');
  const exBar = h('div', { class: 'examples', role: 'group', 'aria-label': 'Optimisation examples' });
  for (const ex of ctx.examples.filter(e => e.kind === 'optimization')) {
    const b = h('button', { type: 'button', 'data-example': ex.file }, ex.label);
    b.addEventListener('click', async () => { text.value = JSON.stringify(await api.example(ex.file), null, 2); });
    exBar.appendChild(b);
  }
  body.append(exBar,
    h('label', { for: 'opt-request' }, 'Optimisation request (JSON)'),
    h('p', { id: 'opt-hint', class: 'hint' }, 'As ', h('a', { href: '/v1/schemas/optimization.schema.json' }, 'optimization.schema.json'), ' describes it; problems are listed below with their JSON pointers.'),
    text, problems, h('div', { class: 'actions' }, submit));
  ctx.jobs.renderOther = renderOptimizationResult;
  useDesign = design => {
    ctx.form.load({ ...ctx.form.toRequest(), design });
    document.getElementById('study-form').scrollIntoView();
    document.getElementById('f-starts').focus();
  };
  submit.addEventListener('click', async () => {
    problems.textContent = '';
    let doc;
    try { doc = JSON.parse(text.value); } catch (e) { problems.textContent = `Not JSON: ${e.message}`; return; }
    try {
      const r = await api.submit(COLLECTION, doc);
      ctx.rememberRequest(r.body.id, doc);
      history.replaceState(null, '', `#${r.body.links.self}`);
      await ctx.jobs.open(r.body.links.self, doc, COLLECTION);
    } catch (e) {
      const ul = h('ul', {}, (e instanceof ApiError && e.errors.length ? e.errors.map(p => `${p.pointer || '(document)'}: ${p.message}`) : [describe(e)]).map(t => h('li', {}, t)));
      problems.append(ul);
    }
  });
  return true;
}
