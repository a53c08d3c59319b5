// The page: examples, the study form with live derived values, submit, the job view with progress
// and cancel, and the results; the optimisation, allocation, simulation and calibration views when
// the service has them (optimization.js, allocation.js, simulation.js, calibration.js), run through the same job view. Uses only
// prsm serve's API (same origin).

import { api, ApiError, describe, getToken, setToken } from './api.js';
import { StudyForm, schemaInfo } from './form.js';
import { renderStudyResult } from './results.js';
import { fmt } from './plots.js';
import { setupOptimization } from './optimization.js';
import { setupAllocation } from './allocation.js';
import { setupSimulation } from './simulation.js';
import { setupCalibration } from './calibration.js';
import { setupImport } from './importdoc.js';

const $ = sel => document.querySelector(sel);
const REQUESTS_KEY = 'prsm.requests';

// ---- requests remembered by job id (for replaying samples after a reload) ------------------
function rememberRequest(id, doc) {
  try {
    const all = JSON.parse(localStorage.getItem(REQUESTS_KEY) || '{}');
    all[id] = { t: Date.now(), doc };
    const ids = Object.keys(all).sort((a, b) => all[b].t - all[a].t);
    for (const old of ids.slice(20)) delete all[old];
    localStorage.setItem(REQUESTS_KEY, JSON.stringify(all));
  } catch { /* storage full or off: the replay then says it lacks the request */ }
}
function recalledRequest(id) {
  try { return (JSON.parse(localStorage.getItem(REQUESTS_KEY) || '{}')[id] || {}).doc; } catch { return undefined; }
}

function duration(s) {
  if (s === null || s === undefined) return '—';
  if (s < 60) return `${Math.round(s)} s`;
  const m = Math.floor(s / 60);
  return m < 60 ? `${m} min ${Math.round(s - 60 * m)} s` : `${Math.floor(m / 60)} h ${m % 60} min`;
}
const count = n => (typeof n === 'number' ? n.toLocaleString('en-US') : '—');
const simulated = ns => (typeof ns === 'number' && ns > 0 ? `${fmt(ns * 1e-9, 6)} s` : typeof ns === 'number' ? '0 s' : '—');

// A job's name: the request's own name (a study's, an optimisation's ...), else the name its
// result echoes, else the name of the design it is about; '' when none is known.
function nameOf(doc, result) {
  const str = v => (typeof v === 'string' && v.trim() ? v.trim() : '');
  const d = doc && typeof doc === 'object' ? doc : {};
  return str(d.name) || str(result && result.name) || str(d.design && d.design.name) || str(d.study && d.study.name)
    || str(d.study && d.study.design && d.study.design.name);
}

