// A study's result (schemas/study-result.schema.json) as plots and tables: a histogram with spec
// limits and yield per output with its numbers beside it, a tornado chart of contributions with the
// definition named, and one sample of the run re-analysed (POST /v1/designs/analyze with the
// sample's errors from samples.csv and "curve": true) for its transmission-error curve over a
// revolution and its per-roller loads: the study result itself has neither.

import { api, describe } from './api.js';
import { histogram, lineChart, tornado, barChart, fmt, percent } from './plots.js';
import { unitOf } from './form.js';

function h(tag, attrs = {}, ...children) {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs)) {
    if (v === undefined || v === null || v === false) continue;
    if (k === 'class') e.className = v;
    else if (k === 'text') e.textContent = v;
    else e.setAttribute(k, v === true ? '' : String(v));
  }
  for (const c of children.flat()) if (c !== null && c !== undefined) e.append(c instanceof Node ? c : String(c));
  return e;
}

// A table row "name | value" whose cell keeps the raw number (data-value) for checks and copying.
function numRow(name, value, key, shown) {
  const td = h('td', { 'data-key': key, 'data-value': typeof value === 'number' ? String(value) : undefined });
  td.textContent = shown !== undefined ? shown : fmt(value);
  return h('tr', {}, h('th', { scope: 'row' }, name), td);
}

function outputTable(name, o, unit) {
  const rows = [
    numRow('samples used', o.n, 'n'),
    numRow('mean', o.mean, 'mean'),
    numRow('sd', o.sd, 'sd'),
    numRow('min', o.min, 'min'),
    numRow('0.135 %', o.quantiles && o.quantiles.p0_135, 'p0_135'),
    numRow('median', o.quantiles && o.quantiles.p50, 'p50'),
    numRow('99.865 %', o.quantiles && o.quantiles.p99_865, 'p99_865'),
    numRow('max', o.max, 'max'),
    numRow('skewness', o.skewness, 'skewness'),
    numRow('excess kurtosis', o.kurtosis_excess, 'kurtosis_excess'),
  ];
  if (o.spec) {
    const y = o.yield || {};
    const iv = y.interval95 || [];
    rows.push(
      numRow('spec', null, 'spec', `${o.spec.lower !== undefined ? fmt(o.spec.lower) : '—'} to ${o.spec.upper !== undefined ? fmt(o.spec.upper) : '—'}`),
      numRow('yield', y.fraction, 'yield', percent(y.fraction)),
      numRow('yield 95 % interval', null, 'yield_interval', `${percent(iv[0])} to ${percent(iv[1])}`),
      numRow('ppm below / above', null, 'ppm', o.ppm ? `${fmt(o.ppm.low, 6)} / ${fmt(o.ppm.high, 6)}` : '—'),
      numRow(o.normality && o.normality.normal_fit_rejected ? 'ppm (normal fit: rejected, not normal)' : 'ppm (normal fit)', null, 'ppm_fit', o.ppm ? `${fmt(o.ppm.low_normal_fit, 4)} / ${fmt(o.ppm.high_normal_fit, 4)}` : '—'),
      numRow('ppm (tail fit)', null, 'ppm_tail', o.ppm ? `${fmt(o.ppm.low_tail_fit, 4)} / ${fmt(o.ppm.high_tail_fit, 4)}` : '—'),
      numRow('Cp', o.cp, 'cp'),
      numRow('Cpk', o.cpk, 'cpk'),
    );
  }
  if (o.stack) {
    rows.push(
      numRow('nominal', o.stack.nominal, 'stack_nominal'),
      numRow('worst case', null, 'worst_case', o.stack.worst_case ? `${fmt(o.stack.worst_case[0])} to ${fmt(o.stack.worst_case[1])}` : '—'),
      numRow('RSS', null, 'rss', o.stack.rss ? `${fmt(o.stack.rss[0])} to ${fmt(o.stack.rss[1])}` : '—'),
    );
    if (o.stack.caveat) rows.push(numRow('⚠ worst case / RSS', null, 'stack_caveat', o.stack.caveat));
  }
  if (o.rare_event) {
    const re = o.rare_event, iv = re.ppm_interval95;
    const side = s => s ? `${s.method}: ${fmt(s.ppm, 4)} ppm${s.interval95_ppm && typeof s.interval95_ppm[0] === 'number' ? ` [${fmt(s.interval95_ppm[0], 3)}, ${fmt(s.interval95_ppm[1], 3)}]` : ''}, ${s.evaluations} evaluations` : '—';
    rows.push(
      numRow('ppm out of spec (rare-event estimate)', null, 'rare_ppm', `${fmt(re.ppm, 4)}${iv && typeof iv[0] === 'number' ? ` [${fmt(iv[0], 3)}, ${fmt(iv[1], 3)}]` : ''}`),
      numRow('below / above', null, 'rare_sides', `${side(re.lower)} / ${side(re.upper)}`),
    );
  }
  return h('table', { class: 'numbers', 'data-output': name },
    h('caption', {}, `${name}${unit ? ` (${unit})` : ''}`),
    h('tbody', {}, rows));
}

