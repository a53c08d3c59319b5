// The simulation view: appears only when GET /v1/openapi.json lists /v1/simulations. The request
// (schemas/simulation.schema.json: a design, or a multi-stage chain, with its dynamics object) is
// edited as JSON with the run's main settings as fields, submitted and followed by the page's job
// view (progress in simulated time, cancel). The result (schemas/dynamics-result.schema.json,
// docs/dynamics.md): plots against time of the carrier ratio of every stage, the efficiency, the
// input torque, the screw speed and the forces per roller, each with its settled value as a dashed
// line; the settled state in a table beside the carrier plot; the checks (power balance,
// Newton–Euler recovery) and the integration; the time series as CSV, written here from the JSON
// with the columns and number format of `prsm simulate --csv` (seriesCsv), and the result as JSON.

import { api } from './api.js';
import { seriesChart, xyChart, cellMap, PALETTE, fmt } from './plots.js';
import { h, requestEditor } from './jobrequest.js';

const COLLECTION = 'simulations';

// ---- the CSV of `prsm simulate --csv` (src/io/dynamics_json.c, prsm_io_dynamics_write_csv) ------
// The columns: these, then "stuck" (Karnopp stick model only), then per stage k the stage columns
// as stage<k>_<name> (the last two from stage 2 on). Numbers as printf's %.17g, empty where the
// value is not defined (null in the JSON).
export const CSV_COLUMNS = ['time_s', 'screw_angle_rad', 'screw_speed_rad_s', 'screw_accel_rad_s2', 'axial_load_N', 'motor_torque_Nm',
  'input_torque_Nm', 'efficiency', 'energy_efficiency', 'power_input_W', 'power_output_W', 'power_sliding_W',
  'power_couplings_W', 'power_other_W', 'power_kinetic_W', 'power_balance_residual_W', 'newton_euler_residual'];
export const CSV_STAGE_COLUMNS = ['carrier_ratio', 'carrier_speed_rad_s', 'nut_position_mm', 'contact_normal_force_N', 'nut_contact_force_N',
  'gear_tangential_force_N', 'gear_tooth_force_N', 'cage_force_N', 'slip_speed_m_s', 'stage_axial_load_N', 'spline_force_N', 'thrust_torque_Nm'];
const FIRST_STAGE_COLUMNS = 10; // stage 1 has no spline nor thrust bearing

// printf("%.17g", v): 17 significant digits, correctly rounded (ties to even, as glibc does), in
// the shorter of the fixed and exponent layouts, trailing zeros removed; '' for a value that is not
// a finite number (the CSV's empty cell).
export function g17(v) {
  if (typeof v !== 'number' || !Number.isFinite(v)) return '';
  if (v === 0) return Object.is(v, -0) ? '-0' : '0';
  let s = v.toExponential(16); // correctly rounded, but a tie goes away from zero
  let e = s.indexOf('e');
  const x = +s.slice(e + 1);
  // An exact tie (the exact value's 18th significant digit a 5 and nothing after it) needs a decimal
  // exponent from -8 to 15 and a value with at most 17 - x binary fraction digits (a double's odd
  // significand is below 2^53; one more of each here, as x is the rounded value's exponent): only
  // such values are looked at more closely, on their exact digits.
  if (x >= -9 && x <= 16 && Number.isInteger(v * 2 ** (18 - x)) && /^-?\d\.\d{16}5000e/.test(v.toExponential(20))) {
    const m = /^(-?\d\.\d{16})(\d+)(e.*)$/.exec(v.toExponential(100));
    if (/^50*$/.test(m[2]) && Number(m[1][m[1].length - 1]) % 2 === 0) { s = m[1] + m[3]; e = s.indexOf('e'); } // the tie: to the even digit, down
  }
  const neg = v < 0;
  let digits = s[neg ? 1 : 0] + s.slice(neg ? 3 : 2, e); // 17 digits
  let end = digits.length;
  while (end > 1 && digits.charCodeAt(end - 1) === 48) end--;
  digits = digits.slice(0, end);
  const sign = neg ? '-' : '';
  if (x < -4 || x >= 17) return `${sign}${digits[0]}${end > 1 ? `.${digits.slice(1)}` : ''}e${x < 0 ? '-' : '+'}${x > -10 && x < 10 ? '0' : ''}${x < 0 ? -x : x}`;
  if (x >= 0) return end > x + 1 ? `${sign}${digits.slice(0, x + 1)}.${digits.slice(x + 1)}` : sign + digits.padEnd(x + 1, '0');
  return `${sign}0.${'0'.repeat(-x - 1)}${digits}`;
}

// The whole CSV (header and one row per output time) from a dynamics result document.
export function seriesCsv(result) {
  const d = result.dynamics, tr = d.transient, ch = d.checks, K = d.stages;
  const n = tr.points;
  const pw = tr.power_W || {};
  const karnopp = Array.isArray(tr.stuck);
  const base = [tr.time_s, tr.screw_angle_rad, tr.screw_speed_rad_s, tr.screw_accel_rad_s2, tr.axial_load_N,
    tr.motor_torque_Nm || tr.input_torque_Nm, // a speed input's motor torque is its input torque (dyn.h)
    tr.input_torque_Nm, tr.efficiency, tr.energy_efficiency, pw.input, pw.output, pw.sliding, pw.couplings, pw.other, pw.kinetic,
    ch.power_balance_residual_W, ch.newton_euler_residual];
  const stageCols = [];
  const header = CSV_COLUMNS.slice();
  if (karnopp) header.push('stuck');
  for (let k = 0; k < K; k++) {
    const s = tr.stages[k];
    CSV_STAGE_COLUMNS.forEach((c, j) => {
      if (k === 0 && j >= FIRST_STAGE_COLUMNS) return;
      header.push(`stage${k + 1}_${c}`);
      stageCols.push(s[c]);
    });
  }
  const lines = [header.join(',')];
  const cell = (a, i) => g17(a ? a[i] : null);
  for (let i = 0; i < n; i++) {
    const row = base.map(a => cell(a, i));
    if (karnopp) row.push(tr.stuck[i] ? '1' : '0');
    for (const a of stageCols) row.push(cell(a, i));
    lines.push(row.join(','));
  }
  return `${lines.join('\n')}\n`;
}

function download(name, type, text) {
  const url = URL.createObjectURL(new Blob([text], { type }));
  const a = h('a', { href: url, download: name, hidden: true });
  document.body.append(a);
  a.click();
  a.remove();
  setTimeout(() => URL.revokeObjectURL(url), 60000);
}

// ---- numbers ----------------------------------------------------------------------------------------
// The time axis in the unit that suits the run's length.
function timeUnit(end) {
  if (end < 1e-3) return { f: 1e6, unit: 'µs' };
  if (end < 1) return { f: 1e3, unit: 'ms' };
  return { f: 1, unit: 's' };
}
// A duration in s, in µs, ms or s; null: not reached within the run.
function duration(s) {
  if (typeof s !== 'number') return '— (not within the run)';
  const u = timeUnit(s);
  return `${fmt(s * u.f)} ${u.unit}`;
}
const cell = (key, v, shown, digits = 4) => h('td', { 'data-key': key, 'data-value': typeof v === 'number' ? String(v) : undefined },
  shown !== undefined ? shown : typeof v === 'number' ? fmt(v, digits) : '—');
const withUnit = (v, u, digits = 4) => (typeof v === 'number' ? `${fmt(v, digits)} ${u}` : '—');

// stage k's colour class in every plot (app.css: s0 ... s5)
const stageCls = k => `s${k % 6}`;