// ---- derived values (POST /v1/designs/analyze, debounced) ---------------------------------
function derivedView(form) {
  const list = $('#derived-list'), status = $('#derived-status'), warn = $('#derived-warnings');
  let timer = null, controller = null, seq = 0;
  const row = (key, label, value, unit = '') => {
    const dt = document.createElement('dt');
    dt.textContent = label;
    const dd = document.createElement('dd');
    dd.dataset.key = key;
    if (typeof value === 'number') dd.dataset.value = String(value);
    dd.textContent = typeof value === 'number' ? `${fmt(value)}${unit ? ` ${unit}` : ''}` : value === undefined || value === null ? '—' : String(value);
    list.append(dt, dd);
  };
  const show = a => {
    list.textContent = '';
    const g = a.geometry || {}, dg = (a.design && a.design.geometry) || {};
    row('screw_radius_mm', 'Screw radius r_s', dg.screw_radius_mm, 'mm');
    row('nut_radius_mm', 'Nut radius r_n', dg.nut_radius_mm, 'mm');
    row('lead_mm', 'Lead', g.lead_mm, 'mm');
    row('helix_angle_screw_deg', 'Helix angle, screw', g.helix_angle_screw_deg, '°');
    row('helix_angle_roller_deg', 'Helix angle, roller', g.helix_angle_roller_deg, '°');
    row('helix_angle_nut_deg', 'Helix angle, nut', g.helix_angle_nut_deg, '°');
    row('z_max', 'Z_max (rollers that fit)', g.z_max);
    row('orbit_radius_mm', 'Roller orbit radius', g.orbit_radius_mm, 'mm');
    row('ring_gear_ratio', 'Ring-gear ratio', g.ring_gear_ratio);
    row('standard_rules', 'Standard rules', g.standard_rules === undefined ? undefined : g.standard_rules ? 'yes' : 'no');
    row('backlash_um', 'Nominal backlash', a.backlash_um, 'µm');
    if (a.efficiency) row('eta', 'Efficiency η (forward)', a.efficiency.eta);
    if (a.stiffness) row('stiffness', 'Axial stiffness', a.stiffness.axial_N_per_um, 'N/µm');
    if (a.hertz && a.hertz.screw_roller) row('p_max', 'p_max screw side (equal share)', a.hertz.screw_roller.p_max_MPa, 'MPa');
    if (a.capacity && a.capacity.dynamic) row('C_a', 'Dynamic rating C_a', a.capacity.dynamic.C_a_N, 'N');
    if (a.capacity && a.capacity.static) {
      const st = a.capacity.static;
      row('C0a', 'Static rating C_0a', st.C0a_N, 'N');
      // C_0a / F, dimensionless; null without an axial load
      row('static_safety', 'Static safety C_0a / F (–)', st.safety_factor === null ? 'no load' : st.safety_factor);
    }
    if (a.efficiency && a.efficiency.torque_Nm) {
      const tq = a.efficiency.torque_Nm;
      // null when friction locks the drive (efficiency.drive_locked)
      row('input_torque_Nm', 'Input torque (screw)', tq.input === null ? 'none: the drive locks' : tq.input, 'N·m');
    }
    if (a.efficiency && 'back_driving_output_torque_Nm' in a.efficiency) {
      const b = a.efficiency.back_driving_output_torque_Nm;
      row('back_driving_torque_Nm', 'Back-driving torque (screw)', b === null ? '—' : b, 'N·m');
    }
    if (a.life) row('L10_h', 'L10 life', a.life.hours, 'h');
    warn.textContent = '';
    const ws = a.warnings || [];
    if (ws.length) {
      const h = document.createElement('h3');
      h.className = 'h4';
      h.textContent = `Warnings (${ws.length})`;
      const ul = document.createElement('ul');
      ul.className = 'warnings';
      ul.id = 'derived-warning-list';
      for (const w of ws) {
        const li = document.createElement('li');
        li.textContent = `${w.pointer ? `${w.pointer}: ` : ''}${w.message}`;
        ul.appendChild(li);
      }
      warn.append(h, ul);
    }
    form.showProblems(ws, { prefix: '/design', source: 'analyze', kind: 'warning' });
  };
  const run = async () => {
    const my = ++seq;
    if (controller) controller.abort();
    controller = new AbortController();
    status.textContent = 'Analysing…';
    try {
      const a = await api.analyze(form.designDoc(), controller.signal);
      if (my !== seq) return;
      form.clearProblems('analyze');
      show(a);
      list.classList.remove('stale');
      status.textContent = `Design analysed${a.warnings && a.warnings.length ? `, ${a.warnings.length} warning${a.warnings.length > 1 ? 's' : ''}` : ''}.`;
    } catch (e) {
      if (e.name === 'AbortError' || my !== seq) return;
      form.clearProblems('analyze');
      list.classList.add('stale');
      warn.textContent = '';
      if (e instanceof ApiError && e.unauthorized) {
        status.textContent = `No analysis: ${describe(e)}`;
      } else if (e instanceof ApiError && e.errors.length) {
        const placed = form.showProblems(e.errors, { prefix: '/design', source: 'analyze' });
        status.textContent = `The design is invalid: ${placed.map(p => `${p.pointer}: ${p.message}`).join('; ')}`;
      } else {
        status.textContent = `No analysis: ${describe(e)}`;
      }
    }
  };
  return { schedule() { clearTimeout(timer); timer = setTimeout(run, 350); }, now: run };
}