// ---- tornado ---------------------------------------------------------------------------------
const DEFINITIONS = [
  { key: 'sobol_total', label: 'Sobol total index (share of variance with interactions)', axis: 'Sobol total index', interval: 'sobol_total_interval95' },
  { key: 'sobol_first', label: 'Sobol first-order index (share of variance alone)', axis: 'Sobol first-order index', interval: 'sobol_first_interval95' },
  { key: 'src_percent', label: 'SRC² share: % of variance explained by the linear fit', axis: 'SRC² share (%)' },
  { key: 'srrc_percent', label: 'SRRC² share: % of rank variance explained by the rank fit', axis: 'SRRC² share (%)' },
  { key: 'stack_change', label: 'One at a time: change of the output at the tolerance’s half-width', axis: 'change (output unit)', signed: true },
];

function tornadoSection(result) {
  const names = Object.keys(result.outputs).filter(n => result.outputs[n].sensitivity);
  const sec = h('section', { class: 'card', 'aria-labelledby': 'tornado-h', id: 'tornado-card' }, h('h3', { id: 'tornado-h' }, 'What drives the spread: contributions per tolerance'));
  if (!names.length) {
    sec.append(h('p', { class: 'hint' }, 'No sensitivity figures in this result (sensitivity src, stack and sobol were off).'));
    return sec;
  }
  const available = DEFINITIONS.filter(d => names.some(n => result.outputs[n].sensitivity.tolerances.some(t => typeof t[d.key] === 'number')));
  const outSel = h('select', { id: 'tornado-output' }, names.map(n => h('option', { value: n }, n)));
  const defSel = h('select', { id: 'tornado-definition' }, available.map(d => h('option', { value: d.key }, d.label)));
  const controls = h('div', { class: 'controls' },
    h('label', { for: 'tornado-output' }, 'Output '), outSel, ' ',
    h('label', { for: 'tornado-definition' }, 'Contribution '), defSel);
  const caption = h('p', { class: 'definition', id: 'tornado-definition-text' });
  const plot = h('div', { class: 'plot-box' });
  const table = h('div', { class: 'table-box' });
  const draw = () => {
    const o = result.outputs[outSel.value];
    const d = DEFINITIONS.find(x => x.key === defSel.value) || DEFINITIONS[2];
    const s = o.sensitivity;
    const items = s.tolerances.map(t => ({
      label: t.parameter, value: t[d.key],
      lo: d.interval && t[d.interval] ? t[d.interval][0] : undefined,
      hi: d.interval && t[d.interval] ? t[d.interval][1] : undefined,
    })).filter(it => typeof it.value === 'number');
    items.sort((a, b) => Math.abs(b.value) - Math.abs(a.value));
    const r2 = d.key === 'src_percent' ? ` Linear fit R² = ${fmt(s.src_r2, 3)}.` : d.key === 'srrc_percent' ? ` Rank fit R² = ${fmt(s.srrc_r2, 3)}.` : '';
    caption.textContent = `${d.label}.${r2} ${d.key.startsWith('src') || d.key.startsWith('srrc') ? `The service’s definition: ${s.contribution_definition}` : d.key.startsWith('sobol') ? `Saltelli/Jansen estimators${result.sobol ? ` from ${result.sobol.evaluations} evaluations (${result.sobol.base_samples} base samples)` : ''}; whiskers: 95 % bootstrap intervals.` : (o.stack && o.stack.method) || ''}`;
    plot.textContent = '';
    plot.appendChild(tornado({
      items, signed: d.signed, xLabel: d.axis,
      title: `Tornado chart of ${outSel.value}: ${d.axis}`,
      desc: `${items.length} tolerances, largest first: ${items.slice(0, 5).map(i => `${i.label} ${fmt(i.value)}`).join('; ')}${items.length > 5 ? '; …' : ''}. Every value is in the table beside the chart.`,
    }));
    table.textContent = '';
    table.appendChild(h('table', { class: 'numbers', id: 'tornado-table' },
      h('caption', {}, `${outSel.value}: ${d.axis}`),
      h('thead', {}, h('tr', {}, h('th', { scope: 'col' }, 'tolerance'), h('th', { scope: 'col' }, d.axis))),
      h('tbody', {}, items.map(i => numRow(i.label, i.value, i.label)))));
  };
  outSel.addEventListener('change', draw);
  defSel.addEventListener('change', draw);
  sec.append(controls, caption, h('div', { class: 'figure-row' }, plot, table));
  draw();
  return sec;
}

