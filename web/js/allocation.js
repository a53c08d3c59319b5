// The allocation view: appears only when GET /v1/openapi.json lists /v1/allocations. The request
// (schemas/allocation.schema.json) is edited as JSON with its stack, solver and Monte Carlo
// settings as fields, and followed by the page's job view (samples, least cost so far, cancel).
// The result (schemas/allocation-result.schema.json): per tolerance the allocated half-width with
// its unit, the linear allocation, bounds and cost; the total cost; per constraint the predicted
// (linear, normal) yield and the Monte Carlo yield with its 95 % interval; a chart of the allocated
// half-widths against their bounds and a chart and table of the Monte Carlo correction steps.

import { api } from './api.js';
import { rangeChart, intervalChart, fmt, percent } from './plots.js';
import { h, requestEditor } from './jobrequest.js';

const COLLECTION = 'allocations';

const unitText = u => ({ um: 'µm', mrad: 'mrad', um_per_300mm: 'µm/300 mm', '': '' }[u] ?? u);
const withUnit = (v, u) => `${fmt(v)}${unitText(u) ? ` ${unitText(u)}` : ''}`;

function costModel(c) {
  if (!c) return '—';
  const A = c.fixed ? `${fmt(c.fixed)} + ` : '';
  if (c.model === 'reciprocal') return `${A}${fmt(c.coefficient)}/T`;
  if (c.model === 'reciprocal_squared') return `${A}${fmt(c.coefficient)}/T²`;
  if (c.model === 'reciprocal_power') return `${A}${fmt(c.coefficient)}/T^${fmt(c.power)}`;
  if (c.model === 'exponential') return `${A}${fmt(c.coefficient)}·exp(−${fmt(c.rate)} T)`;
  return c.model;
}
const numTd = (key, v, shown) => h('td', { 'data-key': key, 'data-value': typeof v === 'number' ? String(v) : undefined }, shown !== undefined ? shown : fmt(v));
const specText = s => (s ? `${s.lower !== undefined ? fmt(s.lower) : '—'} to ${s.upper !== undefined ? fmt(s.upper) : '—'}` : '—');

function toleranceTable(r) {
  const outs = r.constraints.map(c => c.output);
  const linear = (r.linear && r.linear.half_widths) || [];
  const head = ['tolerance', 'allocated ± (unit)', 'linear model ±', 'reference ±', 'bounds', 'cost', 'cost model', ...outs.map(o => `∂${o}/∂T`)];
  return h('table', { class: 'numbers', id: 'alloc-tolerances' },
    h('caption', {}, 'Allocated tolerances (half-widths) and their cost'),
    h('thead', {}, h('tr', {}, head.map(c => h('th', { scope: 'col' }, c)))),
    h('tbody', {}, r.tolerances.map((t, i) => h('tr', { 'data-parameter': t.parameter, class: t.at_bound ? 'at-bound' : undefined },
      h('th', { scope: 'row' }, t.parameter),
      numTd('half_width', t.half_width, `${withUnit(t.half_width, t.unit)}${t.at_bound ? ` (at ${t.at_bound} bound)` : ''}`),
      numTd('linear_half_width', linear[i], withUnit(linear[i], t.unit)),
      numTd('reference_half_width', t.reference_half_width, t.reference_half_width === null ? '—' : withUnit(t.reference_half_width, t.unit)),
      numTd('bounds', null, `${fmt(t.bounds.lower)} to ${t.bounds.upper === null ? 'none' : fmt(t.bounds.upper)}`),
      numTd('cost', t.cost),
      numTd('cost_model', null, costModel(t.cost_model)),
      outs.map(o => numTd(`sensitivity:${o}`, t.sensitivities[o]))))),
    h('tfoot', {}, h('tr', {},
      h('th', { scope: 'row' }, 'total cost'), h('td', {}, ''), h('td', {}, ''), h('td', {}, ''), h('td', {}, ''),
      numTd('total_cost', r.total_cost), h('td', { 'data-key': 'linear_total_cost', 'data-value': String(r.linear.total_cost) }, `linear model: ${fmt(r.linear.total_cost)}`),
      outs.map(() => h('td', {}, '')))));
}

