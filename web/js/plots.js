// Small SVG charts drawn from the API's JSON: histogram with spec limits, line, tornado, bars and a
// clickable scatter. No library: each returns an <svg role="img"> named by its <title> and described
// by its <desc> (the scatter, whose points are buttons, is an <svg role="group">: an image's children
// would be hidden from assistive technology).

const NS = 'http://www.w3.org/2000/svg';
let uid = 0;

export function el(name, attrs = {}, parent) {
  const e = document.createElementNS(NS, name);
  for (const [k, v] of Object.entries(attrs)) if (v !== undefined && v !== null) e.setAttribute(k, String(v));
  if (parent) parent.appendChild(e);
  return e;
}

function text(parent, x, y, s, attrs = {}) {
  const t = el('text', { x, y, ...attrs }, parent);
  t.textContent = s;
  return t;
}

// Significant-digit formatting for tables and labels; null/undefined/NaN as an em dash.
export function fmt(v, digits = 4) {
  if (v === null || v === undefined || Number.isNaN(v)) return '—';
  if (typeof v !== 'number') return String(v);
  if (!Number.isFinite(v)) return v > 0 ? '∞' : '−∞';
  if (v === 0) return '0';
  const a = Math.abs(v);
  let s;
  if (a >= 1e6 || a < 1e-4) s = v.toExponential(digits - 1).replace(/\.?0+e/, 'e');
  else if (a >= 10 ** digits) s = v.toFixed(0);
  else s = String(Number(v.toPrecision(digits)));
  return s.replace(/^-/, '−');
}

export function percent(f, digits = 2) {
  if (f === null || f === undefined) return '—';
  return `${(100 * f).toFixed(digits)} %`;
}

// Ticks at 1, 2, 5 x 10^k covering [lo, hi].
export function ticks(lo, hi, count = 5) {
  if (!(hi > lo)) return [lo];
  const raw = (hi - lo) / count;
  const mag = 10 ** Math.floor(Math.log10(raw));
  const step = [1, 2, 5, 10].map(m => m * mag).find(s => s >= raw) || 10 * mag;
  const out = [];
  for (let t = Math.ceil(lo / step) * step; t <= hi + step * 1e-9; t += step) out.push(Math.abs(t) < step * 1e-9 ? 0 : t);
  return out;
}

function scale(d0, d1, r0, r1) {
  const k = d1 === d0 ? 0 : (r1 - r0) / (d1 - d0);
  return v => r0 + (v - d0) * k;
}

function frame(w, h, title, desc, cls, role = 'img') {
  const id = `plot${++uid}`;
  const svg = el('svg', { viewBox: `0 0 ${w} ${h}`, width: '100%', role, 'aria-labelledby': `${id}t`, 'aria-describedby': `${id}d`, class: `plot ${cls}` });
  el('title', { id: `${id}t` }, svg).textContent = title;
  el('desc', { id: `${id}d` }, svg).textContent = desc;
  return svg;
}

// A tick's label with the decimals its step needs (0.8965, 0.897, 0.8975 stay distinct).
function tickLabel(t, list) {
  const step = list.length > 1 ? Math.abs(list[1] - list[0]) : 0;
  if (!step || Math.abs(t) >= 1e6 || (Math.abs(t) < 1e-4 && t !== 0)) return fmt(t, 3);
  const d = Math.max(0, Math.min(10, -Math.floor(Math.log10(step) + 1e-9)));
  return t.toFixed(d).replace(/^-/, '−');
}

function axes(svg, m, w, h, xs, ys, xt, yt, xLabel, yLabel) {
  const g = el('g', { class: 'axes' }, svg);
  el('line', { x1: m.l, y1: h - m.b, x2: w - m.r, y2: h - m.b }, g);
  el('line', { x1: m.l, y1: m.t, x2: m.l, y2: h - m.b }, g);
  for (const t of xt) {
    const x = xs(t);
    el('line', { x1: x, y1: h - m.b, x2: x, y2: h - m.b + 4 }, g);
    text(g, x, h - m.b + 16, tickLabel(t, xt), { 'text-anchor': 'middle' });
  }
  for (const t of yt) {
    const y = ys(t);
    el('line', { x1: m.l - 4, y1: y, x2: m.l, y2: y }, g);
    el('line', { x1: m.l, y1: y, x2: w - m.r, y2: y, class: 'grid' }, g);
    text(g, m.l - 6, y + 4, tickLabel(t, yt), { 'text-anchor': 'end' });
  }
  if (xLabel) text(g, (m.l + w - m.r) / 2, h - 4, xLabel, { 'text-anchor': 'middle', class: 'label' });
  if (yLabel) text(g, 12, (m.t + h - m.b) / 2, yLabel, { 'text-anchor': 'middle', class: 'label', transform: `rotate(-90 12 ${(m.t + h - m.b) / 2})` });
}