// ---- samples CSV and the replay of one sample ---------------------------------------------------
export function parseCsv(text) {
  const lines = text.split(/\r?\n/).filter(l => l.length);
  const header = lines[0].split(',');
  const rows = lines.slice(1).map(l => {
    const cells = l.split(',');
    const r = {};
    header.forEach((k, i) => { r[k] = k === 'status' ? cells[i] : Number(cells[i]); });
    return r;
  });
  return { header, rows };
}

// The analyze request that reproduces one sample: the study's design (friction deviations added),
// its fixed errors plus the sample's drawn errors (phases from rad to deg), its assembly options.
export function replayRequest(study, header, row) {
  const design = JSON.parse(JSON.stringify(study.design));
  const errors = JSON.parse(JSON.stringify(study.errors || {}));
  const Z = design.geometry.rollers, n = design.geometry.starts;
  for (const col of header) {
    if (col === 'sample' || col === 'status' || !col.includes('.')) continue;
    const m = /^(screw|nut|carrier|roller|friction)(?:\[(\d+)\])?\.(\w+?)(?:\[(\d+)\])?$/.exec(col);
    if (!m) continue;
    const [, part, ri, field0, si] = m;
    let field = field0, v = row[col];
    if (part === 'friction') {
      const key = field.replace(/_mu$/, '');
      design.friction = design.friction || {};
      design.friction[key] = (design.friction[key] ?? 0) + v;
      continue;
    }
    if (/_phase_rad$/.test(field)) { field = field.replace(/_rad$/, '_deg'); v = v * 180 / Math.PI; }
    let obj;
    if (part === 'roller') {
      errors.rollers = errors.rollers || Array.from({ length: Z }, () => ({}));
      obj = errors.rollers[ri === undefined ? 0 : Number(ri)];
    } else {
      obj = errors[part] = errors[part] || {};
    }
    if (si !== undefined) {
      obj[field] = obj[field] || new Array(n).fill(0);
      obj[field][Number(si)] += v;
    } else if (/_phase_deg$/.test(field)) {
      obj[field] = v;
    } else {
      obj[field] = (obj[field] || 0) + v;
    }
  }
  const assembly = { ...(study.assembly || {}), curve: true };
  delete assembly.stroke_mm;
  return { design, errors, assembly };
}