// ---- the result's parts --------------------------------------------------------------------------
function settledTable(d) {
  const st = d.settled, K = d.stages, stages = st.stages || [];
  const torque = d.parameters.input.kind === 'torque';
  const sp = st.speed || {};
  const whole = [
    ['efficiency', 'efficiency η (settled)', st.efficiency, fmt(st.efficiency, 6)],
    ['efficiency_statics', 'efficiency, statics engine', st.efficiency_statics, typeof st.efficiency_statics === 'number' ? fmt(st.efficiency_statics, 6) : '— (viscous friction)'],
    ['input_torque_Nm', 'input torque T_in', st.input_torque_Nm, withUnit(st.input_torque_Nm, 'N m', 6)],
    ['screw_speed_rad_s', 'screw speed', st.screw_speed_rad_s, withUnit(st.screw_speed_rad_s, 'rad/s', 6)],
  ];
  if (torque) {
    whole.push(['speed_time_to_90_percent_s', 'screw speed at 90 %', sp.time_to_90_percent_s, duration(sp.time_to_90_percent_s)],
      ['speed_time_to_99_percent_s', 'screw speed at 99 %', sp.time_to_99_percent_s, duration(sp.time_to_99_percent_s)]);
  }
  const perStage = [
    ['carrier_ratio', 'carrier ratio ψ̇/θ̇ (settled)', s => fmt(s.carrier_ratio, 6)],
    ['carrier_ratio_min_slip', 'k* (least slip)', s => fmt(s.carrier_ratio_min_slip, 6)],
    ['carrier_ratio_statics', 'statics ratio (contact radii)', s => fmt(s.carrier_ratio_statics, 6)],
    ['time_to_90_percent_s', 'carrier at 90 %', s => duration(s.time_to_90_percent_s)],
    ['time_to_99_percent_s', 'carrier at 99 %', s => duration(s.time_to_99_percent_s)],
  ];
  return h('table', { class: 'numbers settled', id: 'sim-settled' },
    h('caption', {}, st.defined === false ? 'Settled state: none (no speed balances the motor torque: the screw runs away)'
      : `Settled state${st.at_rest ? ' (at rest: the motor cannot start the screw)' : ''}: dashed in the plots`),
    h('tbody', {}, whole.map(([key, label, v, shown]) => h('tr', { 'data-key': key },
      h('th', { scope: 'row' }, label), h('td', { colspan: K, 'data-key': key, 'data-value': typeof v === 'number' ? String(v) : undefined }, shown)))),
    h('tbody', {},
      h('tr', { class: 'head' }, h('th', { scope: 'col' }, 'per stage'), stages.map(s => h('th', { scope: 'col', class: `stage ${stageCls(s.stage - 1)}` }, `stage ${s.stage}`))),
      perStage.map(([key, label, show]) => h('tr', { 'data-key': key },
        h('th', { scope: 'row' }, label),
        stages.map(s => h('td', { 'data-key': `stage${s.stage}.${key}`, 'data-value': typeof s[key] === 'number' ? String(s[key]) : undefined }, show(s)))))));
}

// The forces per roller (and the couplings') a plot is drawn for: key, label, unit, from stage.
const FORCES = [
  ['contact_normal_force_N', 'screw contact normal force N', 'N', 0],
  ['nut_contact_force_N', 'nut contact force N′', 'N', 0],
  ['gear_tooth_force_N', 'gear tooth force (one ring gear)', 'N', 0],
  ['cage_force_N', 'cage (pin) force', 'N', 0],
  ['spline_force_N', 'spline friction force', 'N', 1],
];

function forcesTable(d) {
  const stages = d.settled.stages || [];
  const rows = FORCES.concat([['gear_tangential_force_N', 'gear tangential force F_t', 'N', 0], ['stage_axial_load_N', 'stage axial load (all rollers)', 'N', 0],
    ['slip_speed_m_s', 'slip speed', 'm/s', 0], ['thrust_load_N', 'thrust bearing load', 'N', 1], ['thrust_torque_Nm', 'thrust bearing torque', 'N m', 1],
    ['sliding_power_W', 'sliding loss (all rollers)', 'W', 0]]);
  return h('table', { class: 'numbers', id: 'sim-forces' },
    h('caption', {}, 'Settled forces, per roller unless named otherwise'),
    h('thead', {}, h('tr', {}, h('th', { scope: 'col' }, 'force'), stages.map(s => h('th', { scope: 'col' }, `stage ${s.stage}`)))),
    h('tbody', {}, rows.filter(([, , , from]) => stages.length > from).map(([key, label, u]) => h('tr', { 'data-key': key },
      h('th', { scope: 'row' }, `${label} (${u})`),
      stages.map(s => cell(`stage${s.stage}.${key}`, s[key], typeof s[key] === 'number' ? fmt(s[key], 5) : '—')))),
      h('tr', { 'data-key': 'loaded_flank' }, h('th', { scope: 'row' }, 'loaded screw flank'), stages.map(s => h('td', {}, s.loaded_flank || '—')))));
}

function checksTable(d) {
  const c = d.checks, cv = d.convergence || {};
  const row = (key, label, v, limit) => h('tr', { 'data-key': key, class: typeof v === 'number' && v > limit ? 'violated' : undefined },
    h('th', { scope: 'row' }, label), cell(key, v, fmt(v, 3)), cell(`${key}_limit`, limit, fmt(limit, 3)),
    h('td', { 'data-key': `${key}_ok` }, typeof v === 'number' && v <= limit ? 'passed' : 'failed'));
  return [
    h('table', { class: 'numbers', id: 'sim-checks' },
      h('caption', {}, `Checks at every output time: ${c.passed ? 'both passed' : 'a check failed (see the warnings)'}`),
      h('thead', {}, h('tr', {}, ['check', 'largest', 'limit', ''].map(x => h('th', { scope: 'col' }, x)))),
      h('tbody', {},
        row('max_power_balance_relative', 'power balance: |residual| / input power', c.max_power_balance_relative, c.power_balance_limit),
        row('max_newton_euler_residual', 'Newton–Euler recovery of the carrier acceleration', c.max_newton_euler_residual, c.newton_euler_limit))),
    h('table', { class: 'numbers', id: 'sim-convergence' },
      h('caption', {}, 'Integration (GSL odeiv2)'),
      h('tbody', {}, [['steps', 'accepted steps', cv.steps], ['rhs_evaluations', 'right-hand-side evaluations', cv.rhs_evaluations],
        ['jacobian_evaluations', 'Jacobian evaluations', cv.jacobian_evaluations], ['events', 'located events', cv.events]]
        .map(([key, label, v]) => h('tr', {}, h('th', { scope: 'row' }, label), cell(key, v, typeof v === 'number' ? v.toLocaleString('en-US') : '—'))),
      h('tr', {}, h('th', { scope: 'row' }, 'implicit stepper handed over at'), cell('stepper_switch_time_s', cv.stepper_switch_time_s,
        typeof cv.stepper_switch_time_s === 'number' ? duration(cv.stepper_switch_time_s) : 'never')))),
  ];
}

// The time series cut to their first n output times (every array of the transient, its stages' too).
function sliceSeries(o, n) {
  if (Array.isArray(o)) return o.length && o[0] !== null && typeof o[0] === 'object' ? o.map(x => sliceSeries(x, n)) : o.slice(0, n);
  if (o && typeof o === 'object') return Object.fromEntries(Object.entries(o).map(([k, v]) => [k, k === 'points' ? n : sliceSeries(v, n)]));
  return o;
}

// A first-to-last description of a curve for the chart's <desc>.
const span = (label, y, u) => {
  const v = y.filter(x => typeof x === 'number' && Number.isFinite(x));
  const lo = v.reduce((a, b) => (b < a ? b : a), Infinity), hi = v.reduce((a, b) => (b > a ? b : a), -Infinity);
  return v.length ? `${label} from ${fmt(v[0])} to ${fmt(v[v.length - 1])}${u ? ` ${u}` : ''} (between ${fmt(lo)} and ${fmt(hi)})` : `${label} undefined throughout`;
};

