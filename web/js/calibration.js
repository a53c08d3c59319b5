// The calibration view: appears only when GET /v1/openapi.json lists /v1/calibrations. The request
// (schemas/measured-request.schema.json: a design, optionally its error set, the measured TE curve
// as arrays or as a bench CSV file's text, picked with the file input, and the calibration options) is edited as JSON with a few settings as fields, and run
// in the page's job view. The result (schemas/measured-result.schema.json, docs/measured-data.md):
// the measured TE and the calibrated model's TE overlaid against travel or screw angle, the
// detrended spectrum with the named lines marked, the calibrated estimates with their standard
// errors (a table and a chart of the lines' amplitudes, or the physical model's fields, with
// ± one standard error), the comparison with the model and the identifiability caveats.

import { api } from './api.js';
import { xyChart, intervalChart, fmt } from './plots.js';
import { h, requestEditor } from './jobrequest.js';

const COLLECTION = 'calibrations';

const UNITS = { um: 'µm', 'um/300mm': 'µm/300 mm', deg: '°', '': '–', '-': '–' };
const unitText = u => (u in UNITS ? UNITS[u] : u);
const LINE_LABELS = {
  screw_rev: 'screw_rev (1)', screw: 'screw (1 − k)', carrier: 'carrier (k)', roller_spin: 'roller_spin (i_g k)',
  roller_pass_nut: 'roller_pass_nut (Z k)', roller_pass_screw: 'roller_pass_screw (Z (1 − k))', mesh: 'mesh (z₂ k)',
};
const SHORT = { screw_rev: 'screw rev', roller_spin: 'roller spin', roller_pass_nut: 'pass nut', roller_pass_screw: 'pass screw' };
const numTd = (key, v, shown) => h('td', { 'data-key': key, 'data-value': typeof v === 'number' ? String(v) : undefined }, shown !== undefined ? shown : fmt(v));

// The columns of a bench CSV (measured.te_csv): a header row naming them, '#' comments and blank
// lines skipped, RFC 4180 quotes around a field; every value a number. null when it is not such a
// table (the service says why when the request is submitted).
export function csvColumns(text) {
  if (typeof text !== 'string') return null;
  const split = line => {
    const out = []; let cur = '', q = false;
    for (let i = 0; i < line.length; i++) {
      const c = line[i];
      if (q) { if (c === '"' && line[i + 1] === '"') { cur += '"'; i++; } else if (c === '"') q = false; else cur += c; }
      else if (c === '"') q = true; else if (c === ',') { out.push(cur.trim()); cur = ''; } else cur += c;
    }
    out.push(cur.trim());
    return out;
  };
  const rows = text.split(/\r?\n/).filter(l => l.trim() && !l.startsWith('#')).map(split);
  if (rows.length < 2) return null;
  const cols = {};
  rows[0].forEach((name, i) => { cols[name] = rows.slice(1).map(r => Number(r[i])); });
  return Object.values(cols).every(c => c.every(Number.isFinite)) ? cols : null;
}

// The measured curve of the request (measured.te arrays, or the CSV text of measured.te_csv):
// angle (rad) and travel (mm), the one missing from the lead.
export function measuredCurve(request, leadMm) {
  const m = request && request.measured;
  const te = m && (m.te || csvColumns(m.te_csv));
  if (!te || !Array.isArray(te.te_um)) return null;
  const n = te.te_um.length;
  const L = typeof leadMm === 'number' && leadMm > 0 ? leadMm : NaN;
  const angle = Array.isArray(te.screw_angle_rad) ? te.screw_angle_rad : Array.isArray(te.travel_mm) ? te.travel_mm.map(s => (2 * Math.PI * s) / L) : null;
  const travel = Array.isArray(te.travel_mm) ? te.travel_mm : angle ? angle.map(t => (L * t) / (2 * Math.PI)) : null;
  if (!angle || !travel || angle.length !== n || travel.length !== n) return null;
  return { angle, travel, te: te.te_um };
}