function replaySection(job, study) {
  const result = job.result;
  const sec = h('section', { class: 'card', id: 'replay-card', 'aria-labelledby': 'replay-h' },
    h('h3', { id: 'replay-h' }, 'One assembly of the run: transmission error over a revolution and load sharing per roller'));
  const note = h('p', { class: 'hint' }, 'The study reports distributions; to see a curve, one sample of the run is analysed again with its drawn errors (POST /v1/designs/analyze with "curve": true), and its outputs are checked against the sample’s row of samples.csv.');
  sec.append(note);
  if (!study || !study.design || result.model !== 'design') {
    sec.append(h('p', { class: 'hint', id: 'replay-unavailable' }, study ? 'Benchmark studies have no assembly to show.' : 'This browser does not have this study’s request (it was submitted elsewhere): load the same request in the form and submit it again (a cached result answers at once) to see a sample re-analysed.'));
    return sec;
  }
  const outs = Object.keys(result.outputs);
  const choices = [];
  for (const o of outs) choices.push([`max:${o}`, `largest ${o}`], [`median:${o}`, `median ${o}`], [`min:${o}`, `smallest ${o}`]);
  const pick = h('select', { id: 'replay-pick' }, choices.map(([v, l]) => h('option', { value: v }, l)));
  const def = outs.includes('te_pp_um') ? 'max:te_pp_um' : outs.includes('load_sharing_factor') ? 'max:load_sharing_factor' : `median:${outs[0]}`;
  pick.value = def;
  const idx = h('input', { id: 'replay-index', type: 'number', min: 0, step: 1 });
  const go = h('button', { type: 'button', id: 'replay-go' }, 'Show sample');
  const status = h('p', { class: 'status', role: 'status', 'aria-live': 'polite', id: 'replay-status' });
  const body = h('div', { id: 'replay-body' });
  sec.append(h('div', { class: 'controls' },
    h('label', { for: 'replay-pick' }, 'Sample with the '), pick, ' ',
    h('label', { for: 'replay-index' }, 'or sample number '), idx, ' ', go), status, body);

  let csv = null;
  const run = async index => {
    status.textContent = 'Loading samples…';
    try {
      if (!csv) csv = parseCsv(await api.text(job.links.samples_csv));
      const ok = csv.rows.filter(r => r.status === 'ok');
      if (!ok.length) { status.textContent = 'No valid samples to show.'; return; }
      let row;
      if (index !== undefined) {
        row = csv.rows.find(r => r.sample === index);
        if (!row) { status.textContent = `No sample ${index} (0 to ${csv.rows.length - 1}).`; return; }
        if (row.status !== 'ok') { status.textContent = `Sample ${index} is ${row.status}: it has no outputs.`; return; }
      } else {
        const [how, o] = pick.value.split(':');
        const sorted = ok.slice().sort((a, b) => a[o] - b[o]);
        row = how === 'max' ? sorted[sorted.length - 1] : how === 'min' ? sorted[0] : sorted[Math.floor((sorted.length - 1) / 2)];
      }
      status.textContent = `Analysing sample ${row.sample}…`;
      const req = replayRequest(study, csv.header, row);
      const a = await api.analyze(req);
      drawReplay(body, row, a, req, outs);
      status.textContent = `Sample ${row.sample} re-analysed.`;
    } catch (e) {
      status.textContent = `Could not show the sample: ${describe(e)}`;
    }
  };
  pick.addEventListener('change', () => { idx.value = ''; run(); });
  go.addEventListener('click', () => run(idx.value === '' ? undefined : Number(idx.value)));
  idx.addEventListener('keydown', e => { if (e.key === 'Enter') { e.preventDefault(); go.click(); } });
  run();
  return sec;
}