function plots(d, x, tu) {
  const tr = d.transient, st = d.settled, K = d.stages, stages = st.stages || [];
  const xLabel = `time (${tu.unit})`;
  const n = tr.points;
  const about = `${n} output times from 0 to ${fmt(x[n - 1])} ${tu.unit}`;
  const torque = d.parameters.input.kind === 'torque';
  const figure = (svg, id, caption) => { svg.id = id; return h('figure', { class: 'plot-box' }, svg, h('figcaption', {}, caption)); };

  const carrier = seriesChart({
    x, xLabel, yLabel: 'carrier ratio ψ̇/θ̇ (–)',
    series: tr.stages.map((s, k) => ({ key: `stage${k + 1}`, label: `stage ${k + 1} carrier`, y: s.carrier_ratio, cls: stageCls(k) })),
    refs: stages.map((s, k) => ({ key: `stage${k + 1}`, value: s.carrier_ratio, cls: stageCls(k), label: `stage ${k + 1}: settled carrier ratio ${fmt(s.carrier_ratio, 6)} (k* ${fmt(s.carrier_ratio_min_slip, 6)}, statics ${fmt(s.carrier_ratio_statics, 6)})` })),
    marks: stages.flatMap((s, k) => [[0.9, s.time_to_90_percent_s], [0.99, s.time_to_99_percent_s]].map(([q, t]) => ({
      x: typeof t === 'number' ? t * tu.f : null, y: q * s.carrier_ratio, cls: stageCls(k), label: `stage ${k + 1}: ${100 * q} % of the settled ratio at ${duration(t)}` }))),
    title: `Carrier ratio of ${K === 1 ? 'the carrier' : `the ${K} carriers`} against time`,
    desc: `${about}. ${tr.stages.map((s, k) => span(`Stage ${k + 1}`, s.carrier_ratio)).join('; ')}. Dashed: the settled ratios ${stages.map(s => fmt(s.carrier_ratio, 6)).join(' and ')}; dots: 90 % and 99 % of them. Every settled value is in the table beside the chart.`,
  });
  const eff = seriesChart({
    x, xLabel, yLabel: 'efficiency η (–)',
    series: [{ key: 'efficiency', label: 'η = F_N Λ / T_in', y: tr.efficiency, cls: 's0' }],
    refs: [{ key: 'efficiency', value: st.efficiency, cls: 's0', label: `settled efficiency ${fmt(st.efficiency, 6)} (statics engine ${fmt(st.efficiency_statics, 6)})` }],
    title: 'Instantaneous efficiency against time',
    desc: `${about}. ${span('Efficiency', tr.efficiency)}; settled ${fmt(st.efficiency, 6)} (dashed), the statics engine's ${fmt(st.efficiency_statics, 6)}.`,
  });
  const torqueSeries = [{ key: 'input_torque_Nm', label: 'input torque T_in', y: tr.input_torque_Nm, cls: 's0' }];
  if (torque && Array.isArray(tr.motor_torque_Nm)) torqueSeries.push({ key: 'motor_torque_Nm', label: 'motor torque T_m', y: tr.motor_torque_Nm, cls: 's2' });
  const tq = seriesChart({
    x, xLabel, yLabel: 'torque (N m)', series: torqueSeries,
    refs: [{ key: 'input_torque_Nm', value: st.input_torque_Nm, cls: 's0', label: `settled input torque ${fmt(st.input_torque_Nm, 6)} N m` }],
    title: 'Input torque against time',
    desc: `${about}. ${torqueSeries.map(s => span(s.label, s.y, 'N m')).join('; ')}; settled input torque ${fmt(st.input_torque_Nm, 6)} N m (dashed).`,
  });
  const sp = st.speed || {};
  const speed = seriesChart({
    x, xLabel, yLabel: 'screw speed θ̇ (rad/s)',
    series: [{ key: 'screw_speed_rad_s', label: 'screw speed', y: tr.screw_speed_rad_s, cls: 's0' }],
    refs: [{ key: 'screw_speed_rad_s', value: st.screw_speed_rad_s, cls: 's0', label: `settled screw speed ${fmt(st.screw_speed_rad_s, 6)} rad/s` }],
    marks: torque ? [[0.9, sp.time_to_90_percent_s], [0.99, sp.time_to_99_percent_s]].map(([q, t]) => ({ x: typeof t === 'number' ? t * tu.f : null, y: q * st.screw_speed_rad_s, cls: 's0', label: `${100 * q} % of the settled speed at ${duration(t)}` })) : [],
    title: 'Screw speed against time',
    desc: `${about}. ${span('Screw speed', tr.screw_speed_rad_s, 'rad/s')}; settled ${fmt(st.screw_speed_rad_s, 6)} rad/s (dashed).`,
  });
  const main = h('div', { class: 'figure-row' },
    figure(carrier, 'sim-carrier-plot', `Carrier ratio ψ̇/θ̇ of ${K === 1 ? 'the stage' : 'each stage (legend)'}; dashed: settled; dots: 90 % and 99 % of it.`),
    h('div', { class: 'table-box' }, settledTable(d)));
  const grid = h('div', { class: 'plot-grid' },
    figure(eff, 'sim-efficiency-plot', 'Efficiency F_N Λ / T_in (undefined while the screw stands still); dashed: settled.'),
    figure(tq, 'sim-torque-plot', `Torque into the first screw${torqueSeries.length > 1 ? ' and the motor torque' : ''}; dashed: settled.`),
    figure(speed, 'sim-speed-plot', `Screw speed${torque ? '; dots: 90 % and 99 % of the settled speed' : ' (prescribed)'}; dashed: settled.`));

  const forceFigures = FORCES.filter(([, , , from]) => K > from).map(([key, label, u, from]) => {
    const ks = tr.stages.map((s, k) => k).filter(k => k >= from && Array.isArray(tr.stages[k][key]));
    const svg = seriesChart({
      x, xLabel, yLabel: `${label} (${u})`,
      series: ks.map(k => ({ key: `stage${k + 1}`, label: `stage ${k + 1}`, y: tr.stages[k][key], cls: stageCls(k) })),
      refs: ks.filter(k => stages[k]).map(k => ({ key: `stage${k + 1}`, value: stages[k][key], cls: stageCls(k), label: `stage ${k + 1}: settled ${label} ${fmt(stages[k][key], 6)} ${u}` })),
      title: `${label[0].toUpperCase()}${label.slice(1)} against time`,
      desc: `${about}. ${ks.map(k => span(`Stage ${k + 1}`, tr.stages[k][key], u)).join('; ')}. Dashed: settled values, in the table of settled forces.`,
    });
    return figure(svg, `sim-force-plot-${key}`, `${label[0].toUpperCase()}${label.slice(1)}${from ? ' (the coupling into stage 2 on)' : ', per roller'}; dashed: settled.`);
  });
  return { main, grid, forces: h('div', { class: 'plot-grid' }, forceFigures) };
}

// ---- the vibration analyses (docs/vibration.md; dynamics-result.schema.json $defs/vibration_dynamics):
// linear (eigenvalues, FRF, half-power band), vibration (class, Poincaré section, phase portrait,
// spectrum with its named lines, extremes, Lyapunov exponents), sweep (the bifurcation diagram up
// and down), frequency_response (harmonic balance with its folds, the sweeps, the jumps) and basins
// (the grid of initial states coloured by the attractor each reaches). The gear pair's quantities
// are dimensionless: lengths in half backlashes b_g, time τ in units of the inverse natural frequency.
const VIBRATION = { linear: 'Linearised model', vibration: 'Steady-state vibration', sweep: 'Parameter sweep (bifurcation diagram)',
  frequency_response: 'Frequency response (harmonic balance and sweeps)', basins: 'Basins of attraction' };