// hist: {lower, upper, counts[]} of the result; spec: {lower?, upper?}; the x range is widened to
// show the spec limits. Bars outside the spec are marked "out".
export function histogram({ hist, spec, label, unit, title, desc }) {
  const w = 520, h = 260, m = { l: 52, r: 14, t: 14, b: 40 };
  const svg = frame(w, h, title, desc, 'histogram');
  const n = hist.counts.length;
  const binW = (hist.upper - hist.lower) / n || 1;
  let lo = hist.lower, hi = hist.upper > hist.lower ? hist.upper : hist.lower + 1;
  const limits = [spec && spec.lower, spec && spec.upper].filter(v => typeof v === 'number');
  for (const v of limits) { lo = Math.min(lo, v); hi = Math.max(hi, v); }
  const pad = 0.04 * (hi - lo);
  lo -= pad; hi += pad;
  const maxC = Math.max(1, ...hist.counts);
  const xs = scale(lo, hi, m.l, w - m.r), ys = scale(0, maxC * 1.08, h - m.b, m.t);
  axes(svg, m, w, h, xs, ys, ticks(lo, hi, 6), ticks(0, maxC * 1.08, 4), `${label}${unit ? ` (${unit})` : ''}`, 'samples');
  const g = el('g', { class: 'bars' }, svg);
  hist.counts.forEach((c, i) => {
    const a = hist.lower + i * binW, b = a + binW, mid = (a + b) / 2;
    const out = spec && ((typeof spec.lower === 'number' && mid < spec.lower) || (typeof spec.upper === 'number' && mid > spec.upper));
    const r = el('rect', { x: xs(a), y: ys(c), width: Math.max(0.5, xs(b) - xs(a) - 0.5), height: Math.max(0, ys(0) - ys(c)), class: out ? 'bar out' : 'bar', 'data-count': c }, g);
    el('title', {}, r).textContent = `${fmt(a)} to ${fmt(b)}: ${c} samples`;
  });
  for (const [k, v] of [['lower', spec && spec.lower], ['upper', spec && spec.upper]]) {
    if (typeof v !== 'number') continue;
    const x = xs(v);
    el('line', { x1: x, y1: m.t, x2: x, y2: h - m.b, class: `spec spec-${k}`, 'data-value': v }, svg);
    text(svg, x + (k === 'lower' ? 4 : -4), m.t + 12, `${k === 'lower' ? 'L' : 'U'} = ${fmt(v)}`, { 'text-anchor': k === 'lower' ? 'start' : 'end', class: 'spec-label' });
  }
  return svg;
}

// A polyline y(x) with optional zero line.
export function lineChart({ x, y, xLabel, yLabel, title, desc, xTicks }) {
  const w = 520, h = 240, m = { l: 52, r: 14, t: 14, b: 40 };
  const svg = frame(w, h, title, desc, 'line-chart');
  let ylo = Math.min(0, ...y), yhi = Math.max(0, ...y);
  if (yhi - ylo < 1e-9) { ylo -= 1; yhi += 1; }
  const pad = 0.08 * (yhi - ylo);
  const xs = scale(x[0], x[x.length - 1], m.l, w - m.r), ys = scale(ylo - pad, yhi + pad, h - m.b, m.t);
  axes(svg, m, w, h, xs, ys, xTicks || ticks(x[0], x[x.length - 1], 6), ticks(ylo - pad, yhi + pad, 5), xLabel, yLabel);
  el('line', { x1: m.l, x2: w - m.r, y1: ys(0), y2: ys(0), class: 'zero' }, svg);
  const pts = x.map((xi, i) => `${xs(xi).toFixed(2)},${ys(y[i]).toFixed(2)}`).join(' ');
  el('polyline', { points: pts, class: 'curve', 'data-points': x.length }, svg);
  const g = el('g', { class: 'markers' }, svg);
  x.forEach((xi, i) => {
    const c = el('circle', { cx: xs(xi), cy: ys(y[i]), r: 2.5, class: 'marker' }, g);
    el('title', {}, c).textContent = `${fmt(xi)}: ${fmt(y[i])}`;
  });
  return svg;
}

// items: [{label, value, lo?, hi?}] sorted by the caller; signed: bars grow both ways from 0.
export function tornado({ items, xLabel, title, desc, signed }) {
  const rowH = 22, w = 560, m = { l: 230, r: 20, t: 10, b: 40 };
  const h = m.t + m.b + rowH * Math.max(1, items.length);
  const svg = frame(w, h, title, desc, 'tornado');
  const vals = items.flatMap(it => [it.value, it.lo, it.hi]).filter(v => typeof v === 'number' && Number.isFinite(v));
  let lo = signed ? Math.min(0, ...vals) : 0, hi = Math.max(0, ...vals);
  if (hi - lo < 1e-12) hi = lo + 1;
  const xs = scale(lo, hi, m.l, w - m.r);
  const xt = ticks(lo, hi, 5);
  const g = el('g', { class: 'axes' }, svg);
  el('line', { x1: xs(0), y1: m.t, x2: xs(0), y2: h - m.b }, g);
  el('line', { x1: m.l, y1: h - m.b, x2: w - m.r, y2: h - m.b }, g);
  for (const t of xt) {
    el('line', { x1: xs(t), y1: h - m.b, x2: xs(t), y2: h - m.b + 4 }, g);
    text(g, xs(t), h - m.b + 16, tickLabel(t, xt), { 'text-anchor': 'middle' });
  }
  text(g, (m.l + w - m.r) / 2, h - 4, xLabel, { 'text-anchor': 'middle', class: 'label' });
  const bars = el('g', { class: 'bars' }, svg);
  items.forEach((it, i) => {
    const y = m.t + i * rowH;
    text(bars, m.l - 6, y + rowH * 0.68, it.label, { 'text-anchor': 'end', class: 'row-label' });
    const v = Number.isFinite(it.value) ? it.value : 0;
    const x0 = xs(Math.min(0, v)), x1 = xs(Math.max(0, v));
    const r = el('rect', { x: x0, y: y + 3, width: Math.max(0.5, x1 - x0), height: rowH - 6, class: v < 0 ? 'bar neg' : 'bar', 'data-value': it.value, 'data-label': it.label }, bars);
    el('title', {}, r).textContent = `${it.label}: ${fmt(it.value)}${typeof it.lo === 'number' ? ` (95 % ${fmt(it.lo)} to ${fmt(it.hi)})` : ''}`;
    if (typeof it.lo === 'number' && typeof it.hi === 'number') {
      const yc = y + rowH / 2;
      el('line', { x1: xs(it.lo), x2: xs(it.hi), y1: yc, y2: yc, class: 'whisker' }, bars);
      el('line', { x1: xs(it.lo), x2: xs(it.lo), y1: yc - 4, y2: yc + 4, class: 'whisker' }, bars);
      el('line', { x1: xs(it.hi), x2: xs(it.hi), y1: yc - 4, y2: yc + 4, class: 'whisker' }, bars);
    }
  });
  return svg;
}