function drawReplay(body, row, a, req, outs) {
  body.textContent = '';
  const A = a.assembly;
  const te = A.transmission_error;
  const apr = te.angles_per_revolution;
  const curve = te.curve.te_um.slice(0, apr + 1);
  const x = curve.map((_, i) => i * te.curve.step_deg);
  const tePlot = lineChart({
    x, y: curve, xLabel: 'screw angle (°)', yLabel: 'TE (µm)', xTicks: [0, 45, 90, 135, 180, 225, 270, 315, 360],
    title: `Transmission error over one screw revolution, sample ${row.sample}`,
    desc: `${apr + 1} points from 0° to 360°: peak to peak ${fmt(te.revolution.peak_to_peak_um)} µm, RMS ${fmt(te.revolution.rms_um)} µm at ${te.measuring_load_N} N, from ${fmt(Math.min(...curve))} to ${fmt(Math.max(...curve))} µm. The sample's outputs are in the table beside the chart.`,
  });
  tePlot.id = 'te-plot';
  const ls = A.load_sharing;
  let loadPlot = h('p', { class: 'hint' }, 'No axial load in the design: no load sharing.');
  if (ls && Array.isArray(ls.roller_loads_N)) {
    loadPlot = barChart({
      labels: ls.roller_loads_N.map((_, i) => String(i + 1)), values: ls.roller_loads_N,
      ref: ls.axial_load_N / ls.roller_loads_N.length, refLabel: `F/Z = ${fmt(ls.axial_load_N / ls.roller_loads_N.length)} N`,
      xLabel: 'roller', yLabel: 'load (N)',
      title: `Load per roller at ${fmt(ls.axial_load_N)} N, sample ${row.sample}`,
      desc: `sharing factor ${fmt(ls.sharing_factor)} (max roller load / mean); roller loads ${ls.roller_loads_N.map((v, i) => `${i + 1}: ${fmt(v)} N`).join(', ')}; the equal share F/Z is ${fmt(ls.axial_load_N / ls.roller_loads_N.length)} N.`,
    });
    loadPlot.id = 'roller-plot';
  }
  const compare = [
    ['backlash_um', 'backlash at 0° (µm)', A.backlash.at_zero_um],
    ['backlash_min_um', 'min backlash (µm)', A.backlash.min_over_revolution_um],
    ['backlash_max_um', 'max backlash (µm)', A.backlash.max_over_revolution_um],
    ['te_pp_um', 'TE peak to peak (µm)', te.revolution.peak_to_peak_um],
    ['te_rms_um', 'TE RMS (µm)', te.revolution.rms_um],
    ['load_sharing_factor', 'load sharing factor', ls ? ls.sharing_factor : null],
    ['stiffness_N_per_um', 'stiffness (N/µm)', ls ? ls.stiffness_N_per_um : null],
    ['stiffness_ratio', 'stiffness ratio', ls ? ls.stiffness_ratio : null],
  ];
  const table = h('table', { class: 'numbers', id: 'replay-table', 'data-sample': row.sample },
    h('caption', {}, `Sample ${row.sample}: re-analysed and as the study computed it`),
    h('thead', {}, h('tr', {}, h('th', { scope: 'col' }, 'output'), h('th', { scope: 'col' }, 'analysis'), h('th', { scope: 'col' }, 'samples.csv'))),
    h('tbody', {}, compare.map(([key, label, v]) => h('tr', { 'data-key': key },
      h('th', { scope: 'row' }, label),
      h('td', { 'data-value': typeof v === 'number' ? String(v) : undefined, class: 'analysis' }, fmt(v)),
      h('td', { 'data-value': key in row ? String(row[key]) : undefined, class: 'csv' }, key in row ? fmt(row[key]) : '—')))));
  const lines = te.spectrum && te.spectrum.lines ? h('table', { class: 'numbers' },
    h('caption', {}, 'TE spectrum lines'),
    h('thead', {}, h('tr', {}, h('th', { scope: 'col' }, 'line'), h('th', { scope: 'col' }, 'per rev'), h('th', { scope: 'col' }, 'µm'))),
    h('tbody', {}, te.spectrum.lines.map(l => h('tr', {}, h('th', { scope: 'row', title: l.source }, l.name), h('td', {}, fmt(l.frequency_per_rev)), h('td', {}, fmt(l.amplitude_um)))))) : null;
  body.append(
    h('div', { class: 'figure-row' }, h('figure', { class: 'plot-box' }, tePlot, h('figcaption', {}, `TE at ${te.measuring_load_N} N, ${apr} angles per revolution (the study's setting)`)), h('div', { class: 'table-box' }, table)),
    h('div', { class: 'figure-row' }, h('figure', { class: 'plot-box' }, loadPlot, h('figcaption', {}, ls ? `Roller loads; ${ls.contact_law}` : '')), h('div', { class: 'table-box' }, lines)),
  );
  body.dataset.sample = String(row.sample);
}