const isGearPair = d => !!(d.model && d.model.kind === 'gear_pair');
const cap = s => s[0].toUpperCase() + s.slice(1);
const words = s => String(s).replace(/_/g, ' ');
function observable(name, d) {
  const gp = isGearPair(d);
  const o = {
    mesh_deflection: { label: 'mesh deflection x', unit: 'half backlashes b_g', rate: 'rate x′ = dx/dτ', rateUnit: 'b_g per unit τ' },
    mesh_rate: { label: 'mesh deflection rate x′', unit: 'b_g per unit τ' },
    mesh_force: { label: 'mesh force', unit: gp ? 'scaled, k b_g' : 'N' },
    axial_deflection: { label: 'axial deflection Y = y/b_a', unit: 'half plays b_a', rate: 'axial rate W = ẏ/(b_a ω_a)', rateUnit: 'b_a ω_a' },
    axial_rate: { label: 'axial rate W = ẏ/(b_a ω_a)', unit: 'b_a ω_a' },
    thread_force: { label: 'thread force', unit: 'N' },
  }[name] || { label: words(name), unit: '–' };
  return { rate: 'its rate', rateUnit: 'scaled', ...o };
}
const PARAMETERS = {
  frequency_ratio: ['frequency ratio Ω (mesh over natural frequency)', '–'], screw_speed_rad_s: ['screw speed', 'rad/s'],
  mesh_error_um: ['mesh error', 'µm'], mesh_damping_ratio: ['mesh damping ratio', '–'], error_amplitude: ['error amplitude ε', 'half backlashes'],
  damping_ratio: ['damping ratio ζ', '–'], mean_load: ['mean load f_m', 'scaled'], stiffness_variation: ['stiffness variation κ', '–'],
};
const parameterLabel = p => { const [l, u] = PARAMETERS[p] || [words(p), '–']; return `${l} (${u})`; };
const vfigure = (svg, id, caption, wide) => { svg.id = id; return h('figure', { class: `plot-box${wide ? ' wide' : ''}` }, svg, h('figcaption', {}, caption)); };
const card = (id, title, ...children) => h('section', { class: 'card', id, 'aria-labelledby': `${id}-h` }, h('h3', { id: `${id}-h` }, title), ...children);
const numCell = (v, digits = 5) => h('td', { 'data-value': typeof v === 'number' ? String(v) : undefined }, typeof v === 'number' ? fmt(v, digits) : '—');

function vibrationSummary(r, d, job) {
  const m = d.model || {}, cv = d.convergence || {};
  const gp = m.gear_pair;
  const model = gp ? `1-DOF gear pair: ζ ${fmt(gp.damping_ratio)}, f_m ${fmt(gp.mean_load)}, ε ${fmt(gp.error_amplitude)}, κ ${fmt(gp.stiffness_variation)}, Ω ${fmt(gp.frequency_ratio)}`
    : `reduced PRSM model: ${m.rollers} rollers, ${m.states} states, branches ${m.branches}, screw speed ${withUnit(m.screw_speed_rad_s, 'rad/s')}, mesh ${withUnit(m.mesh_frequency_Hz, 'Hz')}, axial mode ${withUnit(m.axial_frequency_Hz, 'Hz')}`;
  return h('dl', { class: 'summary', id: 'sim-summary' },
    [['Simulation', r.name || '—'], ['Analysis', VIBRATION[d.analysis]], ['Model', model],
      ['Integration', `${(cv.steps || 0).toLocaleString('en-US')} steps${cv.kink_crossings ? `, ${cv.kink_crossings.toLocaleString('en-US')} contact changes` : ''}; ${cv.converged === false ? `not converged (${cv.failed_points} failed points)` : 'converged'}`],
      ['Cached', job.cache_hit ? 'yes' : 'no'], ['Engine', r.engine ? `prsm ${r.engine.version}, ${r.engine.model.replace(/ \(.*$/, '')}` : '—']]
      .map(([k, v]) => h('div', {}, h('dt', {}, k), h('dd', {}, v))));
}