// Vertical bars with a reference line (e.g. the equal share F/Z).
export function barChart({ labels, values, ref, refLabel, xLabel, yLabel, title, desc }) {
  const w = 520, h = 240, m = { l: 56, r: 14, t: 14, b: 40 };
  const svg = frame(w, h, title, desc, 'bar-chart');
  const hi = Math.max(1e-12, ...values, ref || 0) * 1.1;
  const xs = scale(0, values.length, m.l, w - m.r), ys = scale(0, hi, h - m.b, m.t);
  axes(svg, m, w, h, xs, ys, [], ticks(0, hi, 5), xLabel, yLabel);
  const g = el('g', { class: 'bars' }, svg);
  const bw = (w - m.l - m.r) / values.length;
  values.forEach((v, i) => {
    const r = el('rect', { x: xs(i) + bw * 0.15, y: ys(v), width: bw * 0.7, height: ys(0) - ys(v), class: 'bar', 'data-value': v }, g);
    el('title', {}, r).textContent = `${labels[i]}: ${fmt(v)}`;
    text(g, xs(i) + bw / 2, h - m.b + 16, labels[i], { 'text-anchor': 'middle' });
  });
  if (typeof ref === 'number') {
    el('line', { x1: m.l, x2: w - m.r, y1: ys(ref), y2: ys(ref), class: 'ref' }, svg);
    text(svg, w - m.r - 4, ys(ref) - 4, refLabel || fmt(ref), { 'text-anchor': 'end', class: 'ref-label' });
  }
  return svg;
}

// points: [{x, y, label, feasible?, best?}]; onSelect(index) on click, Enter or Space (each point
// focusable). Each point keeps its raw x and y (data-x, data-y); a best point gets a ring.
// legend: a legend above the plot (feasible, constraint violated when any point is, best design,
// selected point). minRelSpan: an axis whose points span less than this fraction of their magnitude
// is drawn that wide about their middle instead of being stretched over the whole plot (a 0.0015
// spread of an efficiency of 0.9 is not a large trade-off); the axis label then gives the span, the
// axis group says so (data-span, data-widened) and the returned svg carries svg.spans: {x, y} with
// {lo, hi, span, relative, widened} of the points, for the caller's note.
export function scatter({ points, xLabel, yLabel, title, desc, onSelect, legend = false, minRelSpan = 0 }) {
  const w = 520, h = legend ? 320 : 300, m = { l: 60, r: 16, t: legend ? 34 : 14, b: 40 };
  const svg = frame(w, h, title, desc, 'scatter', 'group');
  const fit = vals => {
    const lo = Math.min(...vals), hi = Math.max(...vals), span = hi - lo, mag = Math.max(Math.abs(lo), Math.abs(hi));
    const relative = mag > 0 ? span / mag : 0;
    const info = { lo, hi, span, relative, widened: false, min: lo, max: hi };
    if (minRelSpan > 0 && mag > 0 && relative < minRelSpan) {
      const mid = (lo + hi) / 2, half = (minRelSpan * mag) / 2;
      Object.assign(info, { widened: true, min: mid - half, max: mid + half });
    } else if (span < 1e-12) Object.assign(info, { min: lo - 1, max: hi + 1 });
    return info;
  };
  const sx = fit(points.map(p => p.x)), sy = fit(points.map(p => p.y));
  svg.spans = { x: sx, y: sy };
  // the x label has the room for the whole note; the rotated y label only for the range
  const spanNote = (s, long) => `range ${fmt(s.span, 2)}${long ? ` (${fmt(100 * s.relative, 2)} %), axis ${fmt(100 * minRelSpan, 2)} % wide` : ', widened'}`;
  const xlo = sx.min, xhi = sx.max, ylo = sy.min, yhi = sy.max;
  const px = 0.06 * (xhi - xlo), py = 0.08 * (yhi - ylo);
  const xs = scale(xlo - px, xhi + px, m.l, w - m.r), ys = scale(ylo - py, yhi + py, h - m.b, m.t);
  axes(svg, m, w, h, xs, ys, ticks(xlo - px, xhi + px, 5), ticks(ylo - py, yhi + py, 5),
    sx.widened ? `${xLabel} — ${spanNote(sx, true)}` : xLabel, sy.widened ? `${yLabel} — ${spanNote(sy, false)}` : yLabel);
  const axisLabels = svg.querySelectorAll('g.axes text.label');
  [[axisLabels[0], sx, 'x'], [axisLabels[1], sy, 'y']].forEach(([t, s, k]) => {
    if (!t) return;
    t.classList.add(`axis-label-${k}`);
    t.dataset.span = String(s.span);
    t.dataset.widened = String(s.widened);
  });
  // the span of a widened axis, marked on the axis itself
  for (const [s, k] of [[sx, 'x'], [sy, 'y']]) {
    if (!s.widened) continue;
    const g = el('g', { class: `span-mark span-${k}` }, svg);
    if (k === 'x') el('line', { x1: xs(s.lo), x2: xs(s.hi), y1: h - m.b - 3, y2: h - m.b - 3 }, g);
    else el('line', { x1: m.l + 3, x2: m.l + 3, y1: ys(s.lo), y2: ys(s.hi) }, g);
  }
  if (legend) {
    const lg = el('g', { class: 'legend', 'data-legend': 'scatter' }, svg);
    const entries = [['feasible', 'feasible', c => el('circle', { cx: c, cy: 12, r: 5, class: 'point-swatch' }, lg)]];
    if (points.some(p => p.feasible === false)) entries.push(['infeasible', 'constraint violated', c => el('circle', { cx: c, cy: 12, r: 5, class: 'point-swatch infeasible' }, lg)]);
    if (points.some(p => p.best)) entries.push(['best', 'best design', c => { el('circle', { cx: c, cy: 12, r: 8, class: 'best-ring' }, lg); el('circle', { cx: c, cy: 12, r: 4, class: 'point-swatch' }, lg); }]);
    entries.push(['selected', 'selected point (its design below)', c => el('circle', { cx: c, cy: 12, r: 5, class: 'point-swatch selected' }, lg)]);
    let lx = m.l;
    for (const [key, label, swatch] of entries) {
      swatch(lx + 9);
      text(lg, lx + 21, 16, label, { 'data-entry': key });
      lx += 36 + 6 * label.length;
    }
  }
  const order = points.map((p, i) => i).sort((a, b) => points[a].x - points[b].x);
  el('polyline', { points: order.map(i => `${xs(points[i].x)},${ys(points[i].y)}`).join(' '), class: 'front' }, svg);
  const g = el('g', { class: 'points' }, svg);
  points.forEach((p, i) => {
    if (p.best) el('circle', { cx: xs(p.x), cy: ys(p.y), r: 10, class: 'best-ring', 'aria-hidden': 'true' }, g);
    const c = el('circle', { cx: xs(p.x), cy: ys(p.y), r: 6, class: `point${p.feasible === false ? ' infeasible' : ''}${p.best ? ' best' : ''}`, tabindex: 0, role: 'button', 'aria-label': p.label, 'data-index': i, 'data-x': p.x, 'data-y': p.y }, g);
    el('title', {}, c).textContent = p.label;
    const pick = () => {
      g.querySelectorAll('.point').forEach(q => { q.classList.remove('selected'); q.setAttribute('aria-pressed', 'false'); });
      c.classList.add('selected');
      c.setAttribute('aria-pressed', 'true');
      if (onSelect) onSelect(i);
    };
    c.setAttribute('aria-pressed', 'false');
    c.addEventListener('click', pick);
    c.addEventListener('keydown', e => { if (e.key === 'Enter' || e.key === ' ') { e.preventDefault(); pick(); } });
  });
  return svg;
}

