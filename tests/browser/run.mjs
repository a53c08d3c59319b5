#!/usr/bin/env node
// Browser test of the web form (web/) in real headless Chromium (Debian's /usr/bin/chromium) driven
// by playwright-core. Starts `prsm serve` itself on 127.0.0.1 (a free port, a temporary database),
// loads the page, loads an example, submits a small study, waits for the result and checks that the
// plots and numbers are there and agree with the API's JSON fetched directly, checks the export,
// cancel and that an invalid field shows the API's message next to that field, saves screenshots,
// and stops the server.
//
//   node tests/browser/run.mjs --prsm build/prsm --source . --artifacts build/browser-artifacts \
//        [--work build/browser-test] [--chromium /usr/bin/chromium] [--keep]
//
// playwright-core is installed with `npm ci` from tests/browser/package-lock.json into --work
// (default: <artifacts>/../browser-test), not into the source tree; it never downloads a browser.

import { spawn, spawnSync } from 'node:child_process';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { pathToFileURL } from 'node:url';

const t0 = Date.now();
const args = {};
for (let i = 2; i < process.argv.length; i++) {
  const a = process.argv[i];
  if (!a.startsWith('--')) usage(`unexpected argument ${a}`);
  const key = a.slice(2);
  if (key === 'keep') { args.keep = true; continue; }
  if (i + 1 >= process.argv.length) usage(`${a} needs a value`);
  args[key] = process.argv[++i];
}
function usage(msg) {
  console.error(`run.mjs: ${msg}\nusage: node run.mjs --prsm PRSM --source DIR --artifacts DIR [--work DIR] [--chromium PATH] [--keep]`);
  process.exit(64);
}
if (!args.prsm || !args.source || !args.artifacts) usage('--prsm, --source and --artifacts are required');
const source = path.resolve(args.source);
const artifacts = path.resolve(args.artifacts);
const work = path.resolve(args.work || path.join(artifacts, '..', 'browser-test'));
const chromiumPath = args.chromium || '/usr/bin/chromium';
fs.mkdirSync(artifacts, { recursive: true });
for (const f of fs.readdirSync(artifacts)) if (f.endsWith('.png')) fs.rmSync(path.join(artifacts, f));

let failures = 0, passes = 0;
function check(name, ok, detail = '') {
  if (ok) { passes++; console.log(`ok   ${name}`); }
  else { failures++; console.log(`FAIL ${name}${detail ? `: ${detail}` : ''}`); }
  return ok;
}
const near = (a, b, rel = 1e-9) => typeof a === 'number' && typeof b === 'number' && Math.abs(a - b) <= rel * Math.max(1, Math.abs(a), Math.abs(b));
// JSON with object keys sorted (array order kept): equal documents give equal strings.
const canonical = v => JSON.stringify(v, (k, x) => (x && typeof x === 'object' && !Array.isArray(x) ? Object.fromEntries(Object.keys(x).sort().map(key => [key, x[key]])) : x));
const log = s => console.log(`# ${s} (${((Date.now() - t0) / 1000).toFixed(1)} s)`);

// ---- playwright-core, installed from the lock file into the build tree -----------------------
function ensurePlaywright() {
  const lock = path.join(source, 'tests/browser/package-lock.json');
  const pkg = path.join(source, 'tests/browser/package.json');
  const installedLock = path.join(work, 'package-lock.json');
  const entry = path.join(work, 'node_modules/playwright-core/index.mjs');
  const same = fs.existsSync(installedLock) && fs.readFileSync(installedLock, 'utf8') === fs.readFileSync(lock, 'utf8');
  if (same && fs.existsSync(entry)) return entry;
  fs.mkdirSync(work, { recursive: true });
  fs.copyFileSync(pkg, path.join(work, 'package.json'));
  fs.copyFileSync(lock, installedLock);
  log(`npm ci in ${work}`);
  const r = spawnSync('npm', ['ci', '--no-audit', '--no-fund', '--loglevel=error', '--prefix', work], {
    stdio: 'inherit', env: { ...process.env, PLAYWRIGHT_SKIP_BROWSER_DOWNLOAD: '1' },
  });
  if (r.status !== 0 || !fs.existsSync(entry)) {
    console.error('run.mjs: npm ci failed (is the npm registry reachable?)');
    process.exit(1);
  }
  return entry;
}