// The steady state: its class, the Poincaré section, the phase portrait, the spectrum, the extremes.
function vibrationView(d) {
  const v = d.vibration, gp = isGearPair(d);
  const ob = observable(v.observable.name, d);
  const obName = `${ob.label}${v.observable.roller !== null && v.observable.roller !== undefined && !gp ? ` of roller ${v.observable.roller}` : ''}`;
  const ly = v.lyapunov;
  const perS = ly && Array.isArray(ly.exponents_per_s) && typeof ly.exponents_per_s[0] === 'number';
  const lyText = ly ? `Lyapunov exponents (${ly.method}, ${ly.periods} periods): ${ly.exponents_per_tau.map(x => fmt(x, 4)).join(', ')} per τ${perS ? ` (${ly.exponents_per_s.map(x => fmt(x, 4)).join(', ')} 1/s)` : ''}; sum ${fmt(ly.sum_per_tau, 4)} per τ; block spread ${fmt(ly.block_min_per_tau, 3)} to ${fmt(ly.block_max_per_tau, 3)}. The largest is ${ly.exponents_per_tau[0] > 1e-3 ? 'positive: chaos' : 'not positive: no chaos'}.`
    : 'Lyapunov exponents: not computed (steady_state.lyapunov false).';
  const period = `${cap(words(v.classification))}${v.period > 0 ? `, period ${v.period}` : ''}`;
  const forcing = `${v.clock === 'te' ? 'the TE’s common period' : 'the mesh period'}: ${fmt(v.forcing_period_tau)} τ${typeof v.forcing_period_s === 'number' ? ` = ${withUnit(v.forcing_period_s, 's')}` : ''}`;
  const classBox = h('div', { class: 'vib-class', id: 'vib-classification', 'data-classification': v.classification, 'data-period': String(v.period) },
    h('p', { class: 'total' }, h('strong', {}, period), ` (periods counted in forcing periods, ${forcing}); largest return distance ${fmt(v.max_return_distance, 3)} (tolerance ${fmt(v.period_tolerance, 3)}).`),
    h('p', { id: 'vib-lyapunov' }, lyText));

  const P = v.poincare;
  let poincare;
  if (P.size === 2 && Array.isArray(P.vectors) && P.vectors.length) {
    poincare = xyChart({
      series: [{ key: 'poincare', label: `${P.points} section points`, cls: 's0', kind: 'points', x: P.vectors.map(p => p[0]), y: P.vectors.map(p => p[1]), size: 3.2 }],
      xLabel: `${obName} (${ob.unit})`, yLabel: `${ob.rate} (${ob.rateUnit})`, title: 'Poincaré section',
      desc: `${P.points} points of the state at phase 0 of every recorded forcing period: ${period}.`, h: 300 });
  } else {
    const o = P.observable;
    poincare = xyChart({
      series: [{ key: 'poincare', label: `${Math.max(0, o.length - 1)} returns`, cls: 's0', kind: 'points', x: o.slice(0, -1), y: o.slice(1), size: 3.2 }],
      xLabel: `P_i: ${obName} (${ob.unit})`, yLabel: `P_i+1 (${ob.unit})`, title: 'Poincaré return map of the observable',
      desc: `The observable at each section point against the one before (the section vector has ${P.size} components): ${period}.`, h: 300 });
  }
  const pp = v.phase_portrait;
  const hasRate = pp && Array.isArray(pp.rate) && pp.rate.some(x => typeof x === 'number');
  const phase = pp && pp.points ? xyChart({
    series: [{ key: 'phase', label: '', cls: 's0', kind: 'line', x: hasRate ? pp.observable : pp.observable.map((x, i) => i / pp.samples_per_period), y: hasRate ? pp.rate : pp.observable }],
    xLabel: hasRate ? `${obName} (${ob.unit})` : 'time (forcing periods)', yLabel: hasRate ? `${ob.rate} (${ob.rateUnit})` : `${obName} (${ob.unit})`,
    title: hasRate ? 'Phase portrait' : 'The recorded response', legend: false, h: 300,
    desc: `${pp.points} samples, ${pp.samples_per_period} per forcing period, of the recorded steady state.` }) : null;

  // the spectrum: the whole one (log amplitude) with the named lines as stems
  const sf = v.spectrum_full || {};
  const hz = Array.isArray(sf.frequency_Hz) && typeof sf.frequency_Hz[1] === 'number';
  const fx = s => (hz ? s.frequency_Hz : s.frequency_ratio);
  const fullX = (hz ? sf.frequency_Hz : sf.frequency_ratio) || [], fullY = sf.amplitude || [];
  const lines = (v.spectrum || []).filter(s => s.name !== 'mean' && typeof fx(s) === 'number' && fx(s) > 0);
  const peak = Math.max(1e-300, ...fullY.slice(1).filter(Number.isFinite), ...lines.map(s => s.amplitude).filter(Number.isFinite));
  const floor = peak * 1e-7;
  const shown = lines.filter(s => typeof s.amplitude === 'number' && s.amplitude >= floor);
  const xmax = 1.15 * Math.max(...shown.map(fx), hz ? 1 : 1.5);
  const fUnit = hz ? 'frequency (Hz)' : 'frequency ratio to the natural frequency (–)';
  const spectrum = xyChart({
    series: [{ key: 'spectrum', label: `whole spectrum (${sf.window} window, ${sf.periods} periods)`, cls: 's0', kind: 'line', x: fullX.slice(1), y: fullY.slice(1) }],
    stems: shown.map(s => ({ x: fx(s), y: s.amplitude, name: s.name, label: words(s.name), cls: 's1',
      title: `${words(s.name)}: ${hz ? `${fmt(s.frequency_Hz)} Hz, ` : ''}${s.order_per_rev !== null ? `${fmt(s.order_per_rev)} per rev, ` : ''}Ω ${fmt(s.frequency_ratio)}, amplitude ${fmt(s.amplitude)} ${ob.unit}` })),
    xRange: [0, xmax], yRange: [floor, peak * 3], logY: true, h: 360,
    xLabel: fUnit, yLabel: `amplitude (${ob.unit})`, title: `Spectrum of the ${obName}`,
    desc: `One-sided amplitude spectrum of the recorded steady state on a log scale, down to 10^-7 of its peak; the named lines above that: ${shown.map(s => `${words(s.name)} ${fmt(s.amplitude)}`).join(', ')}. Every named line is in the table below.` });
  const specTable = h('table', { class: 'numbers', id: 'vib-spectrum' }, h('caption', {}, `Named lines of the spectrum (amplitude in ${ob.unit}; — not resolved by the record)`),
    h('thead', {}, h('tr', {}, ['line', 'order per rev', 'frequency (Hz)', 'Ω (–)', 'amplitude'].map(x => h('th', { scope: 'col' }, x)))),
    h('tbody', {}, (v.spectrum || []).map(s => h('tr', { 'data-name': s.name }, h('th', { scope: 'row' }, words(s.name)), numCell(s.order_per_rev), numCell(s.frequency_Hz), numCell(s.frequency_ratio), numCell(s.amplitude, 4)))));
  const extremes = h('table', { class: 'numbers', id: 'vib-extremes' }, h('caption', {}, 'Extremes of every observable over the recorded periods'),
    h('thead', {}, h('tr', {}, ['observable', 'unit', 'min', 'max', 'mean', 'RMS', 'amplitude'].map(x => h('th', { scope: 'col' }, x)))),
    h('tbody', {}, (v.extremes || []).map(e => { const o = observable(e.observable, d); return h('tr', { 'data-observable': e.observable },
      h('th', { scope: 'row' }, `${o.label}${e.roller !== null && !gp ? `, roller ${e.roller}` : ''}`), h('td', {}, o.unit), numCell(e.min), numCell(e.max), numCell(e.mean), numCell(e.rms), numCell(e.amplitude)); })));
  const contacts = (v.contacts || []).length ? h('table', { class: 'numbers', id: 'vib-contacts' }, h('caption', {}, 'Share of the recorded time each contact is open or on its back flank'),
    h('thead', {}, h('tr', {}, ['contact', 'open', 'back flank'].map(x => h('th', { scope: 'col' }, x)))),
    h('tbody', {}, v.contacts.map(c => h('tr', {}, h('th', { scope: 'row' }, words(c.contact)), h('td', {}, `${fmt(100 * c.open_share, 3)} %`), h('td', {}, `${fmt(100 * c.back_flank_share, 3)} %`))))) : null;
  return card('vib-vibration-card', `Steady-state vibration of the ${obName}`, classBox,
    h('div', { class: 'plot-grid' }, vfigure(poincare, 'vib-poincare-plot', 'Poincaré section: the state once per forcing period (a period-m orbit shows m points).'),
      phase ? vfigure(phase, 'vib-phase-plot', 'Phase portrait of the recorded steady state.') : null),
    vfigure(spectrum, 'vib-spectrum-plot', 'Amplitude spectrum (log scale) with the named lines marked and labelled above the plot.', true),
    h('div', { class: 'tables vib-tables' }, extremes, contacts, specTable));
}

// A sweep direction's points as markers: every Poincaré value at its parameter value.
function sweepSeries(points, param, key, label, cls, marker, hollow) {
  const ok = (points || []).filter(p => p.converged && Array.isArray(p.poincare));
  const x = [], y = [];
  for (const p of ok) for (const q of p.poincare) { x.push(p[param]); y.push(q); }
  return { key, label: `${label} (${ok.length} points)`, cls, kind: 'points', marker, hollow, size: hollow ? 3.4 : 2.4, x, y, data: { 'data-sweep-points': ok.length } };
}
const failedList = (dirs, param) => {
  const failed = dirs.flatMap(([name, pts]) => (pts || []).filter(p => !p.converged).map(p => `${name}: ${parameterLabel(param).replace(/ \(.*/, '')} ${fmt(p[param])}: ${p.error || 'did not converge'}`));
  return h('div', { id: 'vib-failed', 'data-failed': String(failed.length) }, failed.length ? [h('p', {}, `${failed.length} points failed and are not drawn:`), h('ul', { class: 'warnings' }, failed.map(f => h('li', {}, f)))]
    : h('p', { class: 'hint' }, 'Every point converged.'));
};
const classCounts = pts => {
  const c = {};
  for (const p of pts || []) { if (!p.converged) continue; const k = p.classification === 'periodic' ? `period ${p.period}` : words(p.classification); c[k] = (c[k] || 0) + 1; }
  return Object.entries(c).map(([k, n]) => `${n} ${k}`).join(', ') || 'none';
};

