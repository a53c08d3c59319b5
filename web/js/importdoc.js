// Import of one's own JSON file into the study form: a file input and drag and drop (on the import
// box or on the form). The document's kind is told from its members (schemas/*.schema.json): a
// study (tolerances, with a design or a model) replaces the whole form; a design (geometry), or an
// analyze request {design, errors?, assembly?}, replaces the design and keeps the tolerances and
// settings. Anything else is refused with what it is and where it belongs (an optimisation request,
// a study result, a job document ...); a file that is not JSON is refused with the parser's message
// and the line and column. Nothing is loaded from a refused file. After loading, the design is
// checked by the service (POST /v1/designs/analyze, the one endpoint that checks a document without
// running a job) and what it says is reported here, its problems also next to their fields.

import { api, ApiError, describe } from './api.js';

const MAX_BYTES = 10 * 1024 * 1024;
const isObject = v => v !== null && typeof v === 'object' && !Array.isArray(v);
const has = (doc, ...keys) => keys.every(k => k in doc);

// What a parsed document is: {kind: 'study' | 'design' | 'errors', design, what} for what the study
// form takes, {error} (a sentence) for anything else.
export function classify(doc) {
  if (!isObject(doc)) {
    const what = Array.isArray(doc) ? 'an array' : doc === null ? 'null' : `a ${typeof doc}`;
    return { error: `it holds ${what}, not a JSON object: a study or design document is an object { … }.` };
  }
  // documents the service writes, not requests
  if (typeof doc.id === 'string' && typeof doc.state === 'string' && isObject(doc.links)) {
    return { error: `it is a job document of the service (a${/^[aeiou]/.test(doc.kind || '') ? 'n' : ''} ${doc.kind || 'job'}, ${doc.state}), not a request: open the job from “Recent jobs”, or import the request that made it.` };
  }
  if (has(doc, 'kind', 'request') && isObject(doc.request)) return { error: 'it is a line of a batch file (prsm batch): import its "request" member on its own.' };
  if (has(doc, 'type', 'title', 'status', 'errors')) return { error: 'it is a problem document (an error answer of the service), not a request.' };
  if (has(doc, 'valid', 'errors', 'warnings')) return { error: 'it is the output of prsm validate, not a request.' };
  if (isObject(doc.outputs) && isObject(doc.samples) && 'stop_reason' in doc) return { error: 'it is a study result (what the service answers for a study), not a study request: a study request has "tolerances" and a "design".' };
  if (has(doc, 'method', 'best', 'evaluations')) return { error: 'it is an optimisation result, not a request: its designs can be put into the study form from the optimisation view (“Study this design’s tolerances”).' };
  if (has(doc, 'total_cost', 'correction')) return { error: 'it is an allocation result, not a request.' };
  if (has(doc, 'engine', 'calibration') || has(doc, 'engine', 'identification')) return { error: 'it is a calibration result, not a request.' };
  if (has(doc, 'engine', 'dynamics')) return { error: 'it is a simulation result, not a request.' };
  if ('engine' in doc && (has(doc, 'geometry', 'backlash_um') || 'stages' in doc)) return { error: 'it is an analysis result (what prsm analyze and POST /v1/designs/analyze answer), not a design: import the design that was analysed.' };
  // requests of the other views
  if (has(doc, 'variables', 'objectives')) return { error: 'it is an optimisation request (it has "variables" and "objectives"): paste it into the optimisation view’s request (“Design optimisation” below), not the study form.' };
  if (has(doc, 'allocate', 'constraints')) return { error: 'it is a tolerance allocation request (it has "allocate" and "constraints"): paste it into the allocation view’s request (“Tolerance allocation” below).' };
  if (isObject(doc.measured) && isObject(doc.design)) return { error: 'it is a calibration request (it has "measured"): paste it into the calibration view’s request (“Calibration against measured data” below).' };
  if ('dynamics' in doc || 'gear_pair' in doc || (isObject(doc.design) && 'dynamics' in doc.design)) return { error: 'it is a simulation request (it has "dynamics"): paste it into the simulation view’s request (“Start-up simulation” below).' };
  if ('stages' in doc || (isObject(doc.design) && 'stages' in doc.design)) return { error: 'it is a multi-stage design (it has "stages"): the study form takes a single-stage design; a chain is simulated in the simulation view.' };
  // what the study form takes
  if (Array.isArray(doc.tolerances) || ((isObject(doc.design) || isObject(doc.model)) && ['monte_carlo', 'outputs', 'specs', 'sensitivity', 'correlations'].some(k => k in doc))) {
    return { kind: 'study', design: isObject(doc.design) ? doc.design : null, what: doc.model ? 'a study of a model (its model is sent as loaded)' : 'a study' };
  }
  if (isObject(doc.design) && Object.keys(doc).every(k => ['design', 'errors', 'assembly', 'curve'].includes(k))) {
    return { kind: 'errors', design: doc.design, what: doc.errors ? 'a design with an error set (an analyze request)' : 'an analyze request (its design)' };
  }
  if (isObject(doc.geometry)) return { kind: 'design', design: doc, what: 'a design' };
  const keys = Object.keys(doc);
  return { error: `it is not a study or a design: a study has "tolerances" (and a "design"), a design has "geometry"; this file has ${keys.length ? keys.slice(0, 8).map(k => `"${k}"`).join(', ') + (keys.length > 8 ? ', …' : '') : 'no members'}.` };
}

