// The optimisation view: appears only when the service's contract (GET /v1/openapi.json) lists
// /v1/optimizations. The request (schemas/optimization.schema.json) is edited as JSON with its
// solver settings as fields, submitted and followed by the page's job view (evaluations, best
// objective so far, cancel). The result (schemas/optimization-result.schema.json): a summary, for a
// sweep the Pareto front as a scatter whose points are buttons (click, or Tab and Enter) with the
// same points in a table, the selected point's design, figures and constraints, and the best
// design with its figures and constraints; "Study this design's tolerances" loads a design into the
// study form.
//
// paretoPoints() and pointDetail() are the only places that read a point's shape.

import { api } from './api.js';
import { scatter, fmt } from './plots.js';
import { h, requestEditor } from './jobrequest.js';

const COLLECTION = 'optimizations';

// label and unit of the result's variables and figures
const NAMES = {
  starts: ['starts n', ''], pitch_mm: ['pitch P', 'mm'], lead_mm: ['lead', 'mm'], roller_radius_mm: ['roller radius r_r', 'mm'],
  screw_radius_mm: ['screw radius r_s', 'mm'], nut_radius_mm: ['nut radius r_n', 'mm'], rollers: ['rollers Z', ''],
  engaged_threads: ['engaged threads', ''], flank_angle_deg: ['flank angle β', '°'],
  efficiency: ['efficiency η', ''], stiffness_N_per_um: ['axial stiffness', 'N/µm'], mass_kg: ['mass', 'kg'],
  reflected_inertia_kg_m2: ['reflected inertia', 'kg·m²'], z_max: ['Z_max', ''], nut_outer_diameter_mm: ['nut outer diameter', 'mm'],
  screw_diameter_mm: ['screw diameter', 'mm'], static_safety: ['static safety', ''], life_h: ['L10 life', 'h'],
  life_revolutions: ['L10 life', 'rev'], p_max_MPa: ['p_max', 'MPa'], critical_speed_rpm: ['critical speed', 'rpm'],
  operating_speed_rpm: ['operating speed', 'rpm'],
};
const label = key => (NAMES[key] ? NAMES[key][0] : key);
const unit = key => (NAMES[key] ? NAMES[key][1] : '');
const withUnit = (v, key) => `${fmt(v)}${unit(key) && typeof v === 'number' ? ` ${unit(key)}` : ''}`;
const axisLabel = key => `${label(key)}${unit(key) ? ` (${unit(key)})` : ''}`;

// An objective whose points span less than this fraction of their value is drawn that wide (about
// their middle) instead of over the whole axis, and the chart says so.
const MIN_REL_SPAN = 0.02;
function spanText(pts, k) {
  const key = k === 'x' ? pts[0].xKey : pts[0].yKey;
  const v = pts.map(q => q[k]);
  const lo = Math.min(...v), hi = Math.max(...v);
  return `${label(key)} from ${fmt(lo, 5)} to ${fmt(hi, 5)}${unit(key) ? ` ${unit(key)}` : ''} (range ${fmt(hi - lo, 2)})`;
}

// The Pareto front of a result: pareto.points (sorted by objective_a), x = objective_a and
// y = objective_b (efficiency and stiffness for the issue's sweep), read from each point's figures
// (its objectives as a fallback). best: the point that is the result's best design.
export function paretoPoints(result) {
  const pareto = result && result.pareto;
  if (!pareto || !Array.isArray(pareto.points)) return [];
  const a = pareto.objective_a, b = pareto.objective_b;
  const value = (p, name) => {
    if (p.figures && typeof p.figures[name] === 'number') return p.figures[name];
    const o = (p.objectives || []).find(x => x.name === name);
    return o && typeof o.value === 'number' ? o.value : null;
  };
  const bestKey = result.best ? JSON.stringify(result.best.variables) : null;
  return pareto.points.map((p, i) => ({
    x: value(p, a), y: value(p, b), xKey: a, yKey: b, index: i, point: p,
    feasible: (p.constraints || []).every(c => c.satisfied),
    best: bestKey !== null && JSON.stringify(p.variables) === bestKey,
  })).filter(p => typeof p.x === 'number' && typeof p.y === 'number');
}

function kvTable(id, caption, rows) {
  return h('table', { class: 'numbers', id },
    h('caption', {}, caption),
    h('tbody', {}, rows.map(([key, v]) => h('tr', {},
      h('th', { scope: 'row' }, label(key)),
      h('td', { 'data-key': key, 'data-value': typeof v === 'number' ? String(v) : undefined }, withUnit(v, key))))));
}