// Log-scale ticks (1, 2, 5 x 10^k) covering [lo, hi], lo > 0.
function logTicks(lo, hi) {
  const out = [];
  for (let k = Math.floor(Math.log10(lo)); k <= Math.ceil(Math.log10(hi)); k++) {
    for (const m of [1, 2, 5]) {
      const t = m * 10 ** k;
      if (t >= lo * (1 - 1e-9) && t <= hi * (1 + 1e-9)) out.push(Number(t.toPrecision(6)));
    }
  }
  return out.length >= 2 ? out : [lo, hi];
}

// One row per item on a shared log axis: the allowed range [lo, hi] as a band (hi null: open to the
// right), a bar from lo to the value, a tick at `mark` (e.g. the linear allocation) and a dashed tick
// at `ref` (e.g. the reference half-width). items: [{label, value, lo, hi, mark?, ref?, atBound?}].
export function rangeChart({ items, xLabel, title, desc, markLabel, refLabel }) {
  const rowH = 24, w = 680, m = { l: 250, r: 20, t: 26, b: 40 };
  const h = m.t + m.b + rowH * Math.max(1, items.length);
  const svg = frame(w, h, title, desc, 'range-chart');
  const vals = items.flatMap(it => [it.value, it.lo, it.hi, it.mark, it.ref]).filter(v => typeof v === 'number' && v > 0 && Number.isFinite(v));
  let lo = Math.min(...vals), hi = Math.max(...vals);
  if (!(hi > lo)) { lo /= 2; hi *= 2; }
  lo /= 1.25; hi *= 1.25;
  const L = v => Math.log10(Math.max(v, lo));
  const xs0 = scale(L(lo), L(hi), m.l, w - m.r);
  const xs = v => xs0(L(v));
  const xt = logTicks(lo, hi);
  const g = el('g', { class: 'axes' }, svg);
  el('line', { x1: m.l, y1: h - m.b, x2: w - m.r, y2: h - m.b }, g);
  for (const t of xt) {
    el('line', { x1: xs(t), y1: h - m.b, x2: xs(t), y2: h - m.b + 4 }, g);
    el('line', { x1: xs(t), y1: m.t, x2: xs(t), y2: h - m.b, class: 'grid' }, g);
    text(g, xs(t), h - m.b + 16, fmt(t, 3), { 'text-anchor': 'middle' });
  }
  text(g, (m.l + w - m.r) / 2, h - 4, xLabel, { 'text-anchor': 'middle', class: 'label' });
  // legend
  const lg = el('g', { class: 'legend' }, svg);
  el('rect', { x: m.l, y: 6, width: 14, height: 10, class: 'range' }, lg);
  text(lg, m.l + 18, 15, 'bounds');
  el('rect', { x: m.l + 70, y: 8, width: 14, height: 6, class: 'bar' }, lg);
  text(lg, m.l + 88, 15, 'allocated');
  if (markLabel) { el('line', { x1: m.l + 160, x2: m.l + 160, y1: 5, y2: 17, class: 'mark' }, lg); text(lg, m.l + 165, 15, markLabel); }
  if (refLabel) { el('line', { x1: m.l + 255, x2: m.l + 255, y1: 5, y2: 17, class: 'ref-tick' }, lg); text(lg, m.l + 260, 15, refLabel); }
  const rows = el('g', { class: 'bars' }, svg);
  items.forEach((it, i) => {
    const y = m.t + i * rowH, yc = y + rowH / 2;
    text(rows, m.l - 6, y + rowH * 0.66, it.label, { 'text-anchor': 'end', class: 'row-label' });
    const a = typeof it.lo === 'number' && it.lo > 0 ? it.lo : lo;
    const b = typeof it.hi === 'number' ? it.hi : hi;
    el('rect', { x: xs(a), y: y + 3, width: Math.max(0.5, xs(b) - xs(a)), height: rowH - 6, class: typeof it.hi === 'number' ? 'range' : 'range open' }, rows);
    const r = el('rect', { x: xs(a), y: yc - 4, width: Math.max(1, xs(it.value) - xs(a)), height: 8, class: `bar${it.atBound ? ' at-bound' : ''}`, 'data-value': it.value, 'data-label': it.label }, rows);
    el('title', {}, r).textContent = `${it.label}: ${fmt(it.value)} (bounds ${fmt(it.lo)} to ${typeof it.hi === 'number' ? fmt(it.hi) : 'none'}${it.atBound ? `, at the ${it.atBound} bound` : ''})`;
    el('circle', { cx: xs(it.value), cy: yc, r: 3.5, class: 'end' }, rows);
    if (typeof it.mark === 'number') el('line', { x1: xs(it.mark), x2: xs(it.mark), y1: y + 2, y2: y + rowH - 2, class: 'mark' }, rows);
    if (typeof it.ref === 'number') el('line', { x1: xs(it.ref), x2: xs(it.ref), y1: y + 2, y2: y + rowH - 2, class: 'ref-tick' }, rows);
  });
  return svg;
}