// Where the first syntax error of a text that JSON.parse refused is (an offset), by a strict scan of
// the JSON grammar: JSON.parse's own message does not always say ("Unexpected token ','...").
// null when the scan finds none.
export function jsonErrorOffset(text) {
  let i = 0;
  const fail = () => { throw i; };
  const ws = () => { while (i < text.length && ' \t\n\r'.includes(text[i])) i++; };
  const string = () => {
    i++;
    while (i < text.length) {
      const c = text[i];
      if (c === '"') { i++; return; }
      if (c === '\\') {
        const e = text[i + 1];
        if (e === 'u') { if (!/^[0-9a-fA-F]{4}$/.test(text.slice(i + 2, i + 6))) { i += 1; fail(); } i += 6; continue; }
        if (e === undefined || !'"\\/bfnrt'.includes(e)) { i += 1; fail(); }
        i += 2;
        continue;
      }
      if (c < ' ') fail();
      i++;
    }
    fail();
  };
  const value = () => {
    ws();
    const c = text[i];
    if (c === '{') {
      i++; ws();
      if (text[i] === '}') { i++; return; }
      for (;;) {
        ws();
        if (text[i] !== '"') fail();
        string(); ws();
        if (text[i] !== ':') fail();
        i++; value(); ws();
        if (text[i] === ',') { i++; continue; }
        if (text[i] === '}') { i++; return; }
        fail();
      }
    }
    if (c === '[') {
      i++; ws();
      if (text[i] === ']') { i++; return; }
      for (;;) {
        value(); ws();
        if (text[i] === ',') { i++; continue; }
        if (text[i] === ']') { i++; return; }
        fail();
      }
    }
    if (c === '"') { string(); return; }
    const num = /^-?(0|[1-9][0-9]*)(\.[0-9]+)?([eE][+-]?[0-9]+)?/.exec(text.slice(i, i + 64));
    if (num && num[0] && num[0] !== '-') { i += num[0].length; return; }
    for (const w of ['true', 'false', 'null']) if (text.startsWith(w, i)) { i += w.length; return; }
    fail();
  };
  try {
    value(); ws();
    if (i < text.length) fail();
    return null;
  } catch (e) {
    if (typeof e === 'number') return e;
    throw e;
  }
}

// JSON.parse's message with the line and column of the error, and that line.
function parseError(text, e) {
  const msg = String(e && e.message ? e.message : e).replace(/\s+/g, ' ');
  const m = /position (\d+)/.exec(msg);
  const pos = m ? Number(m[1]) : jsonErrorOffset(text);
  if (pos === null || pos === undefined) return msg;
  const lines = text.slice(0, pos).split('\n');
  const line = lines.length, column = lines[lines.length - 1].length + 1;
  const src = (text.split('\n')[line - 1] || '').trim().slice(0, 80);
  return `${/line \d+/.test(msg) ? msg : `${msg} at line ${line}, column ${column}`}${src ? ` (the line: ${src})` : ''}`;
}