// ---- the server --------------------------------------------------------------------------------
async function startServer(dbDir) {
  const child = spawn(path.resolve(args.prsm), ['serve', '--host', '127.0.0.1', '--port', '0', '--db', path.join(dbDir, 'prsm.db'),
    '--data-dir', source, '--workers', '1'], { stdio: ['ignore', 'pipe', 'pipe'] });
  let out = '';
  const origin = await new Promise((resolve, reject) => {
    const timer = setTimeout(() => reject(new Error(`prsm serve did not start:\n${out}`)), 15000);
    const onData = d => {
      out += d.toString();
      const m = /listening on (http:\/\/127\.0\.0\.1:\d+)\//.exec(out);
      if (m) { clearTimeout(timer); resolve(m[1]); }
    };
    child.stdout.on('data', onData);
    child.stderr.on('data', onData);
    child.on('exit', code => { clearTimeout(timer); reject(new Error(`prsm serve exited (${code}):\n${out}`)); });
  });
  child.stdout.removeAllListeners('data');
  child.stderr.removeAllListeners('data');
  child.stdout.resume();
  child.stderr.resume();
  child.removeAllListeners('exit');
  return { child, origin };
}
async function stopServer(child) {
  if (child.exitCode !== null) return child.exitCode;
  const done = new Promise(resolve => child.on('exit', (code, sig) => resolve(code ?? sig)));
  child.kill('SIGTERM');
  const timer = setTimeout(() => child.kill('SIGKILL'), 10000);
  const code = await done;
  clearTimeout(timer);
  return code;
}

// ---- direct API calls (node's fetch) -----------------------------------------------------------
let ORIGIN = '';
async function apiJson(method, p, body) {
  const r = await fetch(ORIGIN + p, { method, headers: body ? { 'Content-Type': 'application/json' } : {}, body: body ? JSON.stringify(body) : undefined });
  const text = await r.text();
  let json = null;
  try { json = JSON.parse(text); } catch { /* not JSON */ }
  return { status: r.status, json, text, headers: r.headers };
}

function examplesAreCopies() {
  const manifest = JSON.parse(fs.readFileSync(path.join(source, 'web/examples/index.json'), 'utf8'));
  check('web/examples/index.json lists examples', manifest.examples.length > 0);
  for (const ex of manifest.examples) {
    const a = path.join(source, 'web/examples', ex.file), b = path.join(source, 'studies', ex.file);
    check(`web/examples/${ex.file} is identical to studies/${ex.file}`, fs.existsSync(a) && fs.existsSync(b) && fs.readFileSync(a).equals(fs.readFileSync(b)));
  }
  const listed = new Set(manifest.examples.map(e => e.file).concat('index.json'));
  for (const f of fs.readdirSync(path.join(source, 'web/examples'))) check(`web/examples/${f} is listed in index.json`, listed.has(f));
  return manifest;
}

async function main() {
  examplesAreCopies();
  const entry = ensurePlaywright();
  const { chromium } = await import(pathToFileURL(entry).href);
  const dbDir = fs.mkdtempSync(path.join(os.tmpdir(), 'prsm-browser-'));
  const { child, origin } = await startServer(dbDir);
  ORIGIN = origin;
  log(`prsm serve at ${origin}`);
  let browser;
  try {
    browser = await chromium.launch({ executablePath: chromiumPath, headless: true, args: ['--no-sandbox', '--disable-gpu', '--disable-dev-shm-usage'] });
    const context = await browser.newContext({ viewport: { width: 1366, height: 900 }, deviceScaleFactor: 1 });
    const external = [], pageErrors = [];
    await context.route('**/*', route => {
      const u = route.request().url();
      if (u.startsWith(origin + '/') || u.startsWith('data:') || u.startsWith('blob:')) return route.continue();
      external.push(u);
      return route.abort();
    });
    const page = await context.newPage();
    page.on('pageerror', e => pageErrors.push(e.message));
    page.setDefaultTimeout(20000);
    await run(page);
    check('no request left the server (everything served by prsm serve)', external.length === 0, external.join(', '));
    check('no JavaScript errors in the page', pageErrors.length === 0, pageErrors.join(' | '));
  } finally {
    if (browser) await browser.close();
    const code = await stopServer(child);
    check('prsm serve stopped cleanly on SIGTERM', code === 0, String(code));
    if (!args.keep) fs.rmSync(dbDir, { recursive: true, force: true });
  }
}