// Points with 95 % whiskers over a category axis (e.g. correction steps) and a target line.
// points: [{label, y, lo?, hi?, highlight?, title?}]; values and target in the plotted unit.
export function intervalChart({ points, target, targetLabel, xLabel, yLabel, title, desc }) {
  const w = 520, h = 260, m = { l: 60, r: 16, t: 14, b: 46 };
  const svg = frame(w, h, title, desc, 'interval-chart');
  const vals = points.flatMap(p => [p.y, p.lo, p.hi]).concat(typeof target === 'number' ? [target] : []).filter(v => typeof v === 'number' && Number.isFinite(v));
  let ylo = Math.min(...vals), yhi = Math.max(...vals);
  if (yhi - ylo < 1e-12) { ylo -= 1; yhi += 1; }
  const pad = 0.1 * (yhi - ylo);
  const xs = scale(-0.5, points.length - 0.5, m.l, w - m.r), ys = scale(ylo - pad, yhi + pad, h - m.b, m.t);
  axes(svg, m, w, h, xs, ys, [], ticks(ylo - pad, yhi + pad, 5), xLabel, yLabel);
  if (typeof target === 'number') {
    el('line', { x1: m.l, x2: w - m.r, y1: ys(target), y2: ys(target), class: 'ref', 'data-value': target }, svg);
    text(svg, m.l + 4, ys(target) - 4, targetLabel || fmt(target), { 'text-anchor': 'start', class: 'ref-label' });
  }
  const g = el('g', { class: 'points' }, svg);
  points.forEach((p, i) => {
    const x = xs(i);
    text(g, x, h - m.b + 16, p.label, { 'text-anchor': 'middle' });
    if (typeof p.lo === 'number' && typeof p.hi === 'number') {
      el('line', { x1: x, x2: x, y1: ys(p.lo), y2: ys(p.hi), class: 'whisker' }, g);
      el('line', { x1: x - 4, x2: x + 4, y1: ys(p.lo), y2: ys(p.lo), class: 'whisker' }, g);
      el('line', { x1: x - 4, x2: x + 4, y1: ys(p.hi), y2: ys(p.hi), class: 'whisker' }, g);
    }
    if (typeof p.y !== 'number') return;
    const c = el('circle', { cx: x, cy: ys(p.y), r: p.highlight ? 6 : 4.5, class: `marker${p.highlight ? ' highlight' : ''}`, 'data-value': p.y }, g);
    el('title', {}, c).textContent = p.title || `${p.label}: ${fmt(p.y)}`;
  });
  return svg;
}

// Keeps the shape of a long run of points for a plot `px` pixels wide: per pixel column its first,
// lowest, highest and last point (in order), so that no peak is lost. idx: the run's indices.
function envelope(idx, x, y, x0, x1, px) {
  if (idx.length <= 4 * px) return idx;
  const out = [];
  let col = -1, first, lo, hi, last;
  const flush = () => { if (col >= 0) for (const i of [...new Set([first, lo, hi, last])].sort((a, b) => a - b)) out.push(i); };
  for (const i of idx) {
    const c = Math.min(px - 1, Math.floor(((x[i] - x0) / (x1 - x0 || 1)) * px));
    if (c !== col) { flush(); col = c; first = lo = hi = last = i; continue; }
    if (y[i] < y[lo]) lo = i;
    if (y[i] > y[hi]) hi = i;
    last = i;
  }
  flush();
  return out;
}