// ---- the API token (sessionStorage only; see api.js) ------------------------------------------
// A 401 anywhere marks the field and says what to do next to it; typing a token clears that and
// calls onChange (the derived values are analysed again: the analysis is a POST too).
function tokenField(onChange) {
  const input = $('#api-token'), msg = $('#api-token-msg');
  input.value = getToken();
  const clear = () => {
    msg.hidden = true;
    msg.textContent = '';
    input.removeAttribute('aria-invalid');
    input.setAttribute('aria-describedby', 'api-token-hint');
  };
  let timer = null;
  input.addEventListener('input', () => {
    setToken(input.value);
    clear();
    clearTimeout(timer);
    timer = setTimeout(onChange, 300);
  });
  window.addEventListener('prsm:unauthorized', e => {
    const text = e.detail && e.detail.sent ? 'The service refused this token (401): check it.'
      : 'This service needs an API token for POST and DELETE (401): enter it here.';
    if (msg.textContent !== text) msg.textContent = text;
    msg.hidden = false;
    input.setAttribute('aria-invalid', 'true');
    input.setAttribute('aria-describedby', 'api-token-hint api-token-msg');
  });
  return input;
}

// ---- error summary -------------------------------------------------------------------------
function showSummary(placed, headline) {
  const box = $('#error-summary');
  box.textContent = '';
  const h = document.createElement('h3');
  h.className = 'h4';
  h.textContent = headline;
  box.appendChild(h);
  const ul = document.createElement('ul');
  for (const p of placed) {
    const li = document.createElement('li');
    const text = `${p.pointer ? `${p.pointer}: ` : ''}${p.message}`;
    const field = p.element && (/^(INPUT|SELECT)$/.test(p.element.tagName) ? p.element : p.element.querySelector('input, select'));
    if (field) {
      const a = document.createElement('a');
      a.href = '#';
      a.textContent = text;
      a.addEventListener('click', e => { e.preventDefault(); field.focus(); });
      li.appendChild(a);
    } else li.textContent = text;
    ul.appendChild(li);
  }
  box.appendChild(ul);
  box.hidden = false;
  box.focus();
}

// ---- the job view ----------------------------------------------------------------------------
class JobView {
  constructor(onRecent) {
    this.section = $('#job');
    this.timer = null;
    this.path = null;
    this.onRecent = onRecent;
    this.lastAnnounced = '';
    this.renderers = {}; // collection -> (container, job) for the kinds other than studies
    // the job and results sections follow the view whose request they run
    this.anchors = { studies: $('#study-layout'), optimizations: $('#optimization'), allocations: $('#allocation'), simulations: $('#simulation'), calibrations: $('#calibration') };
    $('#job-cancel').addEventListener('click', () => this.cancel());
  }

  announce(text) {
    if (text !== this.lastAnnounced) $('#job-status').textContent = text;
    this.lastAnnounced = text;
  }

  place(collection) {
    const anchor = this.anchors[collection];
    if (anchor && anchor.nextElementSibling !== this.section) anchor.after(this.section, $('#results'));
  }

  async open(path, study, collection = 'studies') {
    clearTimeout(this.timer);
    this.path = path;
    this.study = study;
    this.collection = collection;
    this.place(collection);
    this.section.hidden = false;
    $('#job-problem').hidden = true;
    $('#job-cancel-msg').hidden = true;
    $('#results').hidden = true;
    $('#job-link').href = path;
    $('#job-link').textContent = path.split('/').pop();
    this.showName();
    $('#job-state').textContent = '—';
    delete $('#job-state').dataset.state;
    $('#job-best-row').hidden = true;
    this.announce('Loading the job…');
    await this.poll();
  }