function constraintTable(id, constraints) {
  return h('table', { class: 'numbers constraints', id },
    h('caption', {}, 'Constraints'),
    h('thead', {}, h('tr', {}, ['constraint', 'value', 'limit', 'holds'].map(c => h('th', { scope: 'col' }, c)))),
    h('tbody', {}, constraints.map(c => {
      const u = c.unit && c.unit !== '-' ? ` ${c.unit}` : '';
      return h('tr', { 'data-name': c.name, class: c.satisfied ? undefined : 'violated' },
        h('th', { scope: 'row', title: c.message || undefined }, c.name.replace(/_(mm|h|MPa)$/, '').replace(/_/g, ' ')),
        h('td', { 'data-key': 'value', 'data-value': typeof c.value === 'number' ? String(c.value) : undefined }, `${fmt(c.value)}${u}`),
        h('td', { 'data-key': 'limit', 'data-value': String(c.limit) }, `${c.bound === 'min' ? '≥' : '≤'} ${fmt(c.limit)}${u}`),
        h('td', { 'data-key': 'satisfied', 'data-value': String(c.satisfied) }, c.satisfied ? 'yes' : h('strong', {}, 'no')));
    })));
}

let useDesign = null; // (design) => loads it into the study form; set by setupOptimization

// One point (the best design or a point of the front): variables, objectives and figures, its
// constraints, the tolerance-study button and the design as JSON. idp: prefix of the ids.
function pointDetail(point, idp, heading) {
  const box = h('div', { class: 'point-detail', id: idp });
  box.append(h('h4', { class: 'h4' }, heading));
  const vars = Object.entries(point.variables || {}).filter(([, v]) => v !== null);
  const objs = (point.objectives || []).map(o => [o.name, o.value, o.sense]);
  const figs = Object.entries(point.figures || {}).filter(([k]) => !objs.some(o => o[0] === k));
  box.append(h('div', { class: 'tables' },
    kvTable(`${idp}-variables`, 'Design variables', vars),
    h('table', { class: 'numbers', id: `${idp}-objectives` }, h('caption', {}, 'Objectives'),
      h('tbody', {}, objs.map(([k, v, sense]) => h('tr', {}, h('th', { scope: 'row' }, `${label(k)} (${sense === 'maximise' ? 'max' : 'min'})`),
        h('td', { 'data-key': k, 'data-value': typeof v === 'number' ? String(v) : undefined }, withUnit(v, k)))))),
    kvTable(`${idp}-figures`, 'Other figures', figs),
    constraintTable(`${idp}-constraints`, point.constraints || [])));
  if (point.design) {
    const use = h('button', { type: 'button', id: `${idp}-study`, class: 'study-design' }, 'Study this design’s tolerances');
    use.addEventListener('click', () => useDesign && useDesign(point.design));
    box.append(h('div', { class: 'actions' }, use));
  }
  box.append(h('details', {}, h('summary', {}, 'Design as JSON (a document POST /v1/designs/analyze accepts)'),
    h('pre', { class: 'json', id: `${idp}-design` }, JSON.stringify(point.design, null, 2))));
  return box;
}