// Curves y(x) over a shared x axis (a time series): one per series, broken where a value is null
// (not defined then), each series' settled value as a dashed line of its colour labelled in the
// right margin, optional marks (small circles with a tooltip) and a legend above the plot.
// series: [{key, label, y, cls}] with cls one of s0..s5 (the colours of app.css); refs: [{key, value,
// label, cls}]; marks: [{x, y, cls, label}]. Each curve is a <path class="series"> with data-series
// (its key) and data-points (how many values it has); each reference line a <line class="ref-line">
// with data-series and data-value. Long series are thinned to their envelope per pixel column.
export function seriesChart({ x, series, refs = [], marks = [], xLabel, yLabel, title, desc, refNote = 'settled' }) {
  const w = 600, h = 290, m = { l: 66, r: 70, t: 30, b: 40 };
  const svg = frame(w, h, title, desc, 'series-chart');
  const finite = v => typeof v === 'number' && Number.isFinite(v);
  const n = x.length;
  const x0 = n ? x[0] : 0, x1 = n > 1 ? x[n - 1] : x0 + 1;
  let ylo = Infinity, yhi = -Infinity; // a loop: a spread of 10^5 values would overflow the call stack
  for (const v of series.flatMap(s => s.y).concat(refs.map(r => r.value))) if (finite(v)) { if (v < ylo) ylo = v; if (v > yhi) yhi = v; }
  if (ylo > yhi) { ylo = 0; yhi = 1; }
  if (yhi - ylo < 1e-9 * Math.max(1, Math.abs(yhi))) { const d = Math.max(Math.abs(yhi) * 0.05, 1e-9); ylo -= d; yhi += d; }
  const pad = 0.08 * (yhi - ylo);
  ylo -= pad; yhi += pad;
  const xs = scale(x0, x1, m.l, w - m.r), ys = scale(ylo, yhi, h - m.b, m.t);
  axes(svg, m, w, h, xs, ys, ticks(x0, x1, 6), ticks(ylo, yhi, 5), xLabel, yLabel);
  if (ylo < 0 && yhi > 0) el('line', { x1: m.l, x2: w - m.r, y1: ys(0), y2: ys(0), class: 'zero' }, svg);

  // legend: one entry per series, then the reference lines' meaning
  const lg = el('g', { class: 'legend' }, svg);
  let lx = m.l;
  for (const s of series) {
    el('line', { x1: lx, x2: lx + 18, y1: 12, y2: 12, class: `swatch ${s.cls}` }, lg);
    text(lg, lx + 22, 16, s.label);
    lx += 30 + 6.2 * s.label.length;
  }
  if (refs.length) {
    el('line', { x1: lx, x2: lx + 18, y1: 12, y2: 12, class: 'swatch ref-swatch' }, lg);
    text(lg, lx + 22, 16, refNote);
  }

  const curves = el('g', { class: 'curves' }, svg);
  const px = Math.round(w - m.l - m.r);
  for (const s of series) {
    // runs of defined values, each thinned to its envelope
    let d = '', run = [];
    const draw = () => {
      if (!run.length) return;
      const keep = envelope(run, x, s.y, x0, x1, px);
      d += keep.map((i, j) => `${j ? 'L' : 'M'}${xs(x[i]).toFixed(2)},${ys(s.y[i]).toFixed(2)}`).join('');
      if (keep.length === 1) d += `h0.01`; // a lone point still shows (round caps)
      run = [];
    };
    for (let i = 0; i < n; i++) { if (finite(s.y[i])) run.push(i); else draw(); }
    draw();
    el('path', { d, class: `series ${s.cls}`, 'data-series': s.key, 'data-points': s.y.length, 'data-label': s.label }, curves);
  }

  // reference lines; their labels in the right margin, nudged apart when they would overlap
  const rg = el('g', { class: 'refs' }, svg);
  const placed = refs.filter(r => finite(r.value)).map(r => ({ r, y: ys(r.value) }));
  const byHeight = placed.slice().sort((a, b) => a.y - b.y);
  byHeight.forEach((p, i) => { p.ly = i ? Math.max(p.y, byHeight[i - 1].ly + 12) : p.y; });
  for (const p of placed) { // in the caller's order
    const line = el('line', { x1: m.l, x2: w - m.r, y1: p.y, y2: p.y, class: `ref-line ${p.r.cls}`, 'data-series': p.r.key, 'data-value': p.r.value }, rg);
    el('title', {}, line).textContent = p.r.label;
    const t = text(rg, w - m.r + 4, p.ly + 4, fmt(p.r.value), { class: `ref-text ${p.r.cls}` });
    el('title', {}, t).textContent = p.r.label;
  }
  const mg = el('g', { class: 'marks' }, svg);
  for (const k of marks) {
    if (!finite(k.x) || !finite(k.y)) continue;
    const c = el('circle', { cx: xs(k.x), cy: ys(k.y), r: 3.5, class: `mark-dot ${k.cls}` }, mg);
    el('title', {}, c).textContent = k.label;
  }
  return svg;
}

// ---- x-y charts of the vibration analyses (bifurcation diagrams, Poincaré sections, phase
// portraits, spectra, frequency responses) and a cell map (basins of attraction) ----------------
// The colours of app.css's s0..s5, for filled markers.
export const PALETTE = ['#1f5fbf', '#b4470f', '#1b7a3a', '#6b3fa0', '#0e7c86', '#7a5a00'];
const MARKERS = {
  circle: (x, y, r) => `M${(x - r).toFixed(1)},${y.toFixed(1)}a${r},${r} 0 1,0 ${2 * r},0a${r},${r} 0 1,0 ${-2 * r},0`,
  square: (x, y, r) => `M${(x - r).toFixed(1)},${(y - r).toFixed(1)}h${2 * r}v${2 * r}h${-2 * r}z`,
  triangle: (x, y, r) => `M${x.toFixed(1)},${(y - 1.2 * r).toFixed(1)}l${1.1 * r},${2 * r}h${-2.2 * r}z`,
  diamond: (x, y, r) => `M${x.toFixed(1)},${(y - 1.3 * r).toFixed(1)}l${1.3 * r},${1.3 * r}l${-1.3 * r},${1.3 * r}l${-1.3 * r},${-1.3 * r}z`,
};

// a marker series' fill (or, hollow, its outline) in its colour
const paint = s => { const c = PALETTE[Number((s.cls || 's0').slice(1)) % 6]; return s.hollow ? { fill: 'none', stroke: c, 'stroke-width': 1.2 } : { fill: c, stroke: 'none' }; };