// The line model of the result at the curve's points:
// TE = c0 + c1 s / 300 + sum over lines of a cos(nu theta) + b sin(nu theta), nu at the fitted k.
export function lineModel(cal, curve) {
  const est = cal.estimates || {};
  const c0 = est.offset_um, c1 = est.slope_um_per_300mm;
  if (typeof c0 !== 'number' || typeof c1 !== 'number') return null;
  const lines = (cal.lines || []).filter(l => typeof est[`${l.name}_cos_um`] === 'number' && typeof est[`${l.name}_sin_um`] === 'number');
  return curve.angle.map((t, i) => {
    let v = c0 + (c1 * curve.travel[i]) / 300;
    for (const l of lines) v += est[`${l.name}_cos_um`] * Math.cos(l.order_per_rev * t) + est[`${l.name}_sin_um`] * Math.sin(l.order_per_rev * t);
    return v;
  });
}

function summary(r, job) {
  const cal = r.calibration || {}, m = r.measured || {}, k = cal.carrier_ratio;
  const rows = [
    ['Measurement', r.name || '—'],
    ['Curve', m.points ? `${fmt(m.points, 7)} points over ${fmt(m.revolutions)} screw revolutions, ${fmt(m.stroke_mm)} mm of travel (lead ${fmt(m.lead_mm)} mm)` : 'none'],
    ['Model', cal.model === 'physical' ? 'physical (error fields through the statics model)' : cal.model === 'line' ? 'line (offset, slope, a cos/sin pair per named line and k)' : '—'],
  ];
  if (k) rows.push(['Carrier ratio k', `${fmt(k.estimate, 7)} ± ${fmt(k.standard_error, 3)} (prior k* ${fmt(k.prior, 7)})`]);
  if (typeof cal.residual_sd_um === 'number') rows.push(['Residual s', `${fmt(cal.residual_sd_um)} µm${typeof m.te_noise_sd_um === 'number' ? ` (stated noise ${fmt(m.te_noise_sd_um)} µm)` : ''}`]);
  if (typeof cal.residual_lag1_autocorrelation === 'number') rows.push(['Residual lag-1 autocorrelation r₁', `${fmt(cal.residual_lag1_autocorrelation, 3)}${cal.inflation > 1 ? `: standard errors × ${fmt(cal.inflation, 3)}` : ' (no inflation)'}`]);
  rows.push(['Cached', job.cache_hit ? 'yes' : 'no'], ['Engine', r.engine ? `${r.engine.name} ${r.engine.version}` : '—']);
  return h('dl', { class: 'summary', id: 'cal-summary' }, rows.map(([a, b]) => h('div', {}, h('dt', {}, a), h('dd', {}, String(b)))));
}