function constraintTable(r) {
  const head = ['output', 'spec', 'nominal', 'target yield', 'T_asm (linear → reported)', 'predicted sd', 'predicted yield (linear)', 'Monte Carlo yield', 'its 95 % interval', 'samples', 'meets target'];
  return h('table', { class: 'numbers', id: 'alloc-constraints' },
    h('caption', {}, 'Yield per constraint: the linear model’s prediction and Monte Carlo'),
    h('thead', {}, h('tr', {}, head.map(c => h('th', { scope: 'col' }, c)))),
    h('tbody', {}, r.constraints.map(c => {
      const mc = c.monte_carlo;
      return h('tr', { 'data-output': c.output, class: c.meets_target === false ? 'violated' : undefined },
        h('th', { scope: 'row' }, c.output),
        numTd('spec', null, specText(c.spec)),
        numTd('nominal', c.nominal),
        numTd('target_yield', c.target_yield, c.target_yield === null ? '— (T_asm given)' : percent(c.target_yield, 3)),
        numTd('assembly_tolerance', c.assembly_tolerance, `${fmt(c.assembly_tolerance_linear)} → ${fmt(c.assembly_tolerance)}`),
        numTd('predicted_sd', c.predicted_sd),
        numTd('predicted_yield', c.predicted_yield, percent(c.predicted_yield, 3)),
        numTd('mc_yield', mc ? mc.fraction : null, mc ? percent(mc.fraction, 3) : '— (no Monte Carlo)'),
        mc ? h('td', { 'data-key': 'mc_interval', 'data-lo': String(mc.interval95[0]), 'data-hi': String(mc.interval95[1]) }, `${percent(mc.interval95[0], 3)} to ${percent(mc.interval95[1], 3)}`) : numTd('mc_interval', null, '—'),
        numTd('mc_samples', mc ? mc.samples : null, mc ? fmt(mc.samples, 7) : '—'),
        numTd('meets_target', null, c.meets_target === null ? '—' : c.meets_target ? 'yes' : 'no'));
    })));
}

function stepsTable(r) {
  const outs = r.constraints.map(c => c.output);
  return h('table', { class: 'numbers', id: 'alloc-steps' },
    h('caption', {}, 'Monte Carlo correction steps (scale 1: the linear allocation)'),
    h('thead', {}, h('tr', {}, ['step', 'scale of T_asm', 'total cost', ...outs.map(o => `${o} yield (95 %)`), 'meets target', 'reported'].map(c => h('th', { scope: 'col' }, c)))),
    h('tbody', {}, r.correction.steps.map((s, i) => h('tr', { 'data-step': i, class: s.reported ? 'selected' : undefined },
      h('th', { scope: 'row' }, String(i)),
      numTd('scale', s.scale, fmt(s.scale, 5)),
      numTd('total_cost', s.total_cost),
      s.yields.map(y => numTd('yield', y ? y.fraction : null, y ? `${percent(y.fraction, 3)} (${percent(y.interval95[0], 2)} to ${percent(y.interval95[1], 2)})` : '—')),
      h('td', {}, s.meets_target ? 'yes' : 'no'), h('td', {}, s.reported ? 'yes' : '')))));
}