// series: [{key, label, cls (s0..s5), kind: 'line' | 'points', x, y, marker?, size?, dash?, data?}]:
// a line is broken at non-finite values and thinned to distinct half pixels; points are drawn once
// per distinct pixel as one <path class="xy-points"> with data-points (the values given) and
// data-drawn (the distinct pixels). stems: [{x, y, label, cls?}] vertical lines from the axis to y
// with a label above (labels of stems within 6 px merged). marks: [{x, y, label, cls, marker}]
// single labelled markers. logX, logY: log axes (non-positive values left out).
export function xyChart({ series = [], stems = [], marks = [], xLabel, yLabel, title, desc, logX = false, logY = false,
  xRange, yRange, w = 600, h = 320, legend = true, cls = 'xy-chart' }) {
  const m = { l: 66, r: 20, t: legend ? 34 : 16, b: 40 };
  const short = s => (s.length > 30 ? `${s.slice(0, 29)}…` : s);
  const stemText = g => short([...new Set(g.map(s => s.label))].join(', '));
  if (stems.length) { m.t += 14 + 6.8 * Math.max(...stems.map(s => Math.min(30, s.label.length))); h += m.t - 34; }
  const svg = frame(w, h, title, desc, cls);
  const ok = (v, log) => typeof v === 'number' && Number.isFinite(v) && (!log || v > 0);
  const range = (vals, log, given) => {
    if (given) return given.slice();
    let lo = Infinity, hi = -Infinity;
    for (const v of vals) if (ok(v, log)) { if (v < lo) lo = v; if (v > hi) hi = v; }
    if (lo > hi) return log ? [1, 10] : [0, 1];
    if (log) { if (hi / lo < 1.01) { lo /= 2; hi *= 2; } return [lo / 1.3, hi * 1.3]; }
    if (hi - lo < 1e-12 * Math.max(1, Math.abs(hi))) { const d = Math.max(Math.abs(hi) * 0.05, 1e-9); lo -= d; hi += d; }
    const pad = 0.06 * (hi - lo);
    return [lo - pad, hi + pad];
  };
  const [x0, x1] = range(series.flatMap(s => s.x).concat(stems.map(s => s.x), marks.map(k => k.x)), logX, xRange);
  const [y0, y1] = range(series.flatMap(s => s.y).concat(stems.map(s => s.y), marks.map(k => k.y)), logY, yRange);
  const fx = logX ? Math.log10 : v => v, fy = logY ? Math.log10 : v => v;
  const sx0 = scale(fx(x0), fx(x1), m.l, w - m.r), sy0 = scale(fy(y0), fy(y1), h - m.b, m.t);
  const xs = v => sx0(fx(v)), ys = v => sy0(fy(v));
  const inside = (x, y) => ok(x, logX) && ok(y, logY) && x >= x0 && x <= x1 && y >= y0 && y <= y1;
  const lt = (a, b) => { const t = logTicks(a, b); if (b / a < 1e3) return t; const dec = t.filter(v => Math.abs(Math.log10(v) - Math.round(Math.log10(v))) < 1e-9); return dec.length >= 2 ? dec : t; };
  const xt = logX ? lt(x0, x1) : ticks(x0, x1, 6), yt = logY ? lt(y0, y1) : ticks(y0, y1, 5);
  const thin = (list, n) => (list.length > n ? list.filter((t, i) => i % Math.ceil(list.length / n) === 0) : list);
  axes(svg, m, w, h, xs, ys, thin(xt, 9), thin(yt, 7), xLabel, yLabel);
  if (logX || logY) svg.querySelectorAll('g.axes text:not(.label)').forEach(t => { const v = Number(t.textContent.replace('−', '-')); if (Number.isFinite(v)) t.textContent = fmt(v, 3); });
  const clip = `clip${++uid}`;
  el('rect', { x: m.l, y: m.t, width: w - m.l - m.r, height: h - m.t - m.b }, el('clipPath', { id: clip }, el('defs', {}, svg)));
  const body = el('g', { 'clip-path': `url(#${clip})` }, svg);
  if (legend) {
    const lg = el('g', { class: 'legend' }, svg);
    let lx = m.l;
    for (const s of series.filter(q => q.label)) {
      if (s.kind === 'points') el('path', { d: MARKERS[s.marker || 'circle'](lx + 9, 12, 4), ...paint(s), class: `swatch-marker${s.hollow ? ' hollow' : ''}` }, lg);
      else el('line', { x1: lx, x2: lx + 18, y1: 12, y2: 12, class: `swatch ${s.cls}${s.dash ? ' dashed' : ''}` }, lg);
      text(lg, lx + 22, 16, s.label);
      lx += 30 + 6.2 * s.label.length;
    }
  }
  for (const s of series) {
    const attrs = { 'data-series': s.key, 'data-label': s.label, ...(s.data || {}) };
    if (s.kind === 'points') {
      const seen = new Set();
      let d = '';
      const r = s.size || 2.6;
      const shape = MARKERS[s.marker || 'circle'];
      for (let i = 0; i < s.x.length; i++) {
        if (!inside(s.x[i], s.y[i])) continue;
        const px = xs(s.x[i]), py = ys(s.y[i]);
        const k = `${Math.round(px * 2)},${Math.round(py * 2)}`;
        if (seen.has(k)) continue;
        seen.add(k);
        d += shape(px, py, r);
      }
      el('path', { d: d || 'M0,0', class: `xy-points${s.hollow ? ' hollow' : ''}`, ...paint(s), 'data-points': s.x.length, 'data-drawn': seen.size, ...attrs }, body);
    } else {
      let d = '', pen = false, lastK = '';
      for (let i = 0; i < s.x.length; i++) {
        if (!ok(s.x[i], logX) || !ok(s.y[i], logY)) { pen = false; continue; }
        const px = xs(s.x[i]), py = ys(s.y[i]);
        const k = `${Math.round(px * 2)},${Math.round(py * 2)}`;
        if (pen && k === lastK) continue;
        d += `${pen ? 'L' : 'M'}${px.toFixed(1)},${py.toFixed(1)}`;
        pen = true; lastK = k;
      }
      el('path', { d: d || 'M0,0', class: `series xy-line ${s.cls}${s.dash ? ' dashed' : ''}`, 'data-points': s.x.length, ...attrs }, body);
    }
  }
  // stems with their labels (merged when closer than 6 px), in a band above the plot
  const sg = el('g', { class: 'stems' }, svg);
  const placed = stems.filter(s => ok(s.x, logX) && s.x >= x0 && s.x <= x1).map(s => ({ ...s, px: xs(s.x) })).sort((a, b) => a.px - b.px);
  const groups = [];
  for (const s of placed) {
    const g = groups[groups.length - 1];
    if (g && s.px - g.px < 12) g.items.push(s); else groups.push({ px: s.px, items: [s] });
  }
  for (const g of groups) {
    for (const s of g.items) {
      const yTop = ok(s.y, logY) ? Math.max(m.t, Math.min(h - m.b, ys(s.y))) : h - m.b;
      const line = el('line', { x1: s.px, x2: s.px, y1: h - m.b, y2: yTop, class: `stem ${s.cls || ''}`, 'data-name': s.name || s.label, 'data-value': s.y }, sg);
      el('title', {}, line).textContent = s.title || s.label;
      if (ok(s.y, logY) && s.y >= y0) el('circle', { cx: s.px, cy: yTop, r: 3, class: 'stem-head', 'data-name': s.name || s.label }, sg);
      el('line', { x1: s.px, x2: s.px, y1: m.t, y2: yTop, class: 'stem-guide' }, sg);
    }
    const t = text(sg, g.px + 4, m.t - 4, stemText(g.items), { class: 'stem-label', transform: `rotate(-90 ${g.px + 4} ${m.t - 4})`, 'data-names': g.items.map(s => s.name || s.label).join(' ') });
    el('title', {}, t).textContent = g.items.map(s => s.title || s.label).join('; ');
  }
  const mg = el('g', { class: 'xy-marks' }, svg);
  for (const k of marks) {
    if (!inside(k.x, k.y)) continue;
    const p = el('path', { d: MARKERS[k.marker || 'diamond'](xs(k.x), ys(k.y), k.size || 5), class: `xy-mark ${k.cls || ''}`, 'data-kind': k.kind || '', 'data-x': k.x, 'data-y': k.y }, mg);
    el('title', {}, p).textContent = k.label;
    if (k.text) text(mg, xs(k.x) + 7, ys(k.y) - 7, k.text, { class: 'mark-text' });
  }
  return svg;
}