  async poll() {
    const path = this.path;
    let job;
    try {
      job = await api.job(path);
    } catch (e) {
      if (path !== this.path) return;
      this.announce(`Cannot read the job: ${describe(e)}`);
      if (!(e instanceof ApiError) || e.status === 0 || e.status >= 500) this.timer = setTimeout(() => this.poll(), 2000);
      return;
    }
    if (path !== this.path) return;
    this.render(job);
    if (job.state === 'queued' || job.state === 'running') this.timer = setTimeout(() => this.poll(), 500);
    else { this.finish(job); this.awaitBestSoFar(job); }
  }

  // A cancelled optimisation or allocation hands back its best result so far once its worker has
  // stopped, a moment after the DELETE: look again a few times. (A cancelled study or simulation
  // has none.)
  awaitBestSoFar(job, tries = 20) {
    const path = this.path;
    if (job.state !== 'cancelled' || job.result || this.collection === 'studies' || this.collection === 'simulations' || tries <= 0) return;
    this.timer = setTimeout(async () => {
      let again;
      try { again = await api.job(path); } catch { return; }
      if (path !== this.path) return;
      if (again.result) { this.render(again); this.finish(again); } else this.awaitBestSoFar(again, tries - 1);
    }, 250);
  }

  showName(result) {
    const name = nameOf(this.study, result);
    $('#job-name').textContent = name || `unnamed ${KIND_NAMES[this.collection] || 'job'}`;
    $('#job-name').dataset.name = name;
    return name;
  }

  render(job) {
    this.showName(job.result);
    const p = job.progress || {};
    const bar = $('#job-progress');
    if (typeof p.fraction === 'number') bar.value = Math.min(1, Math.max(0, p.fraction));
    else if (job.state === 'done') bar.value = 1;
    else bar.removeAttribute('value'); // indeterminate while queued
    const pct = typeof p.fraction === 'number' ? `${(100 * p.fraction).toFixed(1)} %` : '';
    const unit = p.unit || 'samples';
    $('#job-state').textContent = job.state;
    $('#job-state').dataset.state = job.state;
    const unitLabel = {evaluations: 'Evaluations', simulated_ns: 'Simulated time', sweep_points: 'Sweep points',
      basin_cells: 'Basin cells', analyses: 'Analyses'}[unit] || 'Samples';
    const phaseLabel = {monte_carlo: 'Monte Carlo run', summary: 'summaries, SRC and stack',
      rare_events: 'rare-event estimates', sobol: 'Sobol indices (Saltelli run)'}[p.phase];
    $('#job-unit').textContent = phaseLabel ? `${unitLabel} — ${phaseLabel}` : unitLabel;
    $('#job-unit').dataset.phase = p.phase || '';
    $('#job-samples').textContent = unit === 'simulated_ns' // nanoseconds of simulated time, shown in s
      ? `${simulated(p.samples_done)} of ${simulated(p.samples_planned)}${pct ? ` (${pct})` : ''}`
      : `${count(p.samples_done)} of ${count(p.samples_planned)}${pct ? ` (${pct})` : ''}`;
    $('#job-interval').parentElement.hidden = unit === 'simulated_ns'; // no stop targets
    const w = p.interval_width, goal = p.interval_goal;
    const iv = $('#job-interval');
    iv.textContent = typeof w === 'number' ? `${fmt(w)}${typeof goal === 'number' ? ` (goal ${fmt(goal)})` : ''}` : job.state === 'running' ? '— (no target, or too few samples yet)' : '—';
    if (typeof w === 'number') iv.dataset.value = String(w); else delete iv.dataset.value;
    $('#job-best-row').hidden = typeof p.best_objective !== 'number';
    $('#job-best-label').textContent = this.collection === 'allocations' ? 'Least cost so far (meeting every target)' : 'Best objective so far';
    $('#job-best').textContent = fmt(p.best_objective);
    $('#job-eta').textContent = job.state === 'running' ? duration(p.eta_s) : '—';
    $('#job-cancel').disabled = !(job.state === 'queued' || job.state === 'running');
    const step = typeof p.fraction === 'number' ? Math.floor(p.fraction * 4) * 25 : -1;
    this.announce(job.state === 'running' ? (step > 0 ? `Running: ${step} % done.` : 'Running.') : job.state === 'queued' ? 'Queued: waiting for a worker.' : this.lastAnnounced);
  }