export function renderAllocationResult(container, job) {
  container.textContent = '';
  const r = job.result || {};
  const corr = r.correction || {}, mc = r.monte_carlo;
  container.append(h('dl', { class: 'summary', id: 'alloc-summary' },
    [['Allocation', r.name || '—'], ['Model', r.kind === 'study' ? 'tolerance study (sensitivities by central differences)' : 'analytic stack'],
      ['Stack', r.stack === 'rss' ? 'RSS' : 'worst case'], ['Solver', r.solver],
      ['Total cost', fmt(r.total_cost)], ['Linear model’s cost', fmt(r.linear && r.linear.total_cost)],
      ['Correction', `${corr.stop_reason}${corr.converged && corr.stop_reason !== 'converged' ? ' (converged)' : ''}, scale ${fmt(corr.scale, 5)}, ${corr.steps ? corr.steps.length : 0} step${corr.steps && corr.steps.length === 1 ? '' : 's'}`],
      ['Monte Carlo', mc ? `${fmt(mc.samples, 7)} samples a step (${mc.sampler}, seed ${mc.seed}), ${fmt(mc.samples_total, 8)} in all` : 'none'],
      ['Evaluations', fmt(r.evaluations, 7)], ['Time', `${fmt(r.elapsed_s, 3)} s`], ['Cached', job.cache_hit ? 'yes' : 'no'],
      ['Engine', r.versions ? r.versions.engine.replace(/ \(.*$/, '') : '—']]
      .map(([k, v]) => h('div', {}, h('dt', {}, k), h('dd', {}, String(v))))));
  container.append(h('p', { class: 'downloads' }, h('a', { href: job.links.self, id: 'alloc-json-link' }, 'Result as JSON')));
  if (r.cancelled) container.append(h('p', { class: 'notice', id: 'alloc-cancelled' }, 'The allocation was cancelled: below is the best allocation found so far.'));
  if (!Array.isArray(r.tolerances)) return;

  const cheapest = h('p', { class: 'total', id: 'alloc-total' }, 'Total cost ', h('strong', { 'data-value': String(r.total_cost) }, fmt(r.total_cost)),
    ` (the linear model alone: ${fmt(r.linear.total_cost)})`);
  const units = [...new Set(r.tolerances.map(t => unitText(t.unit)).filter(Boolean))];
  const range = rangeChart({
    items: r.tolerances.map((t, i) => ({ label: t.parameter, value: t.half_width, lo: t.bounds.lower, hi: t.bounds.upper,
      mark: r.linear.half_widths[i], ref: t.reference_half_width === null ? undefined : t.reference_half_width, atBound: t.at_bound })),
    xLabel: `half-width${units.length ? ` (${units.join(', ')}: each tolerance's unit)` : ''}, log scale`,
    markLabel: 'linear model', refLabel: 'reference',
    title: 'Allocated half-widths against their bounds',
    desc: `${r.tolerances.length} tolerances; total cost ${fmt(r.total_cost)}; ${r.tolerances.filter(t => t.at_bound).length} at a bound: ${r.tolerances.map(t => `${t.parameter} ${fmt(t.half_width)}`).join(', ')}. Every number is in the table below the chart.`,
  });
  range.id = 'alloc-range-plot';
  container.append(h('section', { class: 'card', id: 'alloc-tolerance-card', 'aria-labelledby': 'alloc-tol-h' },
    h('h3', { id: 'alloc-tol-h' }, 'Allocated tolerances'), cheapest,
    h('figure', { class: 'plot-box wide' }, range, h('figcaption', {}, 'Grey: the allowed range (bounds); blue bar: the allocated half-width (orange at a bound); dark tick: the linear model’s allocation; dashed tick: the reference half-width.')),
    h('div', { class: 'table-wrap' }, toleranceTable(r)),
    h('details', {}, h('summary', {}, 'Convention and sensitivities'), h('p', { class: 'hint' }, r.convention), h('p', { class: 'hint' }, `Sensitivities: ${r.sensitivity_source}.`))));

  const yieldCard = h('section', { class: 'card', id: 'alloc-yield-card', 'aria-labelledby': 'alloc-yield-h' },
    h('h3', { id: 'alloc-yield-h' }, 'Predicted and Monte Carlo yield'), h('div', { class: 'table-wrap' }, constraintTable(r)));
  const steps = corr.steps || [];
  if (steps.some(s => s.yields.some(y => y))) {
    const row = h('div', { class: 'figure-row steps' });
    r.constraints.forEach((c, ci) => {
      const svg = intervalChart({
        points: steps.map((s, i) => {
          const y = s.yields[ci];
          return { label: String(i), y: y ? 100 * y.fraction : null, lo: y ? 100 * y.interval95[0] : undefined, hi: y ? 100 * y.interval95[1] : undefined,
            highlight: s.reported, title: `step ${i}, scale ${fmt(s.scale, 5)}, cost ${fmt(s.total_cost)}: yield ${y ? percent(y.fraction, 3) : '—'}${s.reported ? ' (reported)' : ''}` };
        }),
        target: typeof c.target_yield === 'number' ? 100 * c.target_yield : undefined, targetLabel: typeof c.target_yield === 'number' ? `target ${percent(c.target_yield, 2)}` : undefined,
        xLabel: 'correction step (0: the linear allocation; scales in the table)', yLabel: `${c.output} yield (%)`,
        title: `Monte Carlo yield of ${c.output} at each correction step`,
        desc: `${steps.length} steps with their 95 % Wilson intervals; the larger point is the reported allocation. The steps are in the table beside the chart.`,
      });
      svg.id = `alloc-steps-plot-${ci}`;
      row.append(h('figure', { class: 'plot-box' }, svg, h('figcaption', {}, `${c.output}: Monte Carlo yield (95 % interval) per step; dashed: the target.`)));
    });
    row.append(h('div', { class: 'table-box' }, stepsTable(r)));
    yieldCard.append(row);
  } else {
    yieldCard.append(h('p', { class: 'hint' }, r.kind === 'analytic' ? 'An analytic stack has no Monte Carlo: the linear model is the answer.' : 'No Monte Carlo correction was run.'));
  }
  container.append(yieldCard);
}

export function setupAllocation(openapi, ctx) {
  const paths = (openapi && openapi.paths) || {};
  if (!paths[`/v1/${COLLECTION}`]) return false;
  document.getElementById('allocation').hidden = false;
  document.getElementById('nav-allocation').hidden = false;
  ctx.jobs.renderers[COLLECTION] = renderAllocationResult;
  const examples = ctx.examples.filter(e => e.kind === 'allocation');
  const editor = requestEditor(document.getElementById('allocation-body'), {
    prefix: 'alloc', collection: COLLECTION, noun: 'Allocation', schema: 'allocation.schema.json',
    examples, submitLabel: 'Run allocation',
    fields: [
      { path: 'stack', label: 'Stack model', type: 'enum', options: ['rss', 'worst_case'], placeholder: 'rss (default)' },
      { path: 'solver', label: 'Solver', type: 'enum', options: ['exact', 'slsqp', 'cobyla'], placeholder: 'exact (default)' },
      { path: 'monte_carlo.samples', label: 'Monte Carlo samples a step', type: 'int', placeholder: 'the study’s', hint: 'study allocations only' },
      { path: 'monte_carlo.max_corrections', label: 'Max corrections', type: 'int', placeholder: '8' },
      { path: 'monte_carlo.seed', label: 'Monte Carlo seed', type: 'int', placeholder: 'the study’s' },
    ],
    onSubmitted: (r, doc) => ctx.submitted(r, doc, COLLECTION),
  });
  if (examples.length) api.example(examples[0].file).then(doc => { if (!editor.textarea.value) editor.setDoc(doc, `Loaded ${examples[0].file}; pick another example or edit the request.`); }).catch(() => {});
  return true;
}