function sweepView(d) {
  const s = d.sweep, param = s.parameter;
  const ob = observable(s.observable.name, d);
  const dirs = [['up', s.up], ['down', s.down]].filter(([, p]) => Array.isArray(p) && p.length);
  const series = dirs.map(([name, pts]) => (name === 'up' ? sweepSeries(pts, param, 'up', 'sweep up', 's0', 'circle', false) : sweepSeries(pts, param, 'down', 'sweep down', 's1', 'square', true)));
  const chart = xyChart({ series, xLabel: parameterLabel(param), yLabel: `Poincaré values: ${ob.label} (${ob.unit})`, title: 'Bifurcation diagram', h: 380,
    desc: `The ${s.recorded_periods} Poincaré values of the ${ob.label} at each value of the ${parameterLabel(param)}, ${dirs.map(([n]) => `sweeping ${n}`).join(' and ')} (${s.continuation ? 'each point from the previous one’s end state' : 'every point from one state'}). ${dirs.map(([n, p]) => `${n}: ${classCounts(p)}`).join('; ')}.` });
  return card('vib-sweep-card', 'Bifurcation diagram',
    vfigure(chart, 'vib-bifurcation-plot', 'Filled circles: sweeping up; open squares: sweeping down. One mark per Poincaré value; a period-m orbit shows m marks, a non-periodic one a spread.', true),
    h('p', { id: 'vib-sweep-classes' }, dirs.map(([n, p]) => `Sweeping ${n}: ${classCounts(p)}.`).join(' ')),
    failedList(dirs, param));
}

function frequencyResponseView(d) {
  const f = d.frequency_response, hb = f.harmonic_balance || { points: 0, frequency_ratio: [], amplitude: [], stable: [], folds: [] };
  const part = want => hb.amplitude.map((a, i) => (hb.stable[i] === want || hb.stable[i + 1] === want || hb.stable[i - 1] === want) && (i === 0 || hb.segment[i] === hb.segment[i - 1] || hb.stable[i] === want) ? a : null);
  const amp = pts => (pts || []).filter(p => p.converged);
  const up = amp(f.sweep_up), down = amp(f.sweep_down);
  const jumpAt = j => (j.exact_fold && j.exact_fold.found ? { x: j.exact_fold.frequency_ratio, y: j.exact_fold.amplitude } : null);
  const sweepAmp = (pts, x) => { const p = (pts || []).find(q => Math.abs(q.frequency_ratio - x) < 1e-9); return p ? p.amplitude : null; };
  const chart = xyChart({
    series: [
      { key: 'hb-stable', label: 'harmonic balance, stable', cls: 's2', kind: 'line', x: hb.frequency_ratio, y: part(true) },
      { key: 'hb-unstable', label: 'unstable', cls: 's2', kind: 'line', dash: true, x: hb.frequency_ratio, y: part(false) },
      { key: 'sweep-up', label: `sweep up (${up.length})`, cls: 's0', kind: 'points', marker: 'circle', size: 2.8, x: up.map(p => p.frequency_ratio), y: up.map(p => p.amplitude) },
      { key: 'sweep-down', label: `sweep down (${down.length})`, cls: 's1', kind: 'points', marker: 'square', hollow: true, size: 3.6, x: down.map(p => p.frequency_ratio), y: down.map(p => p.amplitude) },
    ],
    marks: (hb.folds || []).map(k => ({ x: k.frequency_ratio, y: k.amplitude, kind: 'fold', marker: 'diamond', cls: 'fold', text: 'fold', label: `fold (${k.kind}) at Ω ${fmt(k.frequency_ratio, 5)}, amplitude ${fmt(k.amplitude)}` }))
      .concat((f.jumps || []).flatMap(j => {
        const a = sweepAmp(j.direction === 'up' ? f.sweep_up : f.sweep_down, j.from_frequency_ratio), b = sweepAmp(j.direction === 'up' ? f.sweep_up : f.sweep_down, j.to_frequency_ratio);
        const e = jumpAt(j);
        return [{ x: (j.from_frequency_ratio + j.to_frequency_ratio) / 2, y: typeof a === 'number' && typeof b === 'number' ? (a + b) / 2 : a, kind: 'jump', marker: 'triangle', cls: `jump ${j.direction}`, size: 6,
          text: `jump ${j.direction}`, label: `jump sweeping ${j.direction} between Ω ${fmt(j.from_frequency_ratio)} and ${fmt(j.to_frequency_ratio)}${e ? `; exact fold at Ω ${fmt(e.x, 6)}` : ''}` }];
      })),
    xLabel: parameterLabel('frequency_ratio'), yLabel: 'amplitude (max − min)/2 (half backlashes b_g)', title: 'Frequency response: harmonic balance and the sweeps', h: 380,
    desc: `Harmonic balance over ${hb.points} points (dashed where unstable) with ${(hb.folds || []).length} folds; ${up.length} points sweeping up, ${down.length} sweeping down; ${(f.jumps || []).length} jumps.` });
  const jumps = h('table', { class: 'numbers', id: 'vib-jumps' }, h('caption', {}, 'Jumps between neighbouring sweep points'),
    h('thead', {}, h('tr', {}, ['direction', 'from Ω', 'to Ω', 'exact fold Ω', 'amplitude there'].map(x => h('th', { scope: 'col' }, x)))),
    h('tbody', {}, (f.jumps || []).map(j => h('tr', {}, h('th', { scope: 'row' }, j.direction), numCell(j.from_frequency_ratio), numCell(j.to_frequency_ratio),
      numCell(j.exact_fold && j.exact_fold.found ? j.exact_fold.frequency_ratio : null, 6), numCell(j.exact_fold && j.exact_fold.found ? j.exact_fold.amplitude : null)))));
  return card('vib-fr-card', 'Frequency response',
    vfigure(chart, 'vib-fr-plot', 'Green: harmonic balance (dashed: unstable); diamonds: its folds; filled circles: sweeping up; open squares: sweeping down; triangles: the jumps.', true),
    h('div', { class: 'tables vib-tables' }, jumps), failedList([['up', f.sweep_up], ['down', f.sweep_down]], 'frequency_ratio'));
}