  finish(job) {
    this.onRecent();
    if (job.state === 'done') {
      this.announce(`Done${job.cache_hit ? ' (from the cache)' : ''}: ${job.result && job.result.stop_reason ? `stopped on ${job.result.stop_reason}` : 'result below'}.`);
      this.showResult(job);
    } else if (job.state === 'failed') {
      this.announce('The job failed.');
      const box = $('#job-problem');
      box.hidden = false;
      box.textContent = job.problem ? describe(new ApiError(job.problem.status, job.problem)) : 'no problem document';
    } else if (job.state === 'cancelled') {
      this.announce(job.result ? 'Cancelled: the best result so far is below.' : 'Cancelled.');
      if (job.result) this.showResult(job);
    }
  }

  showResult(job) {
    const res = $('#results');
    res.hidden = false;
    const name = this.showName(job.result);
    $('#results-h').textContent = name ? `Results: ${name}` : 'Results';
    const body = $('#results-body');
    if (this.collection === 'studies') renderStudyResult(body, job, this.study);
    else if (this.renderers[this.collection]) this.renderers[this.collection](body, job, this.study);
    else body.textContent = `No view for ${this.collection}: see the result as JSON at ${job.links.self}.`;
  }

  // A POST's answer: 202 (follow the job) or 200 (done, from the cache: show it at once).
  async submitted(r, doc, collection) {
    const job = r.body;
    rememberRequest(job.id, doc);
    history.replaceState(null, '', `#${job.links.self}`);
    if (r.status === 200 && job.state === 'done') {
      clearTimeout(this.timer);
      this.path = job.links.self;
      this.study = doc;
      this.collection = collection;
      this.place(collection);
      this.section.hidden = false;
      $('#job-problem').hidden = true;
      $('#job-cancel-msg').hidden = true;
      $('#job-link').href = job.links.self;
      $('#job-link').textContent = job.id;
      this.render(job);
      this.finish(job);
    } else {
      await this.open(job.links.self, doc, collection);
    }
    this.section.scrollIntoView({ block: 'start' });
  }

  async cancel() {
    if (!this.path) return;
    $('#job-cancel').disabled = true;
    $('#job-cancel-msg').hidden = true;
    try {
      const job = await api.cancel(this.path);
      clearTimeout(this.timer);
      this.render(job);
      this.finish(job);
      this.awaitBestSoFar(job);
    } catch (e) {
      // said next to the button (and announced): the next poll's status line must not hide it
      const msg = $('#job-cancel-msg');
      msg.textContent = `Cancel refused: ${describe(e)}`;
      msg.hidden = false;
      this.poll();
    }
  }
}