export function renderOptimizationResult(container, job) {
  container.textContent = '';
  const r = job.result || {};
  const s = r.search || {}, sv = r.solver || {};
  container.append(h('dl', { class: 'summary', id: 'opt-summary' },
    [['Optimisation', r.name || '—'], ['Method', r.method], ['Status', `${r.status}${r.feasible === false && r.violated && r.violated.length ? ` (violates ${r.violated.join(', ')})` : ''}`],
      ['Evaluations', fmt(r.evaluations, 6)], ['Stop reason', `${r.stop_reason}${r.cancelled ? ' (cancelled: best so far)' : ''}`],
      ['Integer combinations', `${s.combinations}, ${s.pruned} pruned`], ['NLopt runs', `${s.runs}, ${s.runs_feasible} feasible`],
      ['Solver', `${sv.algorithm}, ${sv.multistart} start${sv.multistart === 1 ? '' : 's'} per combination, seed ${sv.seed}`],
      ['Time', `${fmt(r.elapsed_s, 3)} s`], ['Cached', job.cache_hit ? 'yes' : 'no'], ['Engine', r.versions ? r.versions.engine : '—']]
      .map(([k, v]) => h('div', {}, h('dt', {}, k), h('dd', {}, String(v))))));
  container.append(h('p', { class: 'downloads' }, h('a', { href: job.links.self, id: 'opt-json-link' }, 'Result as JSON')));
  if (r.cancelled) container.append(h('p', { class: 'notice', id: 'opt-cancelled' }, 'The optimisation was cancelled: below is the best design found so far.'));
  if (r.warnings && r.warnings.length) container.append(h('ul', { class: 'warnings', 'aria-label': 'Warnings' }, r.warnings.map(w => h('li', {}, `${w.pointer ? `${w.pointer}: ` : ''}${w.message}`))));

  const pts = paretoPoints(r);
  if (pts.length) {
    const p = r.pareto;
    const live = h('p', { class: 'status', id: 'pareto-status', role: 'status', 'aria-live': 'polite' }, 'Click a point (or Tab to it and press Enter), or use a row’s button, to see that design.');
    const detail = h('div', { id: 'pareto-detail' });
    const rowsBody = h('tbody', {});
    const select = i => {
      const pt = pts[i];
      detail.textContent = '';
      detail.dataset.index = String(pt.index);
      detail.append(pointDetail(pt.point, 'pareto-point', `Point ${pt.index + 1} of the front${pt.best ? ' (the best design)' : ''}: ${label(pt.xKey)} ${withUnit(pt.x, pt.xKey)}, ${label(pt.yKey)} ${withUnit(pt.y, pt.yKey)}`));
      live.textContent = `Showing point ${pt.index + 1}: ${label(pt.xKey)} ${withUnit(pt.x, pt.xKey)}, ${label(pt.yKey)} ${withUnit(pt.y, pt.yKey)}.`;
      for (const tr of rowsBody.children) tr.classList.toggle('selected', tr.dataset.index === String(pt.index));
    };
    const svg = scatter({
      points: pts.map(q => ({ x: q.x, y: q.y, feasible: q.feasible, best: q.best,
        label: `Point ${q.index + 1}: ${label(q.xKey)} ${withUnit(q.x, q.xKey)}, ${label(q.yKey)} ${withUnit(q.y, q.yKey)}, ${q.point.variables.starts} starts, ${q.point.variables.rollers} rollers${q.best ? ' (best design)' : ''}` })),
      xLabel: axisLabel(p.objective_a), yLabel: axisLabel(p.objective_b),
      title: `Pareto front: ${label(p.objective_a)} against ${label(p.objective_b)}`,
      desc: `${pts.length} non-dominated designs from ${p.levels} ε-constraint levels (${p.epsilon_runs_feasible} of ${p.epsilon_runs} runs feasible, ${p.dominated_removed} dominated removed); ${spanText(pts, 'x')}; ${spanText(pts, 'y')}. The ringed point is the best design, the selected point is filled red. Each point is a button showing its design; the same points are in the table beside the chart.`,
      onSelect: select,
      legend: true,
      minRelSpan: MIN_REL_SPAN,
    });
    svg.id = 'pareto-plot';
    // an objective that hardly changes along the front is said so in words, not only drawn
    const narrow = ['x', 'y'].filter(k => svg.spans[k].widened).map(k => {
      const key = k === 'x' ? p.objective_a : p.objective_b, sp = svg.spans[k];
      return h('span', { class: 'span-note', 'data-axis': k, 'data-span': String(sp.span) },
        `${label(key)} varies by only ${fmt(sp.span, 2)}${unit(key) ? ` ${unit(key)}` : ''} along the front (range ${fmt(sp.lo, 5)} to ${fmt(sp.hi, 5)}, ${fmt(100 * sp.relative, 2)} % of its value): its axis is drawn ${fmt(100 * MIN_REL_SPAN, 2)} % of the value wide, not stretched over the whole plot, so this small difference does not look like a large trade-off. `);
    });
    for (const q of pts) {
      const b = h('button', { type: 'button', 'data-index': q.index, 'aria-label': `Show point ${q.index + 1}` }, 'Show');
      b.addEventListener('click', () => {
        const c = svg.querySelector(`.point[data-index="${pts.indexOf(q)}"]`);
        if (c) c.dispatchEvent(new MouseEvent('click'));
      });
      const v = q.point.variables;
      rowsBody.append(h('tr', { 'data-index': q.index, class: q.best ? 'best' : undefined },
        h('th', { scope: 'row' }, String(q.index + 1), q.best ? ' (best)' : ''),
        h('td', { 'data-key': q.xKey, 'data-value': String(q.x) }, fmt(q.x, 5)),
        h('td', { 'data-key': q.yKey, 'data-value': String(q.y) }, fmt(q.y, 5)),
        h('td', {}, String(v.starts)), h('td', {}, fmt(v.pitch_mm)), h('td', {}, fmt(v.roller_radius_mm)), h('td', {}, String(v.rollers)),
        h('td', {}, b)));
    }
    const table = h('table', { class: 'numbers', id: 'pareto-table' },
      h('caption', {}, 'The front’s points'),
      h('thead', {}, h('tr', {}, ['#', axisLabel(p.objective_a), axisLabel(p.objective_b), 'starts', 'pitch (mm)', 'r_r (mm)', 'Z', ''].map(c => h('th', { scope: 'col' }, c)))),
      rowsBody);
    container.append(h('section', { class: 'card', id: 'pareto-card', 'aria-labelledby': 'pareto-h' },
      h('h3', { id: 'pareto-h' }, `Pareto front: ${label(p.objective_a)} against ${label(p.objective_b)}`),
      h('div', { class: 'figure-row' }, h('figure', { class: 'plot-box' }, svg, h('figcaption', { id: 'pareto-caption' }, narrow, 'Filled: feasible; hollow: a constraint violated; ringed: the best design (closest to the ideal point); red: the selected point, whose design is shown below.')), h('div', { class: 'table-box' }, table)),
      live, detail));
  }
  const best = h('section', { class: 'card', id: 'best-card', 'aria-labelledby': 'best-h' },
    h('h3', { id: 'best-h' }, r.method === 'pareto' ? 'Best design (the front’s point closest to the ideal)' : 'Best design'));
  if (r.best) best.append(pointDetail(r.best, 'best-point', r.feasible ? 'Feasible: every constraint holds' : `Infeasible: ${(r.violated || []).join(', ')} violated`));
  else best.append(h('p', {}, 'No design could be analysed.'));
  container.append(best);
}