function linearView(d) {
  const l = d.linear, f = l.frf, hp = l.half_power || {};
  const gp = isGearPair(d);
  const eig = (l.eigenvalues || []).filter(e => !(e.imag_per_tau < 0));
  const table = h('table', { class: 'numbers', id: 'vib-eigenvalues' }, h('caption', {}, `Eigenvalues of the linearised model (${l.dofs} degrees of freedom; one row per complex-conjugate pair)`),
    h('thead', {}, h('tr', {}, ['kind', ...(gp ? [] : ['Re λ (1/s)', 'Im λ (rad/s)', 'f (Hz)']), 'Re λ (per τ)', 'Im λ (per τ)', 'ζ (–)'].map(x => h('th', { scope: 'col' }, x)))),
    h('tbody', {}, eig.map(e => h('tr', { 'data-kind': e.kind }, h('th', { scope: 'row' }, e.kind),
      ...(gp ? [] : [numCell(e.real_per_s), numCell(e.imag_rad_s), numCell(e.frequency_Hz, 6)]), numCell(e.real_per_tau), numCell(e.imag_per_tau), numCell(e.damping_ratio)))));
  const hz = Array.isArray(f.frequency_Hz) && typeof f.frequency_Hz[0] === 'number';
  const fx = hz ? f.frequency_Hz : f.frequency_ratio;
  const mags = f.magnitude.filter(x => x > 0);
  const logY = mags.length && Math.max(...mags) / Math.min(...mags) > 20;
  const hpx = k => (hz ? hp[`${k}_frequency_Hz`] : hp[`${k}_frequency_ratio`]);
  const stems = hp.defined ? [['lower', 'f₁'], ['peak', 'peak'], ['upper', 'f₂']].map(([k, lab]) => ({ x: hpx(k), y: k === 'peak' ? hp.peak_magnitude : hp.peak_magnitude / Math.SQRT2, name: k, label: lab, cls: 's1',
    title: `${k === 'peak' ? 'peak' : `${k} half-power frequency`}: ${fmt(hpx(k), 6)} ${hz ? 'Hz' : ''}` })) : [];
  const xl = hz ? 'frequency (Hz)' : 'frequency ratio Ω (–)';
  const io = `${words(f.output)}${gp ? '' : ` ${f.output_roller}`} / ${words(f.input)}${gp ? '' : ` ${f.input_roller}`}`;
  const mag = xyChart({ series: [{ key: 'frf', label: `|H| (${f.points} points)`, cls: 's0', kind: 'line', x: fx, y: f.magnitude }], stems, logY, h: 340,
    xLabel: xl, yLabel: `|H|: ${io} (${f.unit || '–'})`, title: 'Frequency response function, magnitude',
    desc: `|H| of ${io} over ${fmt(fx[0])} to ${fmt(fx[fx.length - 1])} ${hz ? 'Hz' : ''}${logY ? ' on a log scale' : ''}; ${hp.defined ? `peak ${fmt(hp.peak_magnitude)} at ${fmt(hpx('peak'), 6)}, half-power band ${fmt(hpx('lower'), 6)} to ${fmt(hpx('upper'), 6)}` : 'no half-power band'}.` });
  const phase = Array.isArray(f.phase_deg) ? xyChart({ series: [{ key: 'phase', label: '', cls: 's0', kind: 'line', x: fx, y: f.phase_deg }], legend: false, h: 240,
    xLabel: xl, yLabel: 'phase (°)', title: 'Frequency response function, phase', desc: `Phase of ${io} in degrees.` }) : null;
  const hpText = hp.defined ? `Half-power band: ${fmt(hpx('lower'), 6)} to ${fmt(hpx('upper'), 6)} ${hz ? 'Hz' : '(Ω)'} around the peak ${fmt(hp.peak_magnitude)} at ${fmt(hpx('peak'), 6)} ${hz ? 'Hz' : ''}: damping ratio ${fmt(hp.damping_ratio, 4)} from the band, ${fmt(hp.modal_damping_ratio, 4)} of the nearest mode (${hz ? `${fmt(hp.modal_frequency_Hz, 6)} Hz` : `Ω ${fmt(hp.modal_frequency_ratio, 6)}`}).`
    : `Half-power band: not defined${hp.reason ? ` (${hp.reason})` : ''}.`;
  return card('vib-linear-card', 'Linearised model: eigenvalues and frequency response',
    h('div', { class: 'figure-row' }, vfigure(mag, 'vib-frf-plot', 'Magnitude of the FRF; stems: the peak and the half-power frequencies f₁, f₂.'), h('div', { class: 'table-box' }, h('p', { id: 'vib-half-power' }, hpText))),
    phase ? h('div', { class: 'plot-grid' }, vfigure(phase, 'vib-frf-phase-plot', 'Phase of the FRF.')) : null,
    h('div', { class: 'table-wrap' }, table));
}

function basinsView(d) {
  const b = d.basins;
  const keys = (b.attractors || []).map((a, i) => ({ label: a.label, color: PALETTE[i % 6], name: `attractor ${a.label} (period ${a.period}), ${fmt(100 * a.fraction, 3)} %` }))
    .concat([{ label: -1, color: '#b9bec6', name: `other, ${fmt(100 * b.other.fraction, 3)} %` }, { label: -2, color: '#222222', name: `failed, ${fmt(100 * b.failed.fraction, 3)} %` }]);
  const ob = observable('mesh_deflection', d);
  const map = cellMap({ x: b.deflection, y: b.rate, labels: b.labels, byColumn: true, keys,
    marks: (b.attractors || []).flatMap((a, i) => (a.poincare || []).map(p => ({ x: p[0], y: p[1], color: PALETTE[i % 6], text: String(a.label), label: `attractor ${a.label}: section point (${fmt(p[0])}, ${fmt(p[1])})` }))),
    xLabel: `initial ${ob.label} (${ob.unit})`, yLabel: `initial ${ob.rate} (${ob.rateUnit})`, title: 'Basins of attraction',
    desc: `${b.deflection_cells} × ${b.rate_cells} initial states, each coloured by the attractor it reaches: ${keys.map(k => k.name).join('; ')}.` });
  return card('vib-basins-card', 'Basins of attraction',
    h('div', { class: 'figure-row' }, vfigure(map, 'vib-basins-plot', 'Each cell: an initial state, coloured by the attractor it reaches (legend: share of the cells); diamonds: the attractors’ Poincaré points.')));
}

function renderVibration(container, job, r, d) {
  container.append(vibrationSummary(r, d, job));
  const status = h('span', { id: 'sim-download-status', role: 'status', 'aria-live': 'polite', class: 'hint' });
  const jsonButton = h('button', { type: 'button', id: 'sim-json-download' }, 'Download JSON');
  jsonButton.addEventListener('click', () => {
    download(`simulation-${job.id}.json`, 'application/json', `${JSON.stringify(r, null, 2)}\n`);
    status.textContent = `Saved simulation-${job.id}.json: the result (dynamics-result.schema.json).`;
  });
  container.append(h('div', { class: 'actions downloads' }, jsonButton, h('a', { href: job.links.self, id: 'sim-json-link' }, 'Job as JSON (API)'), status));
  const warnings = r.warnings || [];
  if (warnings.length) container.append(h('ul', { class: 'warnings', id: 'sim-warnings', 'aria-label': 'Warnings' }, warnings.map(w => h('li', {}, `${w.pointer ? `${w.pointer}: ` : ''}${w.message}`))));
  const view = { linear: linearView, vibration: vibrationView, sweep: sweepView, frequency_response: frequencyResponseView, basins: basinsView }[d.analysis];
  try {
    container.append(view(d));
  } catch (e) {
    container.append(h('p', { class: 'hint' }, `This ${d.analysis} result could not be drawn (${e.message}): see it as JSON at ${job.links.self}.`));
  }
}