// ---- export ----------------------------------------------------------------------------------
function shellQuote(s) { return `'${s.replace(/'/g, `'\\''`)}'`; }
let exportUrl = null;
function showExport(kind, doc, collection = 'studies') {
  const box = $('#export');
  const json = JSON.stringify(doc, null, 2);
  // The token never goes into an export: the curl command reads it from the environment (the
  // variable prsm serve itself reads), and says so.
  const auth = getToken() ? ` -H "Authorization: Bearer $PRSM_TOKEN"` : '';
  const text = kind === 'json' ? json
    : `curl -si -H 'Content-Type: application/json'${auth} --data ${shellQuote(JSON.stringify(doc))} ${location.origin}/v1/${collection}`;
  $('#export-text').value = text;
  const note = $('#export-note');
  note.hidden = !(kind === 'curl' && auth);
  note.textContent = auth ? 'The command sends the token from the environment variable PRSM_TOKEN (export PRSM_TOKEN=… first); the page never writes the token into an export.' : '';
  $('#export-label').textContent = kind === 'json' ? 'Request as JSON' : 'Request as a curl command';
  if (exportUrl) URL.revokeObjectURL(exportUrl);
  exportUrl = URL.createObjectURL(new Blob([kind === 'json' ? json + '\n' : text + '\n'], { type: kind === 'json' ? 'application/json' : 'text/plain' }));
  const a = $('#export-download');
  a.href = exportUrl;
  a.download = kind === 'json' ? 'study.json' : 'study-curl.sh';
  box.hidden = false;
  box.dataset.kind = kind;
  $('#export-text').focus();
}

// ---- recent jobs (every collection the service has) ----------------------------------------------
// Each job by its name, kind, state and time, the id second. The job list has no names: a job
// submitted from this browser has its request remembered (localStorage, by id); for the others the
// name their result echoes is read once from the finished job (GET, kept for the page's life).
const KIND_NAMES = { studies: 'study', optimizations: 'optimisation', allocations: 'allocation', simulations: 'simulation', calibrations: 'calibration', analyses: 'analysis' };
const JOB_KINDS = { study: 'study', optimization: 'optimisation', allocation: 'allocation', simulation: 'simulation', calibration: 'calibration', analysis: 'analysis' };
let recentCollections = ['studies'];
const resultNames = new Map(); // job id -> name from its result ('' when it has none)
const utc = t => (typeof t === 'string' ? `${t.replace('T', ' ').slice(0, 19)} UTC` : '—');
function recentName(li, name, kind, id) {
  const span = li.querySelector('.job-name');
  span.textContent = name || `unnamed ${kind}`;
  span.classList.toggle('unnamed', !name);
  li.dataset.name = name;
  li.querySelector('a').setAttribute('aria-label', `${name || `unnamed ${kind}`}: ${kind}, ${li.dataset.state}, job ${id.slice(0, 12)}`);
}
async function refreshRecent() {
  const ul = $('#recent-list');
  try {
    const lists = await Promise.all(recentCollections.map(c => api.list(c, 8).then(l => (l.items || []).map(j => ({ ...j, collection: c })))));
    const items = lists.flat().sort((a, b) => (a.created_at < b.created_at ? 1 : a.created_at > b.created_at ? -1 : 0)).slice(0, 10);
    ul.textContent = '';
    const lookups = [];
    for (const j of items) {
      const kind = JOB_KINDS[j.kind] || KIND_NAMES[j.collection] || j.kind || j.collection;
      const li = document.createElement('li');
      li.dataset.id = j.id;
      li.dataset.kind = kind;
      li.dataset.state = j.state;
      const a = document.createElement('a');
      a.href = `#${j.links.self}`;
      const nm = document.createElement('span');
      nm.className = 'job-name';
      a.appendChild(nm);
      const k = document.createElement('span');
      k.className = 'job-kind';
      k.textContent = kind;
      const st = document.createElement('span');
      st.className = 'job-state';
      st.dataset.state = j.state;
      st.textContent = j.state;
      const when = document.createElement('time');
      const t = j.finished_at || j.created_at;
      when.dateTime = t;
      when.textContent = `${j.finished_at ? 'finished' : 'submitted'} ${utc(t)}`;
      const id = document.createElement('code');
      id.className = 'job-id';
      id.title = `job id ${j.id}`;
      id.textContent = j.id.slice(0, 12);
      li.append(a, ' · ', k, ' · ', st, ' · ', when, ' · ', id);
      ul.appendChild(li);
      const remembered = nameOf(recalledRequest(j.id));
      if (remembered || resultNames.has(j.id)) recentName(li, remembered || resultNames.get(j.id), kind, j.id);
      else {
        recentName(li, '', kind, j.id);
        if (j.state === 'done' || j.state === 'cancelled') lookups.push([li, kind, j]);
      }
    }
    if (!ul.children.length) ul.innerHTML = '<li>None yet.</li>';
    // names of jobs this browser did not submit, from their results
    await Promise.all(lookups.map(async ([li, kind, j]) => {
      try {
        const full = await api.job(j.links.self);
        resultNames.set(j.id, nameOf(null, full.result));
        if (li.isConnected) recentName(li, resultNames.get(j.id), kind, j.id);
      } catch { /* keep it unnamed */ }
    }));
  } catch (e) {
    ul.textContent = `Cannot list the jobs: ${describe(e)}`;
  }
}