// ---- the page ----------------------------------------------------------------------------------
async function run(page) {
  const shot = async name => { await page.screenshot({ path: path.join(artifacts, name), fullPage: true }); };
  await page.goto(ORIGIN + '/');
  await page.waitForSelector('body[data-ready=true]');
  await page.waitForSelector('#derived-list dd[data-key=nut_radius_mm]');
  log('page loaded');

  // every control has an accessible name
  const unnamed = await page.evaluate(() => [...document.querySelectorAll('input, select, textarea, button')]
    .filter(e => !(e.labels && e.labels.length) && !e.getAttribute('aria-label') && !e.getAttribute('aria-labelledby') && !(e.tagName === 'BUTTON' && e.textContent.trim()))
    .map(e => e.id || e.outerHTML.slice(0, 80)));
  check('every form control has a label or an accessible name', unnamed.length === 0, unnamed.join(', '));
  check('progress is announced in an aria-live region', await page.$eval('#job-status', e => e.getAttribute('aria-live') === 'polite'));

  // an example with one keyboard action
  const study = JSON.parse(fs.readFileSync(path.join(source, 'studies/case-a-tolerances.json'), 'utf8'));
  await page.focus('#examples button[data-example="case-a.json"]');
  await page.keyboard.press('Enter');
  await page.waitForFunction(() => document.querySelector('#examples-note').textContent.includes('case-a.json'));
  await page.focus('#examples button[data-example="case-a-tolerances.json"]');
  await page.keyboard.press('Enter');
  await page.waitForFunction(() => document.querySelector('#examples-note').textContent.includes('case-a-tolerances.json'));
  check('the example fills the form', await page.inputValue('#f-pitch') === String(study.design.geometry.pitch_mm)
    && await page.$$eval('#tolerances tbody tr', r => r.length) === study.tolerances.length);
  const formDoc = await page.evaluate(() => window.prsm.form.toRequest());
  check('the form gives back the example as it was loaded', canonical(formDoc) === canonical(study), JSON.stringify(formDoc).slice(0, 300));

  // derived values against POST /v1/designs/analyze
  await page.waitForFunction(() => document.querySelector('#derived-status').textContent.startsWith('Design analysed'));
  const analysis = (await apiJson('POST', '/v1/designs/analyze', study.design)).json;
  const derived = await page.$$eval('#derived-list dd', dds => Object.fromEntries(dds.map(d => [d.dataset.key, d.dataset.value === undefined ? d.textContent : Number(d.dataset.value)])));
  for (const [key, want] of [['nut_radius_mm', analysis.design.geometry.nut_radius_mm], ['screw_radius_mm', analysis.design.geometry.screw_radius_mm],
    ['lead_mm', analysis.geometry.lead_mm], ['helix_angle_screw_deg', analysis.geometry.helix_angle_screw_deg],
    ['helix_angle_roller_deg', analysis.geometry.helix_angle_roller_deg], ['helix_angle_nut_deg', analysis.geometry.helix_angle_nut_deg],
    ['z_max', analysis.geometry.z_max], ['eta', analysis.efficiency.eta]]) {
    check(`derived ${key} = ${want} as the API says`, derived[key] === want, String(derived[key]));
  }
  // live: a non-standard nut radius updates the derived values and shows the API's warning there
  await page.fill('#f-rn', '16.5');
  await page.waitForSelector('#derived-list dd[data-key=nut_radius_mm][data-value="16.5"]');
  const warned = (await apiJson('POST', '/v1/designs/analyze', { ...study.design, geometry: { ...study.design.geometry, nut_radius_mm: 16.5 } })).json.warnings;
  await page.waitForSelector('#f-rn ~ .problems .problem-msg.warning');
  const warnText = await page.$eval('#f-rn ~ .problems .problem-msg.warning', e => e.dataset.text);
  check('a rule warning from the analysis shows next to its field', warned.some(w => w.pointer === '/geometry/nut_radius_mm' && w.message === warnText), warnText);
  await page.fill('#f-rn', '');
  await page.waitForFunction(() => !document.querySelector('#f-rn ~ .problems'));
  await shot('01-form.png');

  // ---- a small study: submit, wait, check against the API ----------------------------------
  await page.fill('#f-samples', '1024');
  await page.fill('#f-block', '256');
  await page.fill('#f-sobol-n', '64');
  await page.fill('#f-sobol-b', '20');
  await page.click('#submit');
  await page.waitForSelector('#job-state[data-state=done]', { timeout: 45000 });
  await page.waitForSelector('#output-cards .card.output');
  const jobPath = await page.evaluate(() => location.hash.slice(1));
  check('the page shows the job at #/v1/studies/ID', /^\/v1\/studies\/[0-9a-f]{32}$/.test(jobPath), jobPath);
  const job = (await apiJson('GET', jobPath)).json;
  const result = job.result;
  log(`study done: ${result.samples.used} samples`);
  check('progress shows the samples done', (await page.textContent('#job-samples')).startsWith(result.samples.run.toLocaleString('en-US')), await page.textContent('#job-samples'));
  const outputs = Object.keys(result.outputs);
  const cards = await page.$$eval('#output-cards .card.output', cs => cs.map(c => c.dataset.output));
  check('one card per output of the result', JSON.stringify(cards) === JSON.stringify(outputs), cards.join(','));
  for (const name of outputs) {
    const o = result.outputs[name];
    const card = `#output-cards .card.output[data-output="${name}"]`;
    const bars = await page.$$eval(`${card} svg.histogram rect.bar`, rs => rs.map(r => Number(r.dataset.count)));
    check(`${name}: histogram has the result's ${o.histogram.counts.length} bins and counts`, JSON.stringify(bars) === JSON.stringify(o.histogram.counts));
    const specLines = await page.$$eval(`${card} svg.histogram line.spec`, ls => ls.map(l => Number(l.dataset.value)));
    const specWant = o.spec ? [o.spec.lower, o.spec.upper].filter(v => v !== undefined) : [];
    check(`${name}: spec limits drawn (${specWant.join(', ') || 'none'})`, JSON.stringify(specLines) === JSON.stringify(specWant), JSON.stringify(specLines));
    const cells = await page.$$eval(`${card} table.numbers td`, tds => Object.fromEntries(tds.map(t => [t.dataset.key, { v: t.dataset.value === undefined ? null : Number(t.dataset.value), text: t.textContent }])));
    for (const [key, want] of [['n', o.n], ['mean', o.mean], ['sd', o.sd], ['min', o.min], ['max', o.max], ['p50', o.quantiles.p50],
      ['p0_135', o.quantiles.p0_135], ['p99_865', o.quantiles.p99_865]]) {
      const c = cells[key];
      const shown = c ? Number(c.text.replace('−', '-')) : NaN;
      check(`${name}: ${key} in the table = API ${want}`, c && c.v === want && near(shown, want, 5e-4), c ? `${c.v} shown ${c.text}` : 'missing');
    }
    if (o.spec) {
      const c = cells.yield;
      check(`${name}: yield in the table = API ${o.yield.fraction}`, c && c.v === o.yield.fraction && c.text === `${(100 * o.yield.fraction).toFixed(2)} %`, c && c.text);
      const y = await page.$eval(`${card} h3 .yield`, e => Number(e.dataset.value));
      check(`${name}: yield beside the plot`, y === o.yield.fraction);
      check(`${name}: Cpk in the table`, cells.cpk && cells.cpk.v === o.cpk);
    }
  }
  await shot('03-results.png');

  // tornado: Sobol total indices by default, SRC² shares on demand, the definition named
  const first = outputs[0];
  const torn = async () => page.$$eval('#tornado-table td', tds => Object.fromEntries(tds.map(t => [t.dataset.key, Number(t.dataset.value)])));
  const sensTol = result.outputs[first].sensitivity.tolerances;
  let shown = await torn();
  check('tornado: Sobol total index per tolerance as the API says', sensTol.every(t => shown[t.parameter] === t.sobol_total) && Object.keys(shown).length === sensTol.length);
  check('tornado: bars drawn for every tolerance', await page.$$eval('#tornado-card svg.tornado rect.bar', r => r.length) === sensTol.length);
  check('tornado: whiskers for the bootstrap intervals', await page.$$eval('#tornado-card svg.tornado line.whisker', r => r.length) === 3 * sensTol.length);
  check('tornado: the definition is named', (await page.textContent('#tornado-definition-text')).includes('Sobol total index'));
  await page.selectOption('#tornado-definition', 'src_percent');
  shown = await torn();
  check('tornado: SRC² shares as the API says', sensTol.every(t => shown[t.parameter] === t.src_percent));
  check('tornado: the SRC definition is the service\'s own', (await page.textContent('#tornado-definition-text')).includes(result.outputs[first].sensitivity.contribution_definition));
  await page.selectOption('#tornado-definition', 'sobol_total');
  await (await page.$('#tornado-card')).screenshot({ path: path.join(artifacts, '03b-tornado.png') });

  // the CSV link and the sample replay (TE over a revolution, per-roller loads)
  const csvHref = await page.getAttribute('#csv-link', 'href');
  check('CSV download link is the job\'s samples.csv', csvHref === job.links.samples_csv, csvHref);
  const csv = await apiJson('GET', csvHref);
  const lines = csv.text.trim().split('\n');
  check('samples.csv has a row per sample run', csv.status === 200 && lines.length === result.samples.run + 1, `${csv.status} ${lines.length}`);
  await page.waitForSelector('#replay-table');
  await page.waitForSelector('#te-plot');
  const header = lines[0].split(',');
  const sample = Number(await page.getAttribute('#replay-table', 'data-sample'));
  const row = Object.fromEntries(lines[sample + 1].split(',').map((v, i) => [header[i], v]));
  const teCol = header.indexOf('te_pp_um');
  const maxTe = Math.max(...lines.slice(1).map(l => Number(l.split(',')[teCol])));
  check('replay: the default sample is the one with the largest te_pp_um', Number(row.te_pp_um) === maxTe, `${row.te_pp_um} vs ${maxTe}`);
  const replay = await page.$$eval('#replay-table tbody tr', trs => Object.fromEntries(trs.map(tr => [tr.dataset.key, {
    analysis: tr.querySelector('.analysis').dataset.value, csv: tr.querySelector('.csv').dataset.value }])));
  for (const key of ['te_pp_um', 'backlash_um', 'backlash_min_um', 'load_sharing_factor', 'stiffness_ratio']) {
    const r = replay[key];
    check(`replay: ${key} of sample ${sample} re-analysed = samples.csv (${row[key]})`, r && Number(r.csv) === Number(row[key]) && near(Number(r.analysis), Number(row[key]), 1e-6), JSON.stringify(r));
  }
  const apr = study.assembly.angles_per_revolution;
  check('replay: TE curve over one revolution has angles_per_revolution + 1 points', await page.$eval('#te-plot polyline.curve', p => Number(p.dataset.points)) === apr + 1);
  check('replay: one load bar per roller', await page.$$eval('#roller-plot rect.bar', r => r.length) === study.design.geometry.rollers);
  await (await page.$('#replay-card')).screenshot({ path: path.join(artifacts, '03c-replay.png') });

  // export: the JSON is the submitted request (an identical POST is answered from the cache), and
  // the curl command runs as it is
  await page.click('#export-json');
  const exported = JSON.parse(await page.inputValue('#export-text'));
  const again = await apiJson('POST', '/v1/studies', exported);
  check('exported JSON is the request that ran (answered from the cache, same job)', again.status === 200 && again.json.cache_hit === true && again.json.id === job.id, `${again.status} ${again.json && again.json.id}`);
  await page.click('#export-curl');
  const curlCmd = await page.inputValue('#export-text');
  check('curl command posts to this server', curlCmd.startsWith('curl ') && curlCmd.includes(`${ORIGIN}/v1/studies`));
  if (spawnSync('sh', ['-c', 'command -v curl']).status === 0) {
    const r = spawnSync('sh', ['-c', curlCmd], { encoding: 'utf8' });
    check('the curl command runs and is answered from the cache', r.status === 0 && /HTTP\/1\.1 200/.test(r.stdout) && r.stdout.includes(job.id), r.stderr || r.stdout.slice(0, 200));
  }
  await page.click('#export-close');

  // ---- cancel: a long study (exact mode), cancelled from the page -------------------------------
  await page.fill('#f-samples', '200000');
  await page.selectOption('#f-mode', 'exact');
  await page.uncheck('#f-sobol');
  await page.click('#submit');
  await page.waitForSelector('#job-state[data-state=running]', { timeout: 20000 });
  await page.waitForFunction(() => document.querySelector('#job-progress').value > 0, null, { timeout: 20000 }).catch(() => {});
  const longPath = await page.evaluate(() => location.hash.slice(1));
  // the stop target (backlash_um standard error <= 0.05) is reported while it runs
  const widthShown = await page.waitForSelector('#job-interval[data-value]', { timeout: 30000 }).then(() => true, () => false);
  const live = (await apiJson('GET', longPath)).json.progress;
  check('progress shows the stop target\'s interval width and its goal', widthShown && live.interval_goal === 0.05
    && (await page.textContent('#job-interval')).includes('goal 0.05'), `${await page.textContent('#job-interval')} api ${JSON.stringify(live)}`);
  check('a second job was started', longPath !== jobPath && /^\/v1\/studies\//.test(longPath));
  await shot('02-running.png');
  await (await page.$('#job')).screenshot({ path: path.join(artifacts, '02b-progress.png') });
  await page.click('#job-cancel');
  await page.waitForSelector('#job-state[data-state=cancelled]');
  const cancelled = (await apiJson('GET', longPath)).json;
  check('cancel: the API says the job is cancelled', cancelled.state === 'cancelled', cancelled.state);
  check('cancel: the page says so in its live region', (await page.textContent('#job-status')).includes('Cancelled'));
  check('cancel: the button is disabled afterwards', await page.isDisabled('#job-cancel'));

  // ---- invalid fields: the API's message next to the field ------------------------------------
  await page.selectOption('#f-mode', 'linear');
  await page.fill('#f-samples', '1024');
  await page.fill('#f-pitch', '-2');
  const bad = { ...study.design, geometry: { ...study.design.geometry, pitch_mm: -2 } };
  const refused = await apiJson('POST', '/v1/designs/analyze', bad);
  const msg = refused.json.errors.find(e => e.pointer === '/geometry/pitch_mm').message;
  await page.waitForSelector('#f-pitch ~ .problems .problem-msg.error');
  check('live: the analysis\' message for a negative pitch shows next to the pitch field',
    await page.$eval('#f-pitch ~ .problems .problem-msg.error', e => e.dataset.text) === msg, msg);
  check('live: the pitch field is marked invalid and described by the message', await page.$eval('#f-pitch', e => e.getAttribute('aria-invalid') === 'true'
    && e.getAttribute('aria-describedby').split(' ').some(id => document.getElementById(id).textContent === e.parentElement.querySelector('.problem-msg').textContent)));
  check('live: the derived values say the design is invalid', (await page.textContent('#derived-status')).includes(msg));
  // a tolerance problem too, then submit: the study endpoint's problems go to their fields
  await page.fill('#tolerances tbody tr:nth-child(2) input[data-key=tol]', '-1');
  const badStudy = await page.evaluate(() => window.prsm.form.toRequest());
  const refusedStudy = await apiJson('POST', '/v1/studies', badStudy);
  check('the service refuses the invalid study (422)', refusedStudy.status === 422, String(refusedStudy.status));
  await page.click('#submit');
  await page.waitForSelector('#error-summary:not([hidden])');
  const errs = refusedStudy.json.errors;
  const pitchErr = errs.find(e => e.pointer === '/design/geometry/pitch_mm');
  const tolErr = errs.find(e => e.pointer === '/tolerances/1/tol_um');
  check('submit: the study\'s pitch problem is next to the pitch field', !!pitchErr && await page.$$eval('#f-pitch ~ .problems .problem-msg.error', (ms, m) => ms.some(x => x.dataset.text === m), pitchErr.message));
  check('submit: the tolerance problem is next to that row\'s tolerance field', !!tolErr && await page.$$eval('#tolerances tbody tr:nth-child(2) td.params .problems .problem-msg.error', (ms, m) => ms.some(x => x.dataset.text === m), tolErr.message));
  const summary = await page.textContent('#error-summary');
  check('submit: the error summary lists every problem with its pointer', errs.every(e => summary.includes(`${e.pointer}: ${e.message}`)), summary);
  check('submit: focus moves to the error summary', await page.evaluate(() => document.activeElement && document.activeElement.id === 'error-summary'));
  await shot('04-invalid.png');
  await page.screenshot({ path: path.join(artifacts, '04b-invalid-top.png') });
  // fixing the field clears its submit problem
  await page.fill('#f-pitch', '2');
  await page.waitForFunction(() => !document.querySelector('#f-pitch ~ .problems .problem-msg.error'));
  check('fixing the pitch clears its problems', true);
}

main().then(() => {
  log(`${passes} passed, ${failures} failed; screenshots in ${artifacts}`);
  process.exit(failures ? 1 : 0);
}).catch(e => {
  console.error(`run.mjs: ${e.stack || e}`);
  process.exit(1);
});