export function renderSimulationResult(container, job) {
  container.textContent = '';
  const r = job.result || {};
  const d = r.dynamics;
  if (d && VIBRATION[d.analysis] && d[d.analysis]) {
    renderVibration(container, job, r, d);
    return;
  }
  if (!d || !d.transient || !d.settled) {
    container.append(h('p', { class: 'hint' }, `No time series in this result: see it as JSON at ${job.links.self}.`));
    return;
  }
  const p = d.parameters, tr = d.transient;
  const torque = p.input.kind === 'torque';
  const input = torque ? `motor torque ${fmt(p.input.value_Nm)} N m (${p.input.shape})` : `screw speed ${fmt(p.input.value_rad_s)} rad/s (${p.input.shape})`;
  container.append(h('dl', { class: 'summary', id: 'sim-summary' },
    [['Simulation', r.name || '—'], ['Stages', String(d.stages)], ['Input', input],
      ['Load', `${fmt(p.load.axial_load_N)} N (${p.load.shape})`], ['Friction', `${p.friction.model}${p.friction.stick_model === 'karnopp' ? ', Karnopp sticking' : ''}`],
      ['Losses', p.losses === 'statics' ? 'statics engine’s losses' : 'screw–roller sliding only'],
      ['Simulated', `${duration(p.time.end_s)}, ${tr.points.toLocaleString('en-US')} output times`],
      ['Stepper', `${p.time.stepper}, ${(d.convergence && d.convergence.steps || 0).toLocaleString('en-US')} steps`],
      ...(d.stick ? [['Sticking (Karnopp)', `break-away torque ${withUnit(d.stick.breakaway_torque_Nm, 'N m')}, ${d.stick.mode_changes} stick/slip changes`]] : []),
      ['Checks', d.checks.passed ? 'passed' : 'failed'], ['Cached', job.cache_hit ? 'yes' : 'no'],
      ['Engine', r.engine ? `prsm ${r.engine.version}, ${r.engine.model.replace(/ \(.*$/, '')}` : '—']]
      .map(([k, v]) => h('div', {}, h('dt', {}, k), h('dd', {}, v)))));

  const status = h('span', { id: 'sim-download-status', role: 'status', 'aria-live': 'polite', class: 'hint' });
  const csvButton = h('button', { type: 'button', id: 'sim-csv-download' }, 'Download CSV');
  const jsonButton = h('button', { type: 'button', id: 'sim-json-download' }, 'Download JSON');
  const base = `simulation-${job.id}`;
  csvButton.addEventListener('click', () => {
    // a long run takes a moment to write (about a second per 10^6 numbers): say so first
    status.textContent = `Writing ${tr.points.toLocaleString('en-US')} rows…`;
    csvButton.disabled = true;
    setTimeout(() => {
      try {
        download(`${base}.csv`, 'text/csv', seriesCsv(r));
        status.textContent = `Saved ${base}.csv: ${tr.points.toLocaleString('en-US')} rows, the columns of prsm simulate --csv.`;
      } finally {
        csvButton.disabled = false;
      }
    }, 30);
  });
  jsonButton.addEventListener('click', () => {
    download(`${base}.json`, 'application/json', `${JSON.stringify(r, null, 2)}\n`);
    status.textContent = `Saved ${base}.json: the result (dynamics-result.schema.json).`;
  });
  container.append(h('div', { class: 'actions downloads' }, csvButton, jsonButton,
    h('a', { href: job.links.self, id: 'sim-json-link' }, 'Job as JSON (API)'), status));
  const warnings = r.warnings || [];
  if (warnings.length) container.append(h('ul', { class: 'warnings', id: 'sim-warnings', 'aria-label': 'Warnings' }, warnings.map(w => h('li', {}, `${w.pointer ? `${w.pointer}: ` : ''}${w.message}`))));
  if (!tr.points) return;

  const tu = timeUnit(p.time.end_s);
  const x = tr.time_s.map(t => t * tu.f);

  // the plotted window: the whole run, or its first part (a long run's start-up)
  const upTo = h('input', { id: 'sim-window', type: 'number', min: 0, step: 'any', 'aria-describedby': 'sim-window-hint' });
  const whole = h('button', { type: 'button', id: 'sim-window-all' }, 'Whole run');
  const times = [(d.settled.speed || {}).time_to_99_percent_s].concat((d.settled.stages || []).map(s => s.time_to_99_percent_s)).filter(t => typeof t === 'number');
  const startUp = times.length ? Math.min(p.time.end_s, 2 * Math.max(...times)) : null;
  const startButton = startUp && startUp < p.time.end_s ? h('button', { type: 'button', id: 'sim-window-startup' }, `Start-up (to ${fmt(startUp * tu.f, 3)} ${tu.unit})`) : null;
  const plotsBox = h('div', { id: 'sim-plots' }), forcesBox = h('div', { id: 'sim-force-plots' });
  const windowNote = h('span', { id: 'sim-window-hint', class: 'hint' });
  const draw = limit => {
    let n = tr.points;
    if (typeof limit === 'number' && limit > 0 && limit < x[n - 1]) n = Math.max(2, x.findIndex(t => t > limit * (1 + 1e-12)));
    const dd = n === tr.points ? d : { ...d, transient: sliceSeries(tr, n) };
    const { main, grid, forces } = plots(dd, x.slice(0, n), tu);
    plotsBox.replaceChildren(main, grid);
    forcesBox.replaceChildren(forces);
    upTo.value = String(Number(x[n - 1].toPrecision(6)));
    windowNote.textContent = n === tr.points ? `${tu.unit}: the whole run (${n.toLocaleString('en-US')} output times)` : `${tu.unit}: the first ${n.toLocaleString('en-US')} of ${tr.points.toLocaleString('en-US')} output times`;
    plotsBox.dataset.points = String(n);
  };
  upTo.addEventListener('change', () => draw(Number(upTo.value)));
  whole.addEventListener('click', () => draw());
  if (startButton) startButton.addEventListener('click', () => draw(startUp * tu.f));
  draw();
  container.append(
    h('section', { class: 'card', id: 'sim-carrier-card', 'aria-labelledby': 'sim-carrier-h' },
      h('h3', { id: 'sim-carrier-h' }, `Start-up: carrier${d.stages > 1 ? 's' : ''}, efficiency, torque and speed`),
      h('div', { class: 'controls' }, h('label', { for: 'sim-window' }, 'Plot from 0 to'), upTo, windowNote, whole, startButton),
      plotsBox),
    h('section', { class: 'card', id: 'sim-forces-card', 'aria-labelledby': 'sim-forces-h' },
      h('h3', { id: 'sim-forces-h' }, 'Forces'), h('p', { class: 'hint' }, 'Over the same time as the plots above.'), forcesBox, h('div', { class: 'table-wrap' }, forcesTable(d))),
    h('section', { class: 'card', id: 'sim-checks-card', 'aria-labelledby': 'sim-checks-h' },
      h('h3', { id: 'sim-checks-h' }, 'Checks and integration'),
      h('p', { class: 'hint' }, 'The power balance (input = output + losses + rate of kinetic energy) and the Newton–Euler recovery of the constraint forces are evaluated at every output time (docs/dynamics.md).'),
      h('div', { class: 'tables' }, checksTable(d))));
}

export function setupSimulation(openapi, ctx) {
  const paths = (openapi && openapi.paths) || {};
  if (!paths[`/v1/${COLLECTION}`]) return false;
  document.getElementById('simulation').hidden = false;
  document.getElementById('nav-simulation').hidden = false;
  ctx.jobs.renderers[COLLECTION] = renderSimulationResult;
  const examples = ctx.examples.filter(e => e.kind === 'simulation');
  const editor = requestEditor(document.getElementById('simulation-body'), {
    prefix: 'sim', collection: COLLECTION, noun: 'Simulation', schema: 'simulation.schema.json',
    examples, submitLabel: 'Run simulation',
    fields: [
      { path: 'dynamics.time.end_s', label: 'End time (s)', type: 'number', placeholder: '0.005' },
      { path: 'dynamics.time.output_step_s', label: 'Output step (s)', type: 'number', placeholder: 'end / 500' },
      { path: 'dynamics.input.kind', label: 'Input', type: 'enum', options: ['speed', 'torque'], placeholder: 'speed (default)' },
      { path: 'dynamics.input.value_rad_s', label: 'Screw speed (rad/s)', type: 'number', placeholder: '100', hint: 'speed input' },
      { path: 'dynamics.input.value_Nm', label: 'Motor torque (N m)', type: 'number', hint: 'torque input' },
      { path: 'dynamics.load.axial_load_N', label: 'Axial load (N)', type: 'number', placeholder: '7000' },
      { path: 'dynamics.friction.model', label: 'Friction model', type: 'enum', options: ['coulomb', 'viscous', 'stribeck'], placeholder: 'coulomb (default)' },
      { path: 'dynamics.losses', label: 'Losses', type: 'enum', options: ['statics', 'sliding_only'], placeholder: 'statics (default)' },
      { path: 'dynamics.time.stepper', label: 'Stepper', type: 'enum', options: ['auto', 'rk8pd', 'msbdf', 'rk4imp'], placeholder: 'auto (default)' },
    ],
    onSubmitted: (r, doc) => ctx.submitted(r, doc, COLLECTION),
  });
  if (examples.length) api.example(examples[0].file).then(doc => { if (!editor.textarea.value) editor.setDoc(doc, `Loaded ${examples[0].file}; pick another example or edit the request.`); }).catch(() => {});
  return true;
}