// opts: {zone: the import box, dropTargets: [elements], input: the file input, message: the status
// element, load(kind, doc, fileName) → what was loaded (a sentence), check(design) → Promise of the
// analysis (api.analyze), showProblems(errors) → puts the design's problems at their fields}.
export function setupImport({ zone, dropTargets, input, message, load, check, showProblems }) {
  let seq = 0;
  // state: 'ok' (loaded, the service accepts it), 'error' (not loaded, or the service refuses its
  // design), 'checking' (loaded, the service is asked), 'unchecked' (loaded, the service did not answer)
  const say = (parts, state = 'ok') => {
    message.textContent = '';
    message.append(...parts);
    message.classList.toggle('error', state === 'error' || state === 'unchecked');
    message.dataset.state = state;
    message.hidden = false;
  };
  const list = items => {
    const ul = document.createElement('ul');
    for (const t of items) {
      const li = document.createElement('li');
      li.textContent = t;
      ul.appendChild(li);
    }
    return ul;
  };

  async function importFile(file) {
    const my = ++seq;
    const name = file.name || 'the file';
    if (file.size > MAX_BYTES) return say([`Not loaded: ${name} is ${(file.size / 1048576).toFixed(1)} MB, more than a study or design document (at most 10 MB here).`], 'error');
    let text;
    try { text = await file.text(); } catch (e) { return say([`Not loaded: ${name} could not be read (${e.message}).`], 'error'); }
    if (my !== seq) return undefined;
    if (!text.trim()) return say([`Not loaded: ${name} is empty.`], 'error');
    let doc;
    try { doc = JSON.parse(text); } catch (e) {
      return say([`Not loaded: ${name} is not valid JSON: ${parseError(text, e)}. The form is unchanged.`], 'error');
    }
    const c = classify(doc);
    if (c.error) return say([`Not loaded: ${name} is not a study or design document: ${c.error} The form is unchanged.`], 'error');
    const loaded = load(c.kind, doc, name);
    const head = `Loaded ${name}: ${c.what}${loaded ? ` (${loaded})` : ''}.`;
    if (!c.design) return say([head, ' No design to check.']);
    say([head, ' Checking its design with the service…'], 'checking');
    try {
      const a = await check(c.design);
      if (my !== seq) return undefined;
      const ws = (a && a.warnings) || [];
      say([head, ` The service (POST /v1/designs/analyze) accepts its design${ws.length ? `, with ${ws.length} warning${ws.length > 1 ? 's' : ''} (also next to ${ws.length > 1 ? 'their fields' : 'its field'}):` : '.'}`,
        ...(ws.length ? [list(ws.map(w => `${w.pointer ? `/design${w.pointer}: ` : ''}${w.message}`))] : [])]);
    } catch (e) {
      if (my !== seq) return undefined;
      if (e instanceof ApiError && e.errors.length && !e.unauthorized) {
        showProblems(e.errors);
        say([head, ` The service (POST /v1/designs/analyze) refuses its design: ${e.errors.length === 1 ? 'a problem' : `${e.errors.length} problems`} (also next to the fields): fix ${e.errors.length === 1 ? 'it' : 'them'} before running the study.`,
          list(e.errors.map(p => `${p.pointer ? `/design${p.pointer}: ` : ''}${p.message}`))], 'error');
      } else {
        say([head, ` Its design could not be checked: ${describe(e)}`], 'unchecked');
      }
    }
    return undefined;
  }

  input.addEventListener('change', () => {
    const f = input.files && input.files[0];
    if (f) importFile(f);
    input.value = ''; // the same file again fires change again
  });
  const isFileDrag = e => e.dataTransfer && [...(e.dataTransfer.types || [])].includes('Files');
  for (const t of [zone, ...dropTargets]) {
    t.addEventListener('dragover', e => {
      if (!isFileDrag(e)) return;
      e.preventDefault();
      e.dataTransfer.dropEffect = 'copy';
      t.classList.add('dragging');
    });
    t.addEventListener('dragleave', e => { if (!t.contains(e.relatedTarget)) t.classList.remove('dragging'); });
    t.addEventListener('drop', e => {
      if (!isFileDrag(e)) return;
      e.preventDefault();
      e.stopPropagation();
      t.classList.remove('dragging');
      const files = [...e.dataTransfer.files];
      if (files.length !== 1) say([`Not loaded: drop one file (${files.length} were dropped).`], 'error');
      else importFile(files[0]);
      zone.scrollIntoView({ block: 'nearest' });
    });
  }
  // a file dropped anywhere else must not replace the page
  window.addEventListener('dragover', e => { if (isFileDrag(e)) e.preventDefault(); });
  window.addEventListener('drop', e => { if (isFileDrag(e)) e.preventDefault(); });
  return { importFile };
}