// ---- start -----------------------------------------------------------------------------------
async function main() {
  const [studySchema, openapi, examples] = await Promise.all([
    api.schema('study.schema.json'),
    api.openapi(),
    api.example('index.json').catch(() => ({ examples: [] })),
  ]);
  const form = new StudyForm($('#study-form'), schemaInfo(studySchema));
  const derived = derivedView(form);
  form.on('design', () => derived.schedule());
  tokenField(() => derived.now());
  const jobs = new JobView(refreshRecent);
  window.prsm = { form, jobs, api }; // for the console and the browser test

  // A design into the study form, its tolerances and settings kept (extra: members to set too, such
  // as an error set). The study name follows the design ("Tolerance study of <design name>") unless
  // the user typed one of their own: a study of another design must not stay labelled with the
  // previous example's name. Returns what it says about the name.
  let nameTyped = false; // the study name was typed here since the last whole study was loaded
  $('#f-study-name').addEventListener('input', () => { nameTyped = true; });
  const loadStudy = doc => { form.load(doc); nameTyped = false; };
  const loadDesign = (design, extra, source) => {
    const current = form.toRequest();
    const typed = nameTyped && !!current.name;
    const doc = { ...current, design };
    for (const [k, v] of Object.entries(extra || {})) doc[k] = v;
    if (!typed) {
      const label = (design && typeof design.name === 'string' && design.name.trim()) || source;
      if (label) doc.name = `Tolerance study of ${label}`.slice(0, 100);
    }
    form.load(doc);
    $('#error-summary').hidden = true;
    return doc.name ? `study name “${doc.name}”${typed ? ' kept' : ': edit it in “Study name”'}` : 'no study name: give it one in “Study name”';
  };

  // import of one's own study or design file (file input, or dropped on the box or the form)
  setupImport({
    zone: $('#import'), dropTargets: [$('#study-layout')], input: $('#import-file'), message: $('#import-msg'),
    load: (kind, doc, file) => {
      if (kind === 'study') {
        loadStudy(doc);
        $('#error-summary').hidden = true;
        $('#examples-note').textContent = '';
        return doc.name ? `the whole study, study name “${doc.name}”` : 'the whole study; it has no name: give it one in “Study name”';
      }
      $('#examples-note').textContent = '';
      const design = kind === 'design' ? doc : doc.design;
      const extra = {};
      if (kind === 'errors') for (const k of ['errors', 'assembly']) if (k in doc) extra[k] = doc[k];
      return `tolerances and settings kept; ${loadDesign(design, extra, file)}`;
    },
    check: design => api.analyze(design),
    showProblems: errors => form.showProblems(errors, { prefix: '/design', source: 'analyze' }),
  });

  // examples: one click each
  const bar = $('#examples');
  for (const ex of examples.examples.filter(e => ['study', 'design', 'errors'].includes(e.kind))) {
    const b = document.createElement('button');
    b.type = 'button';
    b.textContent = ex.label;
    b.dataset.example = ex.file;
    b.addEventListener('click', async () => {
      try {
        const doc = await api.example(ex.file);
        let named = '';
        if (ex.kind === 'study') loadStudy(doc);
        else if (ex.kind === 'design') named = loadDesign(doc, {}, ex.file);
        else named = loadDesign(doc.design, { errors: doc.errors, assembly: doc.assembly }, ex.file);
        $('#examples-note').textContent = `Loaded ${ex.file} (${ex.kind === 'study' ? 'the whole study' : ex.kind === 'design' ? 'the design; tolerances and settings kept' : 'its design, error set and assembly options'}${named ? `; ${named}` : ''}).`;
      } catch (e) {
        $('#examples-note').textContent = `Cannot load ${ex.file}: ${describe(e)}`;
      }
    });
    bar.appendChild(b);
  }

  $('#study-form').addEventListener('submit', async e => {
    e.preventDefault();
    form.clearProblems('submit');
    $('#error-summary').hidden = true;
    const doc = form.toRequest();
    const btn = $('#submit');
    btn.disabled = true;
    try {
      await jobs.submitted(await api.submit('studies', doc), doc, 'studies');
    } catch (err) {
      if (err instanceof ApiError && err.unauthorized) {
        showSummary([{ pointer: '', message: describe(err), element: $('#api-token') }], err.tokenSent ? 'The API token was refused' : 'The service needs an API token');
      } else if (err instanceof ApiError && err.errors.length) {
        const placed = form.showProblems(err.errors, { source: 'submit' });
        showSummary(placed, `${err.problem.title} (${err.status}): ${err.errors.length === 1 ? 'a problem' : `${err.errors.length} problems`} in the request`);
      } else {
        showSummary([{ pointer: '', message: describe(err) }], err.status === 503 ? `The service is busy${err.problem.retry_after_s ? `: retry in ${err.problem.retry_after_s} s` : ''}` : 'The request was not accepted');
      }
    } finally {
      btn.disabled = false;
    }
  });

  $('#export-json').addEventListener('click', () => showExport('json', form.toRequest()));
  $('#export-curl').addEventListener('click', () => showExport('curl', form.toRequest()));
  $('#export-close').addEventListener('click', () => { $('#export').hidden = true; $('#export-json').focus(); });
  $('#export-copy').addEventListener('click', async () => {
    const t = $('#export-text');
    try { await navigator.clipboard.writeText(t.value); } catch { t.select(); document.execCommand('copy'); }
  });

  // #/v1/studies/ID opens that job
  const route = () => {
    const m = /^#(\/v1\/([a-z]+)\/[0-9a-f]{32})$/.exec(location.hash);
    if (m) jobs.open(m[1], recalledRequest(m[1].split('/').pop()), m[2]);
  };
  window.addEventListener('hashchange', route);

  const ctx = { jobs, form, loadDesign, examples: examples.examples, submitted: (r, doc, c) => jobs.submitted(r, doc, c) };
  if (setupOptimization(openapi, ctx)) recentCollections.push('optimizations');
  if (setupAllocation(openapi, ctx)) recentCollections.push('allocations');
  if (setupSimulation(openapi, ctx)) recentCollections.push('simulations');
  if (setupCalibration(openapi, ctx)) recentCollections.push('calibrations');
  if (openapi && openapi.paths && openapi.paths['/v1/analyses']) recentCollections.push('analyses');
  api.version().then(v => { $('#version').textContent = `prsm ${v.prsm || v.version || ''}`.trim(); }).catch(() => {});
  refreshRecent();

  if (location.hash.startsWith('#/v1/')) route();
  const first = examples.examples.find(e => e.kind === 'study');
  if (first) {
    form.load(await api.example(first.file));
    $('#examples-note').textContent = `Loaded ${first.file}; pick another example or edit the fields.`;
  } else {
    form.load({ design: { geometry: {} }, tolerances: [] });
  }
  document.body.dataset.ready = 'true';
}

main().catch(e => {
  const p = document.createElement('p');
  p.className = 'notice';
  p.setAttribute('role', 'alert');
  p.textContent = `The form could not start: ${describe(e)}`;
  document.querySelector('main').prepend(p);
});