// ctx: {jobs (the JobView), form (the StudyForm), examples (the manifest's list), submitted(response, doc, collection)}
export function setupOptimization(openapi, ctx) {
  const paths = (openapi && openapi.paths) || {};
  if (!paths[`/v1/${COLLECTION}`]) return false;
  const section = document.getElementById('optimization');
  section.hidden = false;
  document.getElementById('nav-optimization').hidden = false;
  useDesign = design => {
    const named = ctx.loadDesign(design, {}, 'an optimised design');
    document.getElementById('examples-note').textContent = `Loaded the optimised design into the study form (tolerances and settings kept; ${named}).`;
    document.getElementById('study-form').scrollIntoView();
    document.getElementById('f-starts').focus();
  };
  ctx.jobs.renderers[COLLECTION] = renderOptimizationResult;
  const editor = requestEditor(document.getElementById('optimization-body'), {
    prefix: 'opt', collection: COLLECTION, noun: 'Optimisation', schema: 'optimization.schema.json',
    examples: ctx.examples.filter(e => e.kind === 'optimization'),
    submitLabel: 'Run optimisation',
    fields: [
      { path: 'solver.max_evaluations', label: 'Max evaluations', type: 'int', placeholder: '2000' },
      { path: 'solver.max_time_s', label: 'Time cap (s)', type: 'number', placeholder: '60' },
      { path: 'solver.multistart', label: 'Starts per combination', type: 'int', placeholder: '2' },
      { path: 'solver.seed', label: 'Seed', type: 'int', placeholder: '1' },
      { path: 'solver.algorithm', label: 'Algorithm', type: 'enum', options: ['cobyla', 'slsqp', 'mma', 'auglag'], placeholder: 'cobyla (default)' },
      { path: 'multi_objective.points', label: 'Pareto levels', type: 'int', placeholder: '7', hint: 'a Pareto sweep only' },
    ],
    onSubmitted: (r, doc) => ctx.submitted(r, doc, COLLECTION),
  });
  const first = ctx.examples.find(e => e.kind === 'optimization');
  if (first) api.example(first.file).then(doc => { if (!editor.textarea.value) editor.setDoc(doc, `Loaded ${first.file}; pick another example or edit the request.`); }).catch(() => {});
  return true;
}