function overlayCard(r, request) {
  const card = h('section', { class: 'card', id: 'cal-overlay-card', 'aria-labelledby': 'cal-overlay-h' }, h('h3', { id: 'cal-overlay-h' }, 'Measured and model transmission error'));
  const curve = measuredCurve(request, r.measured && r.measured.lead_mm);
  if (!curve) {
    card.append(h('p', { class: 'hint', id: 'cal-no-curve' }, 'The measured curve is part of the request, which this browser does not have for this job (it was submitted elsewhere): the spectrum and the estimates are below.'));
    return card;
  }
  const cal = r.calibration || {};
  // the result's fitted curve (either model), else the line model evaluated here from its estimates
  const model = Array.isArray(cal.fitted_te_um) && cal.fitted_te_um.length === curve.te.length ? cal.fitted_te_um
    : cal.model === 'line' ? lineModel(cal, curve) : null;
  const axis = h('select', { id: 'cal-x-axis' }, h('option', { value: 'travel' }, 'nut travel (mm)'), h('option', { value: 'angle' }, 'screw angle (rev)'));
  const fig = h('figure', { class: 'plot-box wide' });
  const modelName = cal.model === 'physical' ? 'physical model (the error fields through the statics model)' : 'line model';
  let rms = null;
  if (model) rms = Math.sqrt(model.reduce((a, v, i) => a + (curve.te[i] - v) ** 2, 0) / model.length);
  const draw = () => {
    const byAngle = axis.value === 'angle';
    const x = byAngle ? curve.angle.map(t => t / (2 * Math.PI)) : curve.travel;
    const series = [{ key: 'measured', label: 'measured', cls: 's0', kind: 'line', x, y: curve.te }];
    if (model) series.push({ key: 'model', label: `calibrated ${modelName}`, cls: 's1', kind: 'line', dash: true, x, y: model });
    const svg = xyChart({
      series, w: 900, h: 300,
      xLabel: byAngle ? 'screw angle θ (rev)' : 'nut travel s (mm)', yLabel: 'transmission error (µm)',
      title: 'Measured transmission error and the calibrated model',
      desc: `${curve.te.length} measured points${model ? ` and the calibrated ${modelName} at the same points (RMS difference ${fmt(rms)} µm, the fit's residual s ${fmt(cal.residual_sd_um)} µm)` : ''}, against ${byAngle ? 'the screw angle in revolutions' : 'the nut travel in mm'}. The estimates are in the table below.`,
    });
    svg.id = 'cal-overlay-plot';
    fig.textContent = '';
    fig.append(svg, h('figcaption', {}, model ? `Blue: measured; orange dashed: the ${modelName} with the calibrated estimates (RMS difference ${fmt(rms)} µm).`
      : 'The measured curve (this result has no fitted curve): the estimates and their standard errors are below.'));
  };
  axis.addEventListener('change', draw);
  draw();
  card.append(h('div', { class: 'field inline' }, h('label', { for: 'cal-x-axis' }, 'Horizontal axis'), axis), fig);
  if (model) card.append(h('p', { class: 'hint', id: 'cal-overlay-rms', 'data-value': String(rms) }, `RMS of measured − model: ${fmt(rms)} µm over ${curve.te.length} points.`));
  return card;
}

function spectrumCard(r) {
  const id = r.identification;
  const card = h('section', { class: 'card', id: 'cal-spectrum-card', 'aria-labelledby': 'cal-spectrum-h' }, h('h3', { id: 'cal-spectrum-h' }, 'Spectrum of the detrended curve and the named lines'));
  if (!id || !id.spectrum || !Array.isArray(id.spectrum.amplitude_um)) {
    card.append(h('p', { class: 'hint' }, 'No identification in this result (no measured curve).'));
    return card;
  }
  const amp = id.spectrum.amplitude_um, step = id.spectrum.step_per_rev;
  const x = amp.map((_, i) => i * step);
  const shown = id.lines.filter(l => !l.above_nyquist);
  const svg = xyChart({
    series: [{ key: 'spectrum', label: 'amplitude (Hann window, slope removed)', cls: 's0', kind: 'line', x, y: amp }],
    stems: shown.map(l => ({ x: l.found_order_per_rev, y: l.amplitude_um, label: l.name, name: l.name, cls: 'named', title: `${l.name}: order ${fmt(l.order_per_rev)} (found at ${fmt(l.found_order_per_rev)}), ${fmt(l.amplitude_um)} µm` })),
    w: 900, h: 300, xLabel: 'order (cycles per screw revolution)', yLabel: 'amplitude (µm)',
    title: 'Spectrum of the detrended measured TE with the named lines',
    desc: `${amp.length} bins of ${fmt(step)} cycles per revolution; the lead deviation ${fmt(id.lead_deviation_um_per_300mm)} µm per 300 mm was removed first. Named lines: ${shown.map(l => `${l.name} at ${fmt(l.found_order_per_rev)}, ${fmt(l.amplitude_um)} µm`).join('; ')}. The table below lists them.`,
  });
  svg.id = 'cal-spectrum-plot';
  const table = h('table', { class: 'numbers', id: 'cal-lines-found' },
    h('caption', {}, `Named lines at k* = ${fmt(id.carrier_ratio, 7)} (resolution ${fmt(id.resolution_per_rev)} cycles per revolution)`),
    h('thead', {}, h('tr', {}, ['line', 'order (per rev)', 'found at', 'amplitude (µm)'].map(c => h('th', { scope: 'col' }, c)))),
    h('tbody', {}, id.lines.map(l => h('tr', { 'data-line': l.name },
      h('th', { scope: 'row' }, LINE_LABELS[l.name] || l.name),
      numTd('order_per_rev', l.order_per_rev), numTd('found_order_per_rev', l.found_order_per_rev),
      numTd('amplitude_um', l.amplitude_um, l.above_nyquist ? 'above the Nyquist order' : fmt(l.amplitude_um))))));
  card.append(h('p', {}, `Lead deviation (the slope removed): ${fmt(id.lead_deviation_um_per_300mm)} µm per 300 mm.`),
    h('figure', { class: 'plot-box wide' }, svg, h('figcaption', {}, 'The detrended, Hann-windowed amplitude spectrum; each stem marks a named line at the order where its largest amplitude sits.')),
    h('div', { class: 'table-wrap' }, table));
  return card;
}

function estimatesCard(r) {
  const cal = r.calibration;
  const card = h('section', { class: 'card', id: 'cal-estimates-card', 'aria-labelledby': 'cal-estimates-h' }, h('h3', { id: 'cal-estimates-h' }, 'Calibrated estimates (± standard error)'));
  if (!cal) {
    card.append(h('p', { class: 'hint' }, 'No calibration in this result.'));
    return card;
  }
  const params = h('table', { class: 'numbers', id: 'cal-estimates' },
    h('caption', {}, `Estimates of the ${cal.model} model with their standard errors${cal.inflation > 1 ? ` (inflated × ${fmt(cal.inflation, 3)} for correlated residuals)` : ''}`),
    h('thead', {}, h('tr', {}, ['parameter', 'unit', 'estimate', '± standard error', 'white-noise standard error'].map(c => h('th', { scope: 'col' }, c)))),
    h('tbody', {}, cal.parameters.map(p => h('tr', { 'data-name': p.name },
      h('th', { scope: 'row' }, p.name), h('td', {}, unitText(p.unit)),
      numTd('estimate', p.estimate, fmt(p.estimate, 7)), numTd('standard_error', p.standard_error, fmt(p.standard_error, 3)),
      numTd('standard_error_white', p.standard_error_white, fmt(p.standard_error_white, 3))))));
  const row = h('div', { class: 'figure-row' });
  let items;
  if (Array.isArray(cal.lines) && cal.lines.length) {
    items = cal.lines.map(l => ({ label: l.name, y: l.amplitude_um, se: l.amplitude_se_um, title: `${l.name} (order ${fmt(l.order_per_rev)}): ${fmt(l.amplitude_um)} ± ${fmt(l.amplitude_se_um, 2)} µm` }));
  } else {
    items = cal.parameters.filter(p => p.name !== 'offset_um').map(p => ({ label: p.name, y: p.estimate, se: p.standard_error, title: `${p.name}: ${fmt(p.estimate)} ± ${fmt(p.standard_error, 2)} ${unitText(p.unit)}` }));
  }
  const chart = intervalChart({
    points: items.map(i => ({ label: SHORT[i.label] || i.label.replace(/_/g, ' ').slice(0, 12), y: i.y, lo: typeof i.se === 'number' ? i.y - i.se : undefined, hi: typeof i.se === 'number' ? i.y + i.se : undefined, title: i.title })),
    xLabel: cal.lines && cal.lines.length ? 'named line' : 'fitted field', yLabel: cal.lines && cal.lines.length ? 'amplitude (µm)' : 'estimate (its unit)',
    title: cal.lines && cal.lines.length ? 'Calibrated line amplitudes with ± one standard error' : 'Calibrated fields with ± one standard error',
    desc: `${items.map(i => i.title).join('; ')}. Every number is in the tables beside the chart.`,
  });
  chart.id = 'cal-estimates-plot';
  row.append(h('figure', { class: 'plot-box' }, chart, h('figcaption', {}, 'Estimate (point) with ± one standard error (whiskers); at this scale the whiskers of a well-determined line are shorter than the point.')));
  if (Array.isArray(cal.lines) && cal.lines.length) {
    row.append(h('div', { class: 'table-box' }, h('table', { class: 'numbers', id: 'cal-line-estimates' },
      h('caption', {}, 'Lines as amplitude and phase: a cos + b sin = A cos(νθ − ϑ)'),
      h('thead', {}, h('tr', {}, ['line', 'order ν', 'amplitude A (µm)', 'phase ϑ (°)'].map(c => h('th', { scope: 'col' }, c)))),
      h('tbody', {}, cal.lines.map(l => h('tr', { 'data-line': l.name },
        h('th', { scope: 'row' }, l.name), numTd('order_per_rev', l.order_per_rev, fmt(l.order_per_rev, 5)),
        numTd('amplitude_um', l.amplitude_um, `${fmt(l.amplitude_um)} ± ${fmt(l.amplitude_se_um, 2)}`),
        numTd('phase_deg', l.phase_deg, `${fmt(l.phase_deg)} ± ${fmt(l.phase_se_deg, 2)}`)))))));
  }
  card.append(h('div', { class: 'table-wrap' }, params), row);
  if (Array.isArray(cal.dropped_lines) && cal.dropped_lines.length) card.append(h('p', { class: 'hint', id: 'cal-dropped' }, `Left out (at or above the record's Nyquist order): ${cal.dropped_lines.map(d => (typeof d === 'string' ? d : d.name)).join(', ')}.`));
  card.append(h('p', { class: 'hint' }, `Condition number of JᵀJ ${fmt(cal.condition_number, 3)} (unit-norm columns ${fmt(cal.condition_number_scaled, 3)}); ${cal.converged === false ? 'the fit did not converge' : 'converged'}.`));
  return card;
}

function comparisonCard(r) {
  const c = r.comparison || {};
  const rows = [];
  if (c.te) rows.push(['TE: measured − model', `residual RMS ${fmt(c.te.residual_rms_um)} µm, peak to peak ${fmt(c.te.residual_peak_to_peak_um)} µm, lead deviation ${fmt(c.te.residual_lead_deviation_um_per_300mm)} µm/300 mm${c.te.with_errors ? '' : ' (the model has no error set: its TE is flat)'}`]);
  if (c.cage_ratio) rows.push(['Cage ratio', `measured ${fmt(c.cage_ratio.measured, 6)}; k* ${fmt(c.cage_ratio.carrier_ratio_min_slip, 6)} (z ${fmt(c.cage_ratio.z_min_slip, 3)}), statics ${fmt(c.cage_ratio.carrier_ratio_statics, 6)} (z ${fmt(c.cage_ratio.z_statics, 3)})`]);
  if (c.efficiency) rows.push(['Efficiency', `measured ${fmt(c.efficiency.measured)}, model ${fmt(c.efficiency.model)} (z ${fmt(c.efficiency.z, 3)})`]);
  if (r.friction) rows.push(['Friction μ (screw–roller)', r.friction.found ? `${fmt(r.friction.mu)} ± ${fmt(r.friction.mu_standard_error, 2)} (sliding only: ${fmt(r.friction.mu_sliding_only)})` : 'no μ in [0, 0.5] gives the efficiency']);
  if (r.carrier_drag) rows.push(['Carrier drag', r.carrier_drag.above_min_slip ? 'the measured ratio is above k*: drag cannot explain it' : r.carrier_drag.found ? `${fmt(r.carrier_drag.carrier_drag_Nm_s_per_rad)} ± ${fmt(r.carrier_drag.carrier_drag_se_Nm_s_per_rad, 2)} N·m·s/rad` : 'not found']);
  const card = h('section', { class: 'card', id: 'cal-comparison-card', 'aria-labelledby': 'cal-comparison-h' }, h('h3', { id: 'cal-comparison-h' }, 'Comparison with the model'));
  card.append(rows.length ? h('dl', { class: 'summary', id: 'cal-comparison' }, rows.map(([a, b]) => h('div', {}, h('dt', {}, a), h('dd', {}, b)))) : h('p', { class: 'hint' }, 'Nothing to compare.'));
  return card;
}

function caveatsCard(r) {
  const cav = (r.calibration && r.calibration.caveats) || [];
  const card = h('section', { class: 'card', id: 'cal-caveats-card', 'aria-labelledby': 'cal-caveats-h' }, h('h3', { id: 'cal-caveats-h' }, 'Identifiability caveats'));
  const fired = cav.filter(c => c.triggered).length;
  card.append(h('p', { id: 'cal-caveats-count', 'data-triggered': String(fired) }, fired ? `${fired} of ${cav.length} apply to this fit (marked).` : `None of the ${cav.length} applies to this fit; they are listed because each limits what a TE curve can say.`),
    h('ul', { class: 'caveats', id: 'cal-caveats' }, cav.map(c => h('li', { 'data-code': c.code, 'data-triggered': String(c.triggered), class: c.triggered ? 'warning' : undefined },
      h('strong', {}, `${c.code}${c.triggered ? ' (applies here)' : ''}: `), c.message))));
  return card;
}

export function renderCalibrationResult(container, job, request) {
  container.textContent = '';
  const r = job.result || {};
  container.append(summary(r, job), h('p', { class: 'downloads' }, h('a', { href: job.links.self, id: 'cal-json-link' }, 'Result as JSON')));
  if (Array.isArray(r.warnings) && r.warnings.length) {
    container.append(h('ul', { class: 'warnings', id: 'cal-warnings' }, r.warnings.map(w => h('li', {}, `${w.pointer ? `${w.pointer}: ` : ''}${w.message}`))));
  }
  container.append(overlayCard(r, request), spectrumCard(r), estimatesCard(r), comparisonCard(r), caveatsCard(r));
}

export function setupCalibration(openapi, ctx) {
  const paths = (openapi && openapi.paths) || {};
  if (!paths[`/v1/${COLLECTION}`]) return false;
  document.getElementById('calibration').hidden = false;
  document.getElementById('nav-calibration').hidden = false;
  ctx.jobs.renderers[COLLECTION] = renderCalibrationResult;
  const examples = ctx.examples.filter(e => e.kind === 'calibration');
  const editor = requestEditor(document.getElementById('calibration-body'), {
    prefix: 'cal', collection: COLLECTION, noun: 'Calibration', schema: 'measured-request.schema.json',
    examples, submitLabel: 'Run calibration',
    fields: [
      { path: 'dynamics.calibrate.model', label: 'Model', type: 'enum', options: ['line', 'physical'], placeholder: 'line (default)' },
      { path: 'dynamics.calibrate.grid_points', label: 'Grid points over k', type: 'int', placeholder: '2001', hint: 'line model' },
      { path: 'dynamics.calibrate.autocorrelation_limit', label: 'Autocorrelation limit r₁', type: 'number', placeholder: '0.2' },
      { path: 'measured.te_noise_sd_um', label: 'TE noise sd (µm)', type: 'number', placeholder: 'unknown' },
    ],
    onSubmitted: (r, doc) => ctx.submitted(r, doc, COLLECTION),
  });
  // a bench file as it is: its text into measured.te_csv (the service reads it with line and column
  // in every problem), in place of any curve the request held
  const csvInput = h('input', { type: 'file', id: 'cal-csv', accept: '.csv,text/csv,text/plain' });
  const csvNote = h('span', { class: 'hint', id: 'cal-csv-note', role: 'status' });
  csvInput.addEventListener('change', async () => {
    const f = csvInput.files && csvInput.files[0];
    if (!f) return;
    let doc;
    try { doc = editor.getDoc(); } catch (e) { csvNote.textContent = 'The request below is not JSON yet: load an example or fix it first.'; return; }
    const text = await f.text();
    doc.measured = doc.measured && typeof doc.measured === 'object' ? doc.measured : {};
    delete doc.measured.te;
    doc.measured.te_csv = text;
    const cols = csvColumns(text);
    editor.setDoc(doc, `Loaded ${f.name} into measured.te_csv${cols && cols.te_um ? ` (${cols.te_um.length} points)` : ''}.`);
    csvNote.textContent = `${f.name}: ${text.length} characters`;
  });
  document.getElementById('calibration-body').prepend(h('p', { class: 'file-pick' },
    h('label', { for: 'cal-csv' }, 'Measured TE from a bench CSV file (columns screw_angle_rad or travel_mm, and te_um): '), csvInput, ' ', csvNote));
  if (examples.length) api.example(examples[0].file).then(doc => { if (!editor.textarea.value) editor.setDoc(doc, `Loaded ${examples[0].file}; pick another example or edit the request.`); }).catch(() => {});
  return true;
}