// ---- the whole result ------------------------------------------------------------------------
export function renderStudyResult(container, job, study) {
  const r = job.result;
  container.textContent = '';
  const samples = r.samples || {};
  // the result is labelled with the study's name (the form's "Study name", echoed by the service)
  // and the name of its design (from the request, when this page knows it)
  const studyName = r.name || (study && study.name) || '';
  const designName = study && study.design && typeof study.design.name === 'string' ? study.design.name : '';
  container.append(h('p', { class: 'result-title', id: 'result-title', 'data-name': studyName },
    'Study: ', h('strong', { id: 'result-name' }, studyName || 'unnamed study (give it a name in the form’s “Study name”)'),
    designName ? ` · design: ${designName}` : null));
  const summary = h('dl', { class: 'summary', id: 'result-summary' },
    [['Stop reason', r.stop_reason], ['Converged', r.converged ? 'yes' : 'no'],
      ['Samples used / run / cap', `${samples.used} / ${samples.run} / ${samples.cap}`],
      ['Failed, edge contact', `${samples.failed}, ${samples.edge_contact} (${samples.edge_contact_policy})`],
      ['Sampler', r.sampler ? `${r.sampler.used}${r.sampler.used !== r.sampler.requested ? ` (asked ${r.sampler.requested})` : ''}` : '—'],
      ['Seed', r.seed], ['Assembly model', r.assembly_mode || '—'],
      ['Time', r.timing_s ? `${fmt(r.timing_s.monte_carlo, 3)} s Monte Carlo, ${fmt(r.timing_s.sensitivity, 3)} s sensitivity` : '—'],
      ['Cached', job.cache_hit || r.cache_hit ? 'yes' : 'no'], ['Engine', r.versions ? r.versions.engine : '—']]
      .map(([k, v]) => h('div', {}, h('dt', {}, k), h('dd', {}, String(v)))));
  const links = h('p', { class: 'downloads' });
  if (job.links && job.links.samples_csv) links.append(h('a', { href: job.links.samples_csv, id: 'csv-link', download: `samples-${job.id}.csv` }, 'Download every sample (CSV)'), ' · ');
  links.append(h('a', { href: job.links.self, id: 'json-link' }, 'Result as JSON'));
  container.append(summary, links);
  if (r.warnings && r.warnings.length) container.append(h('ul', { class: 'warnings', 'aria-label': 'Warnings' }, r.warnings.map(w => h('li', {}, typeof w === 'string' ? w : w.message))));

  const grid = h('div', { class: 'outputs', id: 'output-cards' });
  for (const [name, o] of Object.entries(r.outputs)) {
    const unit = unitOf(name);
    const yieldTxt = o.spec && o.yield ? `yield ${percent(o.yield.fraction)} (95 %: ${percent(o.yield.interval95[0])} to ${percent(o.yield.interval95[1])})` : 'no spec';
    const svg = histogram({
      hist: o.histogram, spec: o.spec, label: name, unit,
      title: `Histogram of ${name}`,
      desc: `${o.histogram.counts.length} bins from ${fmt(o.histogram.lower)} to ${fmt(o.histogram.upper)}${unit ? ` ${unit}` : ''}; ${o.n} samples, mean ${fmt(o.mean)}, sd ${fmt(o.sd)}; ${o.spec ? `spec ${o.spec.lower !== undefined ? fmt(o.spec.lower) : '—'} to ${o.spec.upper !== undefined ? fmt(o.spec.upper) : '—'}, ` : ''}${yieldTxt}. Every figure is in the table beside the chart.`,
    });
    const card = h('section', { class: 'card output', 'data-output': name, 'aria-labelledby': `out-h-${name}` },
      h('h3', { id: `out-h-${name}` }, name, o.spec && o.yield ? h('span', { class: `yield ${o.yield.fraction < 0.9973 ? 'low' : ''}`, 'data-value': String(o.yield.fraction) }, ` · ${yieldTxt}`) : null),
      h('div', { class: 'figure-row' }, h('figure', { class: 'plot-box' }, svg), h('div', { class: 'table-box' }, outputTable(name, o, unit))));
    grid.append(card);
  }
  container.append(grid, tornadoSection(r), replaySection(job, study));
}