// A grid of cells coloured by label (e.g. the attractor each initial state goes to). x, y: the
// cell centres; labels[i][j] for y[i], x[j] (or the transpose: labels[j][i] with byColumn) ; keys:
// [{label, name, color}] in legend order, labels not listed drawn grey ("other").
export function cellMap({ x, y, labels, byColumn = false, keys, xLabel, yLabel, title, desc, marks = [] }) {
  const w = 640, h = 420, m = { l: 60, r: 250, t: 16, b: 42 };
  const svg = frame(w, h, title, desc, 'cell-map');
  const dx = x.length > 1 ? (x[x.length - 1] - x[0]) / (x.length - 1) : 1, dy = y.length > 1 ? (y[y.length - 1] - y[0]) / (y.length - 1) : 1;
  const xa = x[0] - dx / 2, xb = x[x.length - 1] + dx / 2, ya = y[0] - dy / 2, yb = y[y.length - 1] + dy / 2;
  const xs = scale(xa, xb, m.l, w - m.r), ys = scale(ya, yb, h - m.b, m.t);
  const colour = new Map(keys.map(k => [k.label, k.color]));
  const g = el('g', { class: 'cells' }, svg);
  const counts = new Map();
  for (let i = 0; i < y.length; i++) {
    for (let j = 0; j < x.length; j++) {
      const lab = byColumn ? labels[j][i] : labels[i][j];
      counts.set(lab, (counts.get(lab) || 0) + 1);
      el('rect', { x: xs(x[j] - dx / 2), y: ys(y[i] + dy / 2), width: xs(x[j] + dx / 2) - xs(x[j] - dx / 2) + 0.3, height: ys(y[i] - dy / 2) - ys(y[i] + dy / 2) + 0.3,
        fill: colour.get(lab) || '#b9bec6', class: 'cell', 'data-label': lab }, g);
    }
  }
  axes(svg, m, w, h, xs, ys, ticks(xa, xb, 6), ticks(ya, yb, 6), xLabel, yLabel);
  svg.querySelectorAll('g.axes line.grid').forEach(l => l.remove());
  const mg = el('g', { class: 'xy-marks' }, svg);
  for (const k of marks) {
    if (!(k.x >= xa && k.x <= xb && k.y >= ya && k.y <= yb)) continue;
    const p = el('path', { d: MARKERS.diamond(xs(k.x), ys(k.y), 6), class: 'xy-mark attractor-mark', style: `fill: ${k.color || '#fff'}` }, mg);
    el('title', {}, p).textContent = k.label;
    if (k.text) text(mg, xs(k.x) + 8, ys(k.y) + 4, k.text, { class: 'attractor-text' });
  }
  const lg = el('g', { class: 'legend cell-legend' }, svg);
  keys.forEach((k, i) => {
    el('rect', { x: w - m.r + 12, y: m.t + i * 20, width: 14, height: 14, fill: k.color, class: 'cell-key', 'data-label': k.label }, lg);
    text(lg, w - m.r + 31, m.t + i * 20 + 11, `${k.name}: ${counts.get(k.label) || 0} cells`);
  });
  return svg;
}
