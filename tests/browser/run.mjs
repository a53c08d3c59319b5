#!/usr/bin/env node
// Browser test of the web form (web/) in real headless Chromium (Debian's /usr/bin/chromium) driven
// by playwright-core. Starts `prsm serve` itself on 127.0.0.1 (a free port, a temporary database),
// loads the page, loads an example, submits a small study, waits for the result and checks that the
// plots and numbers are there and agree with the API's JSON fetched directly, checks the export,
// cancel and that an invalid field shows the API's message next to that field; the study name
// (typed, sent, labelling the result, the job and the recent jobs with kind, state and time), the
// derived C_0a, static safety and torques with their units, the import of one's own file (file input
// and drag and drop; wrong kinds, broken JSON and a design the service refuses); then, when the
// service's openapi lists them, the optimisation view (a Pareto sweep: the front's SVG points and a
// clicked point's design against the API, its legend with the selected point, an objective's small
// span drawn at least 2 % of its value wide and said so, the best design, cancel), the allocation view (case A
// and LS-1: the tables and charts against the API, cancel) and the simulation view (seed 000's
// two-stage start-up: both carriers' curves, the settled table and the checks against the API, the
// CSV download against `prsm simulate --csv` and samples.csv, the JSON download, a refused request's
// problem at its field, cancel), or prints "SKIPPED ..." for a view the service does not serve. Throughout: Tab order and focus rings, Chromium's accessibility tree (every
// control, link, chart and progress bar named, every chart described), text contrast computed in
// the page, nothing wider than a 1366 x 768 laptop screen (viewport screenshots of the form and the
// results). Then a second server with --token-file: the 401 points at the page's API token field,
// with the token a study runs and cancels, the token stays out of exports and localStorage. Saves
// screenshots, and stops the servers.
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
async function startServer(dbDir, extra = []) {
  const env = { ...process.env };
  delete env.PRSM_TOKEN; // the first server takes no token; the second one gets --token-file
  const child = spawn(path.resolve(args.prsm), ['serve', '--host', '127.0.0.1', '--port', '0', '--db', path.join(dbDir, 'prsm.db'),
    '--data-dir', source, '--workers', '1', ...extra], { stdio: ['ignore', 'pipe', 'pipe'], env });
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
    if (ex.kind === 'calibration') { calibrationExampleIsV6(ex.file); continue; }
    const a = path.join(source, 'web/examples', ex.file), b = path.join(source, 'studies', ex.file);
    check(`web/examples/${ex.file} is identical to studies/${ex.file}`, fs.existsSync(a) && fs.existsSync(b) && fs.readFileSync(a).equals(fs.readFileSync(b)));
  }
  const listed = new Set(manifest.examples.map(e => e.file).concat('index.json'));
  for (const f of fs.readdirSync(path.join(source, 'web/examples'))) check(`web/examples/${f} is listed in index.json`, listed.has(f));
  return manifest;
}

// A page on a laptop screen (1366 x 768) that may talk to `origin` only; external requests and
// page errors are collected for the checks at the end.
async function openPage(browser, origin) {
  const context = await browser.newContext({ viewport: { width: 1366, height: 768 }, deviceScaleFactor: 1 });
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
  return { context, page, external, pageErrors };
}

async function main() {
  examplesAreCopies();
  const entry = ensurePlaywright();
  const { chromium } = await import(pathToFileURL(entry).href);
  const dbDir = fs.mkdtempSync(path.join(os.tmpdir(), 'prsm-browser-'));
  const servers = [];
  let browser;
  try {
    const first = await startServer(dbDir);
    servers.push(first.child);
    ORIGIN = first.origin;
    log(`prsm serve at ${ORIGIN}`);
    browser = await chromium.launch({ executablePath: chromiumPath, headless: true, args: ['--no-sandbox', '--disable-gpu', '--disable-dev-shm-usage'] });
    const a = await openPage(browser, ORIGIN);
    await run(a.page);
    check('no request left the server (everything served by prsm serve)', a.external.length === 0, a.external.join(', '));
    check('no JavaScript errors in the page', a.pageErrors.length === 0, a.pageErrors.join(' | '));
    await a.context.close();

    // a second server that wants a bearer token for POST and DELETE (--token-file)
    const token = `prsm-test-${process.pid}-${Date.now().toString(36)}`;
    const tokenDir = path.join(dbDir, 'token');
    fs.mkdirSync(tokenDir);
    const tokenFile = path.join(tokenDir, 'token.txt');
    fs.writeFileSync(tokenFile, `${token}\n`, { mode: 0o600 });
    const second = await startServer(tokenDir, ['--token-file', tokenFile]);
    servers.push(second.child);
    log(`prsm serve --token-file at ${second.origin}`);
    const b = await openPage(browser, second.origin);
    const saved = ORIGIN;
    ORIGIN = second.origin;
    try { await tokenRun(b.page, token); } finally { ORIGIN = saved; }
    check('token server: no request left the server', b.external.length === 0, b.external.join(', '));
    check('token server: no JavaScript errors in the page', b.pageErrors.length === 0, b.pageErrors.join(' | '));
    await b.context.close();
  } finally {
    if (browser) await browser.close();
    for (const child of servers) {
      const code = await stopServer(child);
      check('prsm serve stopped cleanly on SIGTERM', code === 0, String(code));
    }
    if (!args.keep) fs.rmSync(dbDir, { recursive: true, force: true });
  }
}

// ---- accessibility and layout checks, run in the page as it stands ------------------------------
// Chromium's own accessibility tree (CDP Accessibility.getFullAXTree: the names a screen reader
// gets): every control, link, image and progress bar that is not hidden has a name, and every
// image (the charts' <svg role="img">) a description.
const NAMED_ROLES = new Set(['textbox', 'spinbutton', 'combobox', 'listbox', 'checkbox', 'radio', 'switch', 'slider', 'searchbox',
  'button', 'link', 'img', 'image', 'progressbar', 'menuitem', 'tab']);
async function axTree(page) {
  const cdp = await page.context().newCDPSession(page);
  try {
    await cdp.send('Accessibility.enable');
    const { nodes } = await cdp.send('Accessibility.getFullAXTree');
    const describe = async n => {
      if (!n.backendDOMNodeId) return `(${n.role && n.role.value})`;
      try {
        const { node } = await cdp.send('DOM.describeNode', { backendNodeId: n.backendDOMNodeId });
        const attrs = Object.fromEntries((node.attributes || []).reduce((a, v, i, all) => (i % 2 ? a : a.concat([[v, all[i + 1]]])), []));
        return `${node.localName}${attrs.id ? `#${attrs.id}` : ''}${attrs.class ? `.${attrs.class.split(' ').join('.')}` : ''}`;
      } catch { return `(${n.role && n.role.value})`; }
    };
    const out = [];
    for (const n of nodes) {
      if (n.ignored) continue;
      const role = n.role && n.role.value;
      const props = Object.fromEntries((n.properties || []).map(p => [p.name, p.value && p.value.value]));
      out.push({ role, name: (n.name && n.name.value) || '', description: (n.description && n.description.value) || '', value: n.value && n.value.value, props, node: n });
    }
    for (const x of out) x.where = NAMED_ROLES.has(x.role) && (!x.name.trim() || ((x.role === 'img' || x.role === 'image') && !x.description.trim())) ? await describe(x.node) : '';
    return out;
  } finally {
    await cdp.detach();
  }
}
async function a11yAudit(page, where) {
  const tree = await axTree(page);
  const controls = tree.filter(x => NAMED_ROLES.has(x.role));
  const unnamed = controls.filter(x => !x.name.trim());
  check(`${where}: every control, link, chart and progress bar has an accessible name (${controls.length} in the accessibility tree)`, controls.length > 0 && unnamed.length === 0,
    unnamed.map(x => `${x.role} ${x.where}`).join(', '));
  const images = tree.filter(x => x.role === 'img' || x.role === 'image');
  const undescribed = images.filter(x => !x.description.trim());
  check(`${where}: every chart (${images.length}) has a description`, undescribed.length === 0, undescribed.map(x => x.where).join(', '));
  // the same from the DOM: every chart is an <svg role="img"> (a scatter of point buttons: role="group")
  // named by its <title> and described by its <desc>; no positive tabindex (Tab follows the page)
  const dom = await page.evaluate(() => {
    const text = ids => (ids || '').split(/\s+/).filter(Boolean).map(id => (document.getElementById(id) || {}).textContent || '').join(' ').trim();
    const svgs = [...document.querySelectorAll('svg')].filter(s => s.getClientRects().length);
    return {
      svgs: svgs.length,
      bad: svgs.filter(s => !(s.getAttribute('role') === 'img' || (s.getAttribute('role') === 'group' && s.querySelector('[role=button]')))
        || !text(s.getAttribute('aria-labelledby')) || !text(s.getAttribute('aria-describedby'))
        || s.querySelector(`:scope > title`) !== document.getElementById(s.getAttribute('aria-labelledby'))).map(s => s.id || s.getAttribute('class')),
      tabindex: [...document.querySelectorAll('[tabindex]')].filter(e => Number(e.getAttribute('tabindex')) > 0).map(e => e.id || e.tagName),
      fakeButtons: [...document.querySelectorAll('[role=button]')].filter(e => e.tagName !== 'circle' && e.tagName !== 'BUTTON').map(e => e.id || e.tagName),
    };
  });
  check(`${where}: every chart (${dom.svgs}) is an <svg role="img"> (or a group of point buttons) with a <title> naming it and a <desc>`, dom.bad.length === 0, dom.bad.join(', '));
  check(`${where}: no positive tabindex, and buttons are <button> (besides the charts' point buttons)`, !dom.tabindex.length && !dom.fakeButtons.length,
    dom.tabindex.concat(dom.fakeButtons).join(', '));
  return tree;
}

// Text contrast as WCAG 2.x computes it, for every visible text in the page (HTML text by its
// colour, SVG text by its fill) against the background it sits on (ancestors' background colours
// blended over white, the opacity of the ancestors applied): 4.5:1, or 3:1 for large text.
async function contrastAudit(page, where) {
  const r = await page.evaluate(() => {
    const rgba = c => {
      const m = /rgba?\(([^)]+)\)/.exec(c || '');
      if (!m) return null;
      const p = m[1].split(/[\s,/]+/).filter(Boolean).map(Number);
      return [p[0], p[1], p[2], p.length > 3 ? p[3] : 1];
    };
    const over = (top, under) => [0, 1, 2].map(i => top[3] * top[i] + (1 - top[3]) * under[i]).concat(1);
    const lum = c => {
      const f = v => { v /= 255; return v <= 0.03928 ? v / 12.92 : ((v + 0.055) / 1.055) ** 2.4; };
      return 0.2126 * f(c[0]) + 0.7152 * f(c[1]) + 0.0722 * f(c[2]);
    };
    const ratio = (a, b) => { const [x, y] = [lum(a), lum(b)].sort((p, q) => q - p); return (x + 0.05) / (y + 0.05); };
    const background = el => {
      const layers = [];
      for (let e = el; e && e.nodeType === 1; e = e.parentElement) {
        const c = rgba(getComputedStyle(e).backgroundColor);
        if (c && c[3] > 0) { layers.push(c); if (c[3] >= 1) break; }
      }
      return layers.reverse().reduce((acc, c) => over(c, acc), [255, 255, 255, 1]);
    };
    const opacity = el => { let o = 1; for (let e = el; e && e.nodeType === 1; e = e.parentElement) o *= Number(getComputedStyle(e).opacity); return o; };
    const seen = [], low = [];
    for (const el of document.querySelectorAll('body *')) {
      if (['SCRIPT', 'STYLE', 'OPTION', 'title', 'desc', 'NOSCRIPT'].includes(el.tagName)) continue;
      if (![...el.childNodes].some(n => n.nodeType === 3 && n.textContent.trim())) continue;
      if (!el.getClientRects().length || el.closest('[hidden], .visually-hidden, title, desc')) continue;
      const cs = getComputedStyle(el);
      if (cs.visibility !== 'visible' || cs.display === 'none') continue;
      if (el.matches(':disabled') || el.closest('button:disabled')) continue; // WCAG: inactive controls are exempt (ours pass anyway)
      const svgText = el instanceof SVGElement;
      let fg = rgba(svgText ? cs.fill : cs.color);
      if (!fg) continue;
      const bg = background(svgText ? el.closest('svg').parentElement : el);
      fg = over([fg[0], fg[1], fg[2], fg[3] * opacity(el)], bg);
      const size = parseFloat(cs.fontSize), bold = Number(cs.fontWeight) >= 700;
      const need = size >= 24 || (bold && size >= 18.66) ? 3 : 4.5;
      const r = ratio(fg, bg);
      seen.push(r);
      if (r < need) low.push(`${el.tagName.toLowerCase()}${el.id ? `#${el.id}` : ''}${el.getAttribute('class') ? `.${el.getAttribute('class').split(' ').join('.')}` : ''} "${el.textContent.trim().slice(0, 30)}" ${r.toFixed(2)} < ${need}`);
    }
    return { n: seen.length, min: Math.min(...seen), low };
  });
  check(`${where}: text contrast at least 4.5:1 (3:1 large) for all ${r.n} visible texts (lowest ${r.min.toFixed(2)})`, r.n > 0 && r.low.length === 0, r.low.slice(0, 8).join('; '));
}

// Nothing wider than a 1366 px laptop screen: no horizontal scrolling of the page, and no card,
// fieldset or panel whose content spills out sideways.
async function layoutAudit(page, where) {
  const r = await page.evaluate(() => ({
    page: [document.documentElement.scrollWidth, window.innerWidth],
    spill: [...document.querySelectorAll('main section, .card, fieldset, aside, .figure-row, .table-box, .plot-box, header.top, .actions, .controls')]
      .filter(e => e.getClientRects().length && getComputedStyle(e).overflowX === 'visible' && e.scrollWidth > e.clientWidth + 1)
      .map(e => `${e.tagName.toLowerCase()}${e.id ? `#${e.id}` : ''}.${e.className} ${e.scrollWidth}>${e.clientWidth}`),
  }));
  check(`${where}: fits a ${r.page[1]} px wide screen (no horizontal scrolling, nothing spilling out of its box)`, r.page[0] <= r.page[1] && r.spill.length === 0,
    `page ${r.page[0]}; ${r.spill.slice(0, 6).join('; ')}`);
}

// A viewport screenshot (what a 1366 x 768 laptop shows) with `sel` at the top.
async function laptopShot(page, name, sel) {
  await page.evaluate(s => { if (s) document.querySelector(s).scrollIntoView({ block: 'start' }); else window.scrollTo(0, 0); }, sel || null);
  await page.screenshot({ path: path.join(artifacts, name), fullPage: false });
}

// ---- the page ----------------------------------------------------------------------------------
async function run(page) {
  const shot = async name => { await page.screenshot({ path: path.join(artifacts, name), fullPage: true }); };
  await page.goto(ORIGIN + '/');
  await page.waitForSelector('body[data-ready=true]');
  await page.waitForSelector('#derived-list dd[data-key=nut_radius_mm]');
  log('page loaded');

  // keyboard: Tab from the top of the page visits the skip link, the navigation, the token field, the
  // examples and the form's fields in document order, each stop on screen with a visible focus ring
  const stops = [];
  for (let i = 0; i < 40; i++) {
    await page.keyboard.press('Tab');
    stops.push(await page.evaluate(() => {
      const e = document.activeElement, cs = getComputedStyle(e), r = e.getBoundingClientRect();
      return { id: e.id || e.dataset.example || e.getAttribute('href') || e.tagName, pos: [...document.querySelectorAll('*')].indexOf(e),
        ring: cs.outlineStyle !== 'none' && parseFloat(cs.outlineWidth) >= 2, onScreen: r.width > 0 && r.height > 0 && r.top >= 0 && r.bottom <= innerHeight && r.left >= 0 && r.right <= innerWidth };
    }));
  }
  const order = stops.map(x => x.id);
  check('Tab follows the document order', stops.every((x, i) => i === 0 || x.pos > stops[i - 1].pos), order.join(' '));
  check('Tab reaches the skip link first, then the navigation, the API token, the examples and the design fields', order[0] === '#study-form'
    && order.indexOf('api-token') > order.indexOf('#api') && order.indexOf('case-a-tolerances.json') > order.indexOf('api-token')
    && order.indexOf('f-name') > order.indexOf('case-a-tolerances.json') && order.indexOf('f-starts') === order.indexOf('f-name') + 1, order.join(' '));
  const noRing = stops.filter(x => !x.ring || !x.onScreen).map(x => x.id);
  check('every Tab stop is on screen with a visible focus ring (outline of 2 px or more)', noRing.length === 0, noRing.join(' '));
  await page.evaluate(() => document.activeElement.blur());

  // every control has an accessible name (Chromium's accessibility tree), the charts and the text
  // contrast, the layout on a laptop screen
  await a11yAudit(page, 'form');
  await contrastAudit(page, 'form');
  await layoutAudit(page, 'form');
  check('progress is a labelled <progress> (role progressbar, 0 to 1) with an aria-live status beside it', await page.$eval('#job-status', e => e.getAttribute('aria-live') === 'polite' && e.getAttribute('role') === 'status')
    && await page.$eval('#job-progress', e => e.tagName === 'PROGRESS' && e.max === 1 && e.labels.length === 1));
  check('the API token field is a labelled password field, empty at first', await page.$eval('#api-token', e => e.type === 'password' && e.labels.length === 1 && e.value === ''));
  await laptopShot(page, '10-laptop-form.png');

  // an example with one keyboard action
  const study = JSON.parse(fs.readFileSync(path.join(source, 'studies/case-a-tolerances.json'), 'utf8'));
  const caseADesign = JSON.parse(fs.readFileSync(path.join(source, 'studies/case-a.json'), 'utf8'));
  check('the study name is an editable, labelled field holding the loaded study\'s name', await page.$eval('#f-study-name', e => e.labels.length === 1 && !e.disabled && !e.readOnly)
    && await page.inputValue('#f-study-name') === study.name, await page.inputValue('#f-study-name'));
  await page.focus('#examples button[data-example="case-a.json"]');
  await page.keyboard.press('Enter');
  await page.waitForFunction(() => document.querySelector('#examples-note').textContent.includes('case-a.json'));
  check('loading a design names the study after it (not after the previous example)', await page.inputValue('#f-study-name') === `Tolerance study of ${caseADesign.name}`
    && (await page.evaluate(() => window.prsm.form.toRequest().name)) === `Tolerance study of ${caseADesign.name}`, await page.inputValue('#f-study-name'));
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
  // static rating, static safety and torque, with their units
  // (read in one evaluation: a re-render between a query and its callback would detach the rows)
  const shownRows = await page.evaluate(() => Object.fromEntries([...document.querySelectorAll('#derived-list dd')]
    .map(d => [d.dataset.key, { label: d.previousElementSibling ? d.previousElementSibling.textContent : '', text: d.textContent }])));
  for (const [key, want, label, unitRe] of [
    ['C0a', analysis.capacity.static.C0a_N, /C_0a/, / N$/],
    ['static_safety', analysis.capacity.static.safety_factor, /static safety C_0a \/ F/i, /^[\d.]+$/],
    ['input_torque_Nm', analysis.efficiency.torque_Nm.input, /input torque/i, / N·m$/],
    ['back_driving_torque_Nm', analysis.efficiency.back_driving_output_torque_Nm, /back-driving torque/i, / N·m$/]]) {
    const r = shownRows[key];
    check(`derived ${key} = ${want} as the API says, labelled with its unit`, typeof want === 'number' && derived[key] === want && !!r && label.test(r.label) && unitRe.test(r.text)
      && near(Number(r.text.replace('−', '-').replace(/ N(·m)?$/, '')), want, 5e-4), r ? `${r.label} = ${r.text}` : 'missing');
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

  // a study submitted elsewhere (not from this page): the recent jobs name it from its result
  const elsewhereName = 'Submitted with curl: case A, 256 samples';
  const elsewhere = await apiJson('POST', '/v1/studies', { ...study, name: elsewhereName, monte_carlo: { ...study.monte_carlo, samples: 256, targets: undefined }, sensitivity: { src: false, stack: false } });
  check('a study submitted outside the page is accepted', elsewhere.status === 202 || elsewhere.status === 200, `${elsewhere.status} ${elsewhere.text.slice(0, 200)}`);

  // ---- a small study: submit, wait, check against the API ----------------------------------
  // the study name is typed by the user: it goes into the request and labels the result
  const studyName = 'Browser test: my own screw, 1024 samples';
  await page.fill('#f-study-name', studyName);
  check('the typed study name is in the document sent', (await page.evaluate(() => window.prsm.form.toRequest().name)) === studyName);
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
  check('the service ran the study under the typed name (result.name)', result.name === studyName, result.name);
  check('the result is labelled with the typed study name (heading and title line) and its design\'s name', await page.textContent('#result-name') === studyName
    && await page.textContent('#results-h') === `Results: ${studyName}` && (await page.textContent('#result-title')).includes(`design: ${study.design.name}`)
    && !(await page.textContent('#result-title')).includes(study.name),
    `${await page.textContent('#result-title')} | ${await page.textContent('#results-h')}`);
  check('the job view shows the study name', await page.textContent('#job-name') === studyName, await page.textContent('#job-name'));
  // recent jobs: name, kind, state and time, the id second
  const jobId = jobPath.split('/').pop();
  await page.waitForSelector(`#recent-list li[data-id="${jobId}"][data-state=done]`);
  const recent = await page.$eval(`#recent-list li[data-id="${jobId}"]`, li => ({ name: li.querySelector('a .job-name').textContent, href: li.querySelector('a').getAttribute('href'),
    kind: li.querySelector('.job-kind').textContent, state: li.querySelector('.job-state').textContent, time: li.querySelector('time').getAttribute('datetime'),
    timeText: li.querySelector('time').textContent, id: li.querySelector('.job-id').textContent, text: li.textContent }));
  check('recent jobs: the study is listed by its name (the link), kind, state and time, the id after them', recent.name === studyName && recent.href === `#${jobPath}`
    && recent.kind === 'study' && recent.state === 'done' && recent.time === job.finished_at && recent.timeText.includes(job.finished_at.replace('T', ' ').slice(0, 19))
    && recent.id === jobId.slice(0, 12) && recent.text.indexOf(recent.id) > recent.text.indexOf(recent.timeText), JSON.stringify(recent));
  const otherId = elsewhere.json && elsewhere.json.id;
  const otherNamed = await page.waitForSelector(`#recent-list li[data-id="${otherId}"][data-name="${elsewhereName}"]`, { timeout: 15000 }).then(() => true, () => false);
  check('recent jobs: a study submitted elsewhere is named from its result', otherNamed && (await page.textContent(`#recent-list li[data-id="${otherId}"] .job-name`)) === elsewhereName,
    otherId && await page.$eval(`#recent-list li[data-id="${otherId}"]`, li => li.textContent).catch(() => 'not listed'));
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
    if (o.stack) {
      const cav = cells.stack_caveat;
      check(`${name}: the stack caveat shown exactly when the API gives one`, o.stack.caveat ? cav && cav.text === o.stack.caveat : !cav,
        cav ? cav.text : 'none');
    }
  }
  check('some output carries a stack caveat (load sharing cannot fall below 1)', outputs.some(n => result.outputs[n].stack && result.outputs[n].stack.caveat));
  await shot('03-results.png');
  await page.waitForSelector('#te-plot');
  await a11yAudit(page, 'results');
  await contrastAudit(page, 'results');
  await layoutAudit(page, 'results');
  await laptopShot(page, '11-laptop-job.png', '#job');
  await laptopShot(page, '12-laptop-results.png', '#output-cards');
  await laptopShot(page, '13-laptop-tornado.png', '#tornado-card');

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
  const bar = (await axTree(page)).find(x => x.role === 'progressbar');
  check('while running, the progress bar is a progressbar from 0 to 1 with its value, described by the samples done and planned', bar && bar.name === 'Progress'
    && Number(bar.props.valuemin) === 0 && Number(bar.props.valuemax) === 1 && Number(bar.value) > 0 && /^Samples — Monte Carlo run [\d,]+ of 200,000/.test(bar.description), JSON.stringify(bar && bar.node));
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

  await importChecks(page, study, result);

  // ---- the optimisation and allocation views, when the service has them --------------------
  const openapi = (await apiJson('GET', '/v1/openapi.json')).json;
  for (const [collection, section, fn] of [['optimizations', '#optimization', optimisationView], ['allocations', '#allocation', allocationView],
    ['simulations', '#simulation', simulationView], ['calibrations', '#calibration', calibrationView]]) {
    const served = !!openapi.paths[`/v1/${collection}`];
    check(`the ${section.slice(1)} view is shown exactly when openapi lists /v1/${collection}`, served === await page.isVisible(section));
    if (served) await fn(page, shot);
    else console.log(`SKIPPED ${{ '#optimization': 'optimisation', '#allocation': 'allocation', '#simulation': 'simulation', '#calibration': 'calibration' }[section]} view: /v1/${collection} not served`);
  }
}

// ---- import of one's own file: file input and drag and drop; wrong kinds and bad JSON refused ----
async function importChecks(page, study, studyResult) {
  log('import');
  const formDoc = () => page.evaluate(() => window.prsm.form.toRequest());
  const upload = async (name, text) => {
    await page.setInputFiles('#import-file', { name, mimeType: 'application/json', buffer: Buffer.from(text) });
  };
  // waits for the import's final word: 'ok', 'error' (refused, or the service refuses the design)
  const settled = async () => {
    await page.waitForSelector('#import-msg:not([hidden]):not([data-state=checking])');
    return { state: await page.getAttribute('#import-msg', 'data-state'), text: await page.textContent('#import-msg') };
  };
  const fresh = async () => page.evaluate(() => { const m = document.querySelector('#import-msg'); m.hidden = true; delete m.dataset.state; });

  // a study of one's own, from the file input: the form holds exactly that document
  const mine = JSON.parse(JSON.stringify(study));
  mine.name = 'Imported from my-study.json';
  mine.design.name = 'My own 5-start screw';
  mine.design.geometry.rollers = 9;
  mine.tolerances = mine.tolerances.slice(0, 3);
  mine.monte_carlo.samples = 2048;
  await fresh();
  await upload('my-study.json', JSON.stringify(mine, null, 2));
  let msg = await settled();
  const got = await formDoc();
  check('import (file input): a study file fills the form with exactly that document', msg.state === 'ok' && canonical(got) === canonical(mine), `${msg.state}: ${msg.text} | ${JSON.stringify(got).slice(0, 200)}`);
  check('import: the fields show it (study name, design name, rollers, tolerance rows)', await page.inputValue('#f-study-name') === mine.name && await page.inputValue('#f-name') === mine.design.name
    && await page.inputValue('#f-z') === '9' && await page.$$eval('#tolerances tbody tr', r => r.length) === 3);
  check('import: the message says what was loaded and what the service says of its design', msg.text.includes('my-study.json') && msg.text.includes('a study')
    && msg.text.includes('POST /v1/designs/analyze') && msg.text.includes('accepts its design'), msg.text);

  // a design file dropped on the form: the design is replaced, tolerances and settings kept, and the
  // study, named by the user, keeps that name
  const large = fs.readFileSync(path.join(source, 'studies/large-6start.json'), 'utf8');
  const before = await formDoc();
  await fresh();
  const dropped = await page.evaluate(([text, name]) => {
    const dt = new DataTransfer();
    dt.items.add(new File([text], name, { type: 'application/json' }));
    const target = document.querySelector('#study-form');
    const over = new DragEvent('dragover', { dataTransfer: dt, bubbles: true, cancelable: true });
    target.dispatchEvent(over);
    const highlighted = document.querySelector('#study-layout').classList.contains('dragging');
    const drop = new DragEvent('drop', { dataTransfer: dt, bubbles: true, cancelable: true });
    target.dispatchEvent(drop);
    return { accepted: over.defaultPrevented && drop.defaultPrevented, highlighted, after: document.querySelector('#study-layout').classList.contains('dragging') };
  }, [large, 'large-6start.json']);
  msg = await settled();
  const afterDrop = await formDoc();
  check('import (drag and drop on the form): the drop is taken and the form is highlighted while dragging', dropped.accepted && dropped.highlighted && !dropped.after, JSON.stringify(dropped));
  check('import (drag and drop): a design file replaces the design, the tolerances and settings are kept', msg.state === 'ok'
    && canonical(afterDrop.design) === canonical(JSON.parse(large)) && canonical(afterDrop.tolerances) === canonical(before.tolerances)
    && canonical(afterDrop.monte_carlo) === canonical(before.monte_carlo), `${msg.state}: ${msg.text}`);
  check('import: a design into an imported study follows the design\'s name (the study name was not typed)', afterDrop.name === `Tolerance study of ${JSON.parse(large).name}`, afterDrop.name);
  // a typed study name is kept when another design comes in
  await page.fill('#f-study-name', 'My name, typed');
  await fresh();
  await upload('case-a.json', fs.readFileSync(path.join(source, 'studies/case-a.json'), 'utf8'));
  msg = await settled();
  check('import: a study name typed by the user is kept when a design is imported', msg.state === 'ok' && (await formDoc()).name === 'My name, typed' && msg.text.includes('kept'), msg.text);

  // refused: the wrong kind of document, not JSON, a result; the form stays as it was
  const kept = await formDoc();
  const refusedImport = async (name, text, want, what) => {
    await fresh();
    await upload(name, text);
    const m = await settled();
    const same = canonical(await formDoc()) === canonical(kept);
    check(`import: ${what} is refused with a clear message, the form unchanged`, m.state === 'error' && m.text.startsWith(`Not loaded: ${name}`) && want.every(w => (w instanceof RegExp ? w.test(m.text) : m.text.includes(w))) && same,
      `${m.state}: ${m.text}${same ? '' : ' (the form changed)'}`);
  };
  await refusedImport('optimize-case-a-pareto.json', fs.readFileSync(path.join(source, 'studies/optimize-case-a-pareto.json'), 'utf8'), ['an optimisation request', 'optimisation view'], 'an optimisation request (the wrong kind)');
  await refusedImport('allocate-case-a.json', fs.readFileSync(path.join(source, 'studies/allocate-case-a.json'), 'utf8'), ['allocation request'], 'an allocation request');
  await refusedImport('result.json', JSON.stringify(studyResult), ['a study result', 'not a study request'], 'a study result');
  await refusedImport('broken.json', '{\n  "name": "half a study",\n  "tolerances": [,]\n}\n', ['is not valid JSON', /line 3/], 'a file that is not valid JSON (with the line)');
  await refusedImport('list.json', '[1, 2, 3]', ['an array, not a JSON object'], 'a JSON array');
  await refusedImport('other.json', '{"hello": "world"}', ['"tolerances"', '"geometry"', '"hello"'], 'an object that is neither a study nor a design');
  check('import: a refusal is shown as an error', await page.$eval('#import-msg', e => e.classList.contains('error')));

  // a design the service refuses: loaded, and the service's own message shown (and at the field)
  const badDesign = { ...JSON.parse(large), geometry: { ...JSON.parse(large).geometry, pitch_mm: -3 } };
  const apiSays = (await apiJson('POST', '/v1/designs/analyze', badDesign)).json.errors.find(e => e.pointer === '/geometry/pitch_mm');
  await fresh();
  await upload('bad-pitch.json', JSON.stringify(badDesign));
  msg = await settled();
  check('import: a design the service refuses is loaded with the service\'s message, listed with its pointer', !!apiSays && msg.state === 'error' && msg.text.includes('refuses its design')
    && msg.text.includes(`/design/geometry/pitch_mm: ${apiSays.message}`) && await page.inputValue('#f-pitch') === '-3', msg.text);
  check('import: the typed study name is still kept at the second design imported', await page.inputValue('#f-study-name') === 'My name, typed', await page.inputValue('#f-study-name'));
  await page.waitForSelector('#f-pitch ~ .problems .problem-msg.error');
  check('import: the refused design\'s problem is next to its field', await page.$$eval('#f-pitch ~ .problems .problem-msg.error', (ms, m) => ms.some(x => x.dataset.text === m), apiSays && apiSays.message));
  await page.locator('#import').screenshot({ path: path.join(artifacts, '08-import-refused.png') });

  // back to the example for what follows
  await page.click('#examples button[data-example="case-a-tolerances.json"]');
  await page.waitForFunction(() => document.querySelector('#examples-note').textContent.includes('case-a-tolerances.json'));
  await page.waitForFunction(() => !document.querySelector('#f-pitch ~ .problems .problem-msg.error'));
  check('after the imports the example loads again unchanged', canonical(await formDoc()) === canonical(study));
}

// ---- a service that wants a bearer token: the 401 points at the token field, the token works ----
async function tokenRun(page, token) {
  log('token server');
  const writes = [], reads = [];
  page.on('request', req => {
    if (!req.url().startsWith(`${ORIGIN}/v1/`)) return;
    const auth = req.headers().authorization || null;
    (req.method() === 'POST' || req.method() === 'DELETE' ? writes : reads).push({ method: req.method(), url: req.url(), auth });
  });
  const direct = await apiJson('POST', '/v1/studies', {});
  check('token server: a POST without the token is 401 with WWW-Authenticate', direct.status === 401 && /^Bearer/.test(direct.headers.get('www-authenticate') || ''), `${direct.status}`);
  await page.goto(ORIGIN + '/');
  await page.waitForSelector('body[data-ready=true]');

  // no token: the page's first POST (the live analysis) is refused, and the token field says so
  await page.waitForSelector('#api-token-msg:not([hidden])');
  check('without a token: the token field shows the 401 message and is marked invalid', await page.$eval('#api-token', e => e.getAttribute('aria-invalid') === 'true'
    && e.getAttribute('aria-describedby').split(' ').includes('api-token-msg')) && (await page.textContent('#api-token-msg')).includes('needs an API token'), await page.textContent('#api-token-msg'));
  await page.waitForFunction(() => document.querySelector('#derived-status').textContent.includes('API token'));
  check('without a token: the derived values say the analysis needs the token (nothing put on the design fields)', await page.$$eval('#study-form .problem-msg', m => m.length) === 0);
  await page.fill('#f-samples', '512');
  await page.uncheck('#f-sobol');
  await page.click('#submit');
  await page.waitForSelector('#error-summary:not([hidden])');
  const summary = await page.textContent('#error-summary');
  check('without a token: submitting shows a clear 401 message pointing at the token field', summary.includes('The service needs an API token') && summary.includes('“API token” field'), summary);
  check('without a token: focus moves to the message', await page.evaluate(() => document.activeElement.id === 'error-summary'));
  await page.click('#error-summary a');
  check('without a token: the message\'s link takes focus to the token field', await page.evaluate(() => document.activeElement.id === 'api-token'));
  if (await page.isVisible('#opt-submit')) {
    await page.waitForFunction(() => document.querySelector('#opt-request').value.length > 0);
    await page.click('#opt-submit');
    await page.waitForSelector('#opt-problems:not([hidden])');
    check('without a token: the optimisation view says the token is needed and links to the field', (await page.textContent('#opt-problems')).includes('needs an API token'));
    await page.click('#opt-problems a');
    check('without a token: the link focuses the token field', await page.evaluate(() => document.activeElement.id === 'api-token'));
  }
  await laptopShot(page, '16-token-needed.png');
  await a11yAudit(page, 'token needed');
  await contrastAudit(page, 'token needed');

  // a wrong token: refused, and the page says the token was refused
  await page.fill('#api-token', 'not-the-token');
  await page.waitForFunction(() => document.querySelector('#api-token-msg').textContent.includes('refused'));
  await page.click('#submit');
  await page.waitForFunction(() => document.querySelector('#error-summary').textContent.includes('The API token was refused'));
  check('a wrong token: the page says the token was refused', (await page.textContent('#api-token-msg')).includes('refused this token')
    && (await page.textContent('#error-summary')).includes('refused the API token (401): check the “API token” field'));

  // the token: the analysis runs, the study is accepted and finishes
  await page.fill('#api-token', token);
  await page.waitForFunction(() => document.querySelector('#derived-status').textContent.startsWith('Design analysed'));
  check('with the token: the message goes and the field is valid again', await page.isHidden('#api-token-msg') && await page.$eval('#api-token', e => !e.hasAttribute('aria-invalid')));
  const firstWrite = writes.length;
  await page.click('#submit');
  await page.waitForSelector('#job-state[data-state=done]', { timeout: 45000 });
  await page.waitForSelector('#output-cards .card.output');
  const jobPath = await page.evaluate(() => location.hash.slice(1));
  const job = (await apiJson('GET', jobPath)).json;
  check('with the token: the study is submitted and finishes', job && job.state === 'done' && job.result.samples.run === 512, job && job.state);
  check('with the token: the results are shown', await page.$$eval('#output-cards .card.output', c => c.length) === Object.keys(job.result.outputs).length);
  check('the token is sent as a bearer token with every POST after it was entered', writes.slice(firstWrite).length > 0
    && writes.slice(firstWrite).every(w => w.auth === `Bearer ${token}`), JSON.stringify(writes.slice(firstWrite).map(w => [w.method, w.auth && w.auth.slice(0, 12)])));
  check('no GET carries the token', reads.length > 0 && reads.every(r => r.auth === null));
  const stored = await page.evaluate(() => ({ session: sessionStorage.getItem('prsm.token'), local: JSON.stringify({ ...localStorage }), html: document.documentElement.outerHTML }));
  check('the token is kept in sessionStorage only (not in localStorage nor in the page\'s HTML)', stored.session === token && !stored.local.includes(token) && !stored.html.includes(token));

  // exports: never the token; the curl command takes it from $PRSM_TOKEN
  await page.click('#export-json');
  const exported = await page.inputValue('#export-text');
  check('the exported JSON has no token', !exported.includes(token) && !/authorization/i.test(exported));
  await page.click('#export-curl');
  const curlCmd = await page.inputValue('#export-text');
  check('the exported curl command sends "Authorization: Bearer $PRSM_TOKEN", not the token', curlCmd.includes('-H "Authorization: Bearer $PRSM_TOKEN"') && !curlCmd.includes(token), curlCmd.slice(0, 160));
  check('the export says where the curl command takes the token from', (await page.textContent('#export-note')).includes('PRSM_TOKEN') && await page.isVisible('#export-note'));
  if (spawnSync('sh', ['-c', 'command -v curl']).status === 0) {
    const withToken = spawnSync('sh', ['-c', curlCmd], { encoding: 'utf8', env: { ...process.env, PRSM_TOKEN: token } });
    check('the curl command runs with PRSM_TOKEN set (answered from the cache, same job)', withToken.status === 0 && /HTTP\/1\.1 200/.test(withToken.stdout) && withToken.stdout.includes(job.id), withToken.stderr || withToken.stdout.slice(0, 200));
    const env = { ...process.env };
    delete env.PRSM_TOKEN;
    const without = spawnSync('sh', ['-c', curlCmd], { encoding: 'utf8', env });
    check('the curl command without PRSM_TOKEN is refused (401)', /HTTP\/1\.1 401/.test(without.stdout), without.stdout.slice(0, 100));
  }
  await page.click('#export-close');

  // cancel (DELETE) needs the token too: refused without it, done with it
  await page.fill('#f-samples', '200000');
  await page.selectOption('#f-mode', 'exact');
  await page.click('#submit');
  await page.waitForFunction(p => location.hash.startsWith('#/v1/studies/') && location.hash !== `#${p}` && document.querySelector('#job-state').dataset.state === 'running', jobPath, { timeout: 20000 });
  const longPath = await page.evaluate(() => location.hash.slice(1));
  await page.fill('#api-token', '');
  check('clearing the field forgets the token', await page.evaluate(() => sessionStorage.getItem('prsm.token')) === null);
  await page.click('#job-cancel');
  await page.waitForSelector('#job-cancel-msg:not([hidden])');
  check('cancel without the token: refused, the message beside the button points at the token field', (await page.textContent('#job-cancel-msg')).startsWith('Cancel refused: The service needs an API token')
    && (await page.textContent('#job-cancel-msg')).includes('“API token” field') && await page.isVisible('#api-token-msg') && (await apiJson('GET', longPath)).json.state === 'running',
    await page.textContent('#job-cancel-msg'));
  await page.fill('#api-token', token);
  await page.waitForFunction(() => !document.querySelector('#job-cancel').disabled);
  await page.click('#job-cancel');
  await page.waitForSelector('#job-state[data-state=cancelled]');
  check('cancel with the token: the job is cancelled and the refusal goes', (await apiJson('GET', longPath)).json.state === 'cancelled' && await page.isHidden('#job-cancel-msg'));

  // a reload keeps the token (same tab)
  await page.reload();
  await page.waitForSelector('body[data-ready=true]');
  check('a reload keeps the token in the field (sessionStorage)', await page.inputValue('#api-token') === token);
  await page.waitForFunction(() => document.querySelector('#derived-status').textContent.startsWith('Design analysed'));
  check('after the reload the analysis runs with the token', await page.isHidden('#api-token-msg'));
}

// Loads an example of a view by keyboard and checks the editor holds exactly that document.
async function loadExample(page, view, file) {
  await page.focus(`${view} button[data-example="${file}"]`);
  await page.keyboard.press('Enter');
  const prefix = { '#optimization': 'opt', '#allocation': 'alloc', '#simulation': 'sim', '#calibration': 'cal' }[view];
  await page.waitForFunction(([id, f]) => document.getElementById(id).textContent.includes(f), [`${prefix}-note`, file]);
  const want = JSON.parse(fs.readFileSync(path.join(source, view === '#calibration' ? 'web/examples' : 'studies', file), 'utf8'));
  const got = JSON.parse(await page.inputValue(`#${prefix}-request`));
  check(`${file}: the example loads into the request editor unchanged`, canonical(got) === canonical(want));
  return want;
}
// A cancelled optimisation or allocation: its job document once the worker has attached the best
// result so far (or after 5 s without one).
async function cancelledJob(jobPath) {
  let job;
  for (let i = 0; i < 50; i++) {
    job = (await apiJson('GET', jobPath)).json;
    if (job.result) break;
    await new Promise(res => setTimeout(res, 100));
  }
  return job;
}
// Edits the request editor's JSON as a person would (the input event keeps the fields in step).
async function editRequest(page, id, change) {
  const doc = JSON.parse(await page.inputValue(id));
  change(doc);
  await page.fill(id, JSON.stringify(doc, null, 2));
  return doc;
}
// Waits until the page shows a finished job of the collection with its results, returns its JSON.
// notPath: the previous job's path (the hash must have moved on from it).
async function waitJob(page, collection, state, resultSel, timeout = 60000, notPath = '') {
  await page.waitForFunction(([c, st, sel, prev]) => location.hash.startsWith(`#/v1/${c}/`) && location.hash !== `#${prev}`
    && document.querySelector('#job-state').dataset.state === st && (!sel || document.querySelector(sel)), [collection, state, resultSel, notPath], { timeout });
  const jobPath = await page.evaluate(() => location.hash.slice(1));
  return { jobPath, job: (await apiJson('GET', jobPath)).json };
}

// ---- optimisation: a Pareto sweep, its front against the API, a point's design, cancel ------------
async function optimisationView(page, shot) {
  log('optimisation view');
  check('the optimisation view is in the navigation', await page.isVisible('#nav-optimization'));
  const example = await loadExample(page, '#optimization', 'optimize-case-a-pareto.json');
  check('the solver fields show the example\'s settings', await page.inputValue('#opt-f-solver-max_evaluations') === String(example.solver.max_evaluations)
    && await page.inputValue('#opt-f-multi_objective-points') === String(example.multi_objective.points));

  // a problem of the API next to the field that edits that member
  await page.fill('#opt-f-solver-max_evaluations', '0');
  const bad = JSON.parse(await page.inputValue('#opt-request'));
  check('a field writes its member into the request', bad.solver.max_evaluations === 0);
  const refused = await apiJson('POST', '/v1/optimizations', bad);
  const badMsg = refused.status === 422 && refused.json.errors.find(e => e.pointer === '/solver/max_evaluations');
  await page.click('#opt-submit');
  await page.waitForSelector('#opt-problems:not([hidden])');
  check('a refused optimisation shows the API\'s message next to the max-evaluations field', !!badMsg
    && await page.$eval('#opt-f-solver-max_evaluations ~ .problem-msg', e => e.dataset.text) === badMsg.message
    && await page.$eval('#opt-f-solver-max_evaluations', e => e.getAttribute('aria-invalid') === 'true'), badMsg ? badMsg.message : `${refused.status}`);
  check('the problem summary names the pointer', (await page.textContent('#opt-problems')).includes(`/solver/max_evaluations: ${badMsg && badMsg.message}`));

  // a small budget for the test: 2000 evaluations (the example has more)
  await page.fill('#opt-f-solver-max_evaluations', '2000');
  const sent = JSON.parse(await page.inputValue('#opt-request'));
  check('the request sent is the example with 2000 evaluations', canonical(sent) === canonical({ ...example, solver: { ...example.solver, max_evaluations: 2000 } }));
  await page.click('#opt-submit');
  const { jobPath, job } = await waitJob(page, 'optimizations', 'done', '#pareto-plot');
  const r = job.result;
  log(`optimisation done: ${r.evaluations} evaluations, ${r.pareto.points.length} points`);
  check('the page shows the job at #/v1/optimizations/ID', /^\/v1\/optimizations\/[0-9a-f]{32}$/.test(jobPath), jobPath);
  check('progress counts evaluations', await page.textContent('#job-unit') === 'Evaluations'
    && (await page.textContent('#job-samples')).startsWith(job.progress.samples_done.toLocaleString('en-US')), await page.textContent('#job-samples'));
  check('the job view sits below the optimisation request', await page.evaluate(() => document.querySelector('#optimization').nextElementSibling.id === 'job'));

  // the front: one point per API point, at its efficiency and stiffness
  const pts = r.pareto.points;
  const a = r.pareto.objective_a, b = r.pareto.objective_b;
  check('the sweep is efficiency against stiffness', a === 'efficiency' && b === 'stiffness_N_per_um', `${a} ${b}`);
  const circles = await page.$$eval('#pareto-plot circle.point', cs => cs.map(c => ({ i: Number(c.dataset.index), x: Number(c.dataset.x), y: Number(c.dataset.y), label: c.getAttribute('aria-label'), role: c.getAttribute('role'), tab: c.getAttribute('tabindex') })));
  check(`the front has the API's ${pts.length} points`, pts.length >= 2 && circles.length === pts.length, `${circles.length}`);
  check('each point is at its design\'s efficiency and stiffness', pts.every((p, i) => circles[i] && circles[i].x === p.figures[a] && circles[i].y === p.figures[b]),
    JSON.stringify(circles.map(c => [c.x, c.y])));
  check('each point is a focusable button with a name', circles.every(c => c.role === 'button' && c.tab === '0' && c.label));
  const rows = await page.$$eval('#pareto-table tbody tr', trs => trs.map(tr => [...tr.querySelectorAll('td[data-key]')].map(td => Number(td.dataset.value))));
  check('the front\'s table has the same points', rows.length === pts.length && pts.every((p, i) => rows[i][0] === p.figures[a] && rows[i][1] === p.figures[b]));
  const optId = jobPath.split('/').pop();
  const optListed = await page.waitForSelector(`#recent-list li[data-id="${optId}"][data-kind=optimisation][data-state=done]`, { timeout: 15000 }).then(() => true, () => false);
  check('recent jobs: the optimisation is listed by its name with its kind', optListed && await page.textContent(`#recent-list li[data-id="${optId}"] .job-name`) === example.name,
    optListed ? await page.textContent(`#recent-list li[data-id="${optId}"]`) : 'not listed');
  const bestIdx = pts.findIndex(p => canonical(p.variables) === canonical(r.best.variables));
  const ringed = await page.$$eval('#pareto-plot circle.point.best', cs => cs.map(c => Number(c.dataset.index)));
  check('the best design is marked on the front', bestIdx < 0 ? ringed.length === 0 : JSON.stringify(ringed) === JSON.stringify([bestIdx]), `${ringed} vs ${bestIdx}`);

  // the legend: feasible, best design and the selected point, whose swatch is drawn as a selected point is
  const legend = await page.$$eval('#pareto-plot g.legend text[data-entry]', ts => Object.fromEntries(ts.map(t => [t.dataset.entry, t.textContent])));
  check('the front has a legend with the selected point (and feasible, best design)', /selected point/.test(legend.selected || '') && /feasible/.test(legend.feasible || '')
    && (bestIdx < 0 || /best design/.test(legend.best || '')), JSON.stringify(legend));
  // honest axes: an objective spanning less than 2 % of its value is drawn 2 % wide, and says its range
  for (const [axis, key] of [['x', a], ['y', b]]) {
    const vals = pts.map(p => p.figures[key]);
    const lo = Math.min(...vals), hi = Math.max(...vals), span = hi - lo, rel = span / Math.max(Math.abs(lo), Math.abs(hi));
    const lab = await page.$eval(`#pareto-plot text.axis-label-${axis}`, t => ({ text: t.textContent, span: Number(t.dataset.span), widened: t.dataset.widened }));
    const drawn = await page.$$eval('#pareto-plot circle.point', (cs, ax) => cs.map(c => Number(c.getAttribute(ax === 'x' ? 'cx' : 'cy'))), axis);
    const spread = Math.max(...drawn) - Math.min(...drawn);
    const plotLen = axis === 'x' ? 520 - 60 - 16 : 320 - 34 - 40; // the scatter's plot area (viewBox units)
    const note = await page.$(`#pareto-caption .span-note[data-axis=${axis}]`);
    if (rel < 0.02) {
      const want = plotLen * span / (0.02 * Math.max(Math.abs(lo), Math.abs(hi)) * (axis === 'x' ? 1.12 : 1.16));
      const noteText = note ? await note.textContent() : '';
      check(`${key} spans only ${span.toPrecision(2)} (${(100 * rel).toFixed(2)} %): its axis is drawn 2 % of the value wide, the points over ${want.toFixed(1)} units, not the whole axis`,
        lab.widened === 'true' && lab.span === span && Math.abs(spread - want) < 0.5 && spread < 0.5 * plotLen, `${JSON.stringify(lab)} spread ${spread} want ${want}`);
      check(`${key}: the axis label and a note under the chart give the small range (range ${Number(span.toPrecision(2))})`, lab.text.includes(`range ${Number(span.toPrecision(2))}`)
        && noteText.includes(`varies by only ${Number(span.toPrecision(2))}`) && noteText.includes('2 %'), `${lab.text} | ${noteText}`);
    } else {
      check(`${key} spans ${(100 * rel).toFixed(1)} % of its value: its axis is fitted to the points, without a note`, lab.widened === 'false' && !note && spread > 0.7 * plotLen, `${JSON.stringify(lab)} spread ${spread}`);
    }
  }
  const effVals = pts.map(p => p.figures[a]);
  check('the example\'s front spans a small efficiency range (so the note above is exercised)', (Math.max(...effVals) - Math.min(...effVals)) / Math.max(...effVals) < 0.02, JSON.stringify(effVals));

  // a point's design: clicked, and by keyboard
  const shownPoint = async i => ({
    design: JSON.parse(await page.textContent('#pareto-point-design')),
    vars: await page.$$eval('#pareto-point-variables td', tds => Object.fromEntries(tds.map(t => [t.dataset.key, Number(t.dataset.value)]))),
    cons: await page.$$eval('#pareto-point-constraints tbody tr', trs => trs.map(tr => ({ name: tr.dataset.name,
      value: tr.querySelector('[data-key=value]').dataset.value, satisfied: tr.querySelector('[data-key=satisfied]').dataset.value }))),
    index: Number(await page.getAttribute('#pareto-detail', 'data-index')),
  });
  const samePoint = (got, p) => canonical(got.design) === canonical(p.design)
    && Object.entries(p.variables).filter(([, v]) => v !== null).every(([k, v]) => got.vars[k] === v)
    && got.cons.length === p.constraints.length
    && p.constraints.every((c, j) => got.cons[j].name === c.name && (c.value === null ? got.cons[j].value === undefined : Number(got.cons[j].value) === c.value) && got.cons[j].satisfied === String(c.satisfied));
  const clickIdx = pts.length - 1;
  await page.click(`#pareto-plot circle.point[data-index="${clickIdx}"]`);
  await page.waitForSelector(`#pareto-detail[data-index="${clickIdx}"]`);
  let got = await shownPoint();
  check(`clicking point ${clickIdx + 1} shows its design, variables and constraints as the API says`, samePoint(got, pts[clickIdx]), JSON.stringify(got.vars));
  check('the selection is announced', (await page.textContent('#pareto-status')).includes(`point ${clickIdx + 1}`));
  await page.focus('#pareto-plot circle.point[data-index="0"]');
  await page.keyboard.press('Enter');
  await page.waitForSelector('#pareto-detail[data-index="0"]');
  got = await shownPoint();
  check('Enter on point 1 shows its design', samePoint(got, pts[0]));
  check('the pressed point says so (aria-pressed)', await page.getAttribute('#pareto-plot circle.point[data-index="0"]', 'aria-pressed') === 'true');
  const fills = await page.evaluate(() => ({ point: getComputedStyle(document.querySelector('#pareto-plot circle.point.selected')).fill,
    swatch: getComputedStyle(document.querySelector('#pareto-plot g.legend .point-swatch.selected')).fill,
    other: getComputedStyle(document.querySelector('#pareto-plot circle.point:not(.selected):not(.infeasible)') || document.body).fill }));
  check('the legend\'s selected-point swatch looks like the selected point (and unlike the others)', fills.point === fills.swatch && fills.point !== fills.other, JSON.stringify(fills));

  // the best design with its figures and constraints
  const bestDesign = JSON.parse(await page.textContent('#best-point-design'));
  check('the best design is the API\'s', canonical(bestDesign) === canonical(r.best.design));
  const bestFig = await page.$$eval('#best-point-figures td, #best-point-objectives td', tds => Object.fromEntries(tds.map(t => [t.dataset.key, t.dataset.value === undefined ? null : Number(t.dataset.value)])));
  check('the best design\'s figures are the API\'s', Object.entries(r.best.figures).every(([k, v]) => bestFig[k] === v), JSON.stringify(bestFig));
  const bestCons = await page.$$eval('#best-point-constraints tbody tr', trs => trs.map(tr => tr.dataset.name));
  check('the best design\'s constraints table lists every constraint', JSON.stringify(bestCons) === JSON.stringify(r.best.constraints.map(c => c.name)));
  await shot('05-optimization.png');
  await a11yAudit(page, 'optimisation');
  await contrastAudit(page, 'optimisation');
  await layoutAudit(page, 'optimisation');
  await laptopShot(page, '14-laptop-pareto.png', '#pareto-card');
  await (await page.$('#pareto-card')).screenshot({ path: path.join(artifacts, '05b-pareto.png') });

  // study the selected design's tolerances: the design goes into the study form
  await page.click('#pareto-point-study');
  await page.waitForFunction(() => document.activeElement && document.activeElement.id === 'f-starts');
  const formDesign = await page.evaluate(() => window.prsm.form.toRequest().design);
  check('"Study this design\'s tolerances" puts that design into the study form', canonical(formDesign) === canonical(pts[0].design), JSON.stringify(formDesign).slice(0, 200));
  check('the study form keeps its tolerances', await page.$$eval('#tolerances tbody tr', trs => trs.length) > 0);

  // cancel: a large budget, cancelled from the page once evaluations are counted; its best so far stays
  await page.fill('#opt-f-solver-max_evaluations', '200000');
  await page.fill('#opt-f-solver-max_time_s', '300');
  await page.click('#opt-submit');
  await page.waitForFunction(() => location.hash.startsWith('#/v1/optimizations/') && document.querySelector('#job-state').dataset.state === 'running'
    && document.querySelector('#job-progress').value > 0, null, { timeout: 30000 });
  const bestShown = await page.waitForSelector('#job-best-row:not([hidden])', { timeout: 15000 }).then(() => true, () => false);
  check('a running optimisation shows evaluations and the best objective so far', await page.textContent('#job-unit') === 'Evaluations' && bestShown
    && await page.textContent('#job-best-label') === 'Best objective so far', await page.textContent('#job-best'));
  await (await page.$('#job')).screenshot({ path: path.join(artifacts, '05c-optimization-running.png') });
  const runPath = await page.evaluate(() => location.hash.slice(1));
  await page.click('#job-cancel');
  await page.waitForSelector('#job-state[data-state=cancelled]');
  const cancelled = await cancelledJob(runPath);
  check('cancel: the API says the optimisation is cancelled', cancelled.state === 'cancelled', cancelled.state);
  if (cancelled.result) {
    await page.waitForSelector('#opt-cancelled');
    check('cancel: the best design so far is shown', cancelled.result.cancelled === true && (!cancelled.result.best
      || canonical(JSON.parse(await page.textContent('#best-point-design'))) === canonical(cancelled.result.best.design)));
  } else {
    check('cancel: the page says it was cancelled', (await page.textContent('#job-status')).includes('Cancelled'));
  }
}

// ---- allocation: case A (Monte Carlo-corrected) and LS-1 (analytic), the tables against the API ----
async function allocationView(page, shot) {
  log('allocation view');
  check('the allocation view is in the navigation', await page.isVisible('#nav-allocation'));
  const checkTables = async (r, what) => {
    const rows = await page.$$eval('#alloc-tolerances tbody tr', trs => trs.map(tr => ({ p: tr.dataset.parameter,
      ...Object.fromEntries([...tr.querySelectorAll('td[data-key]')].map(td => [td.dataset.key, td.dataset.value === undefined ? null : Number(td.dataset.value)])),
      text: tr.querySelector('[data-key=half_width]').textContent })));
    check(`${what}: one row per allocated tolerance`, rows.length === r.tolerances.length && rows.every((x, i) => x.p === r.tolerances[i].parameter), rows.map(x => x.p).join(','));
    const unitShown = { um: 'µm', mrad: 'mrad', um_per_300mm: 'µm/300 mm', '': '' };
    check(`${what}: allocated half-widths with their unit, linear half-widths, costs and sensitivities as the API says`, r.tolerances.every((t, i) => rows[i]
      && rows[i].half_width === t.half_width && rows[i].cost === t.cost && rows[i].linear_half_width === r.linear.half_widths[i]
      && rows[i].reference_half_width === t.reference_half_width
      && rows[i].text.startsWith(String(Number(t.half_width.toPrecision(4))))
      && (t.unit === '' || rows[i].text.includes(unitShown[t.unit]))
      && r.constraints.every(c => rows[i][`sensitivity:${c.output}`] === t.sensitivities[c.output])), JSON.stringify(rows[0]));
    check(`${what}: total cost = API ${r.total_cost}`, await page.$eval('#alloc-tolerances tfoot [data-key=total_cost]', td => Number(td.dataset.value)) === r.total_cost
      && await page.$eval('#alloc-total strong', e => Number(e.dataset.value)) === r.total_cost);
    const cons = await page.$$eval('#alloc-constraints tbody tr', trs => trs.map(tr => ({ output: tr.dataset.output,
      ...Object.fromEntries([...tr.querySelectorAll('td[data-key]')].map(td => [td.dataset.key, td.dataset.value === undefined ? null : Number(td.dataset.value)])),
      lo: tr.querySelector('[data-key=mc_interval]').dataset.lo, hi: tr.querySelector('[data-key=mc_interval]').dataset.hi })));
    check(`${what}: predicted (linear) and Monte Carlo yield with its 95 % interval per constraint as the API says`, cons.length === r.constraints.length
      && r.constraints.every((c, i) => cons[i].output === c.output && cons[i].predicted_yield === c.predicted_yield && cons[i].assembly_tolerance === c.assembly_tolerance
        && (c.monte_carlo ? cons[i].mc_yield === c.monte_carlo.fraction && Number(cons[i].lo) === c.monte_carlo.interval95[0]
          && Number(cons[i].hi) === c.monte_carlo.interval95[1] && cons[i].mc_samples === c.monte_carlo.samples : cons[i].mc_yield === null)), JSON.stringify(cons));
    const bars = await page.$$eval('#alloc-range-plot g.bars rect.bar', rs => rs.map(x => Number(x.dataset.value)));
    check(`${what}: the chart has a bar per tolerance at its allocated half-width`, JSON.stringify(bars) === JSON.stringify(r.tolerances.map(t => t.half_width)));
    const steps = r.correction.steps.some(s => s.yields.some(y => y)) ? r.correction.steps : []; // an analytic stack's one step has no yields
    check(`${what}: the correction steps in a table and a chart`, await page.$$eval('#alloc-steps tbody tr', trs => trs.length).catch(() => 0) === steps.length
      && (steps.length === 0 || await page.$$eval('#alloc-steps-plot-0 circle.marker', cs => cs.map(c => Number(c.dataset.value))).then(v => v.length === steps.length
        && steps.every((s, i) => s.yields[0] && Math.abs(v[i] - 100 * s.yields[0].fraction) < 1e-9))), `${steps.length} steps`);
  };

  // case A: backlash at 99.73 %, corrected with Monte Carlo (4096 samples a step for the test)
  const caseA = await loadExample(page, '#allocation', 'allocate-case-a.json');
  check('the Monte Carlo fields show the example\'s settings', await page.inputValue('#alloc-f-monte_carlo-samples') === String(caseA.monte_carlo.samples));
  await page.fill('#alloc-f-monte_carlo-samples', '4096');
  await page.click('#alloc-submit');
  let { job, jobPath: casePath } = await waitJob(page, 'allocations', 'done', '#alloc-tolerances');
  log(`allocation done: total cost ${job.result.total_cost}, ${job.result.correction.steps.length} steps`);
  check('the allocation ran with 4096 samples a step', job.result.monte_carlo && job.result.monte_carlo.samples === 4096);
  check('allocation progress counts samples', await page.textContent('#job-unit') === 'Samples');
  await checkTables(job.result, 'case A');
  await shot('06-allocation.png');
  await a11yAudit(page, 'allocation');
  await contrastAudit(page, 'allocation');
  await layoutAudit(page, 'allocation');
  await laptopShot(page, '15-laptop-allocation.png', '#results');
  await (await page.$('#results')).screenshot({ path: path.join(artifacts, '06b-allocation-results.png') });

  // LS-1: the analytic stack (no Monte Carlo)
  await loadExample(page, '#allocation', 'allocate-ls1.json');
  check('an analytic example leaves the Monte Carlo fields empty', await page.inputValue('#alloc-f-monte_carlo-samples') === '');
  await page.click('#alloc-submit');
  ({ job } = await waitJob(page, 'allocations', 'done', '#alloc-tolerances', 60000, casePath));
  await checkTables(job.result, 'LS-1');
  check('LS-1: the page says an analytic stack has no Monte Carlo', (await page.textContent('#alloc-yield-card')).includes('no Monte Carlo'));

  // cancel: case A in the exact assembly model with more samples, cancelled once samples are counted
  await loadExample(page, '#allocation', 'allocate-case-a.json');
  await editRequest(page, '#alloc-request', d => { d.study.assembly.mode = 'exact'; d.monte_carlo.samples = 16384; });
  await page.click('#alloc-submit');
  await page.waitForFunction(() => location.hash.startsWith('#/v1/allocations/') && document.querySelector('#job-state').dataset.state === 'running'
    && document.querySelector('#job-progress').value > 0, null, { timeout: 30000 });
  check('a running allocation counts its Monte Carlo samples', await page.textContent('#job-unit') === 'Samples', await page.textContent('#job-samples'));
  const runPath = await page.evaluate(() => location.hash.slice(1));
  await page.click('#job-cancel');
  await page.waitForSelector('#job-state[data-state=cancelled]');
  const cancelled = await cancelledJob(runPath);
  check('cancel: the API says the allocation is cancelled', cancelled.state === 'cancelled', cancelled.state);
  if (cancelled.result) await page.waitForSelector('#alloc-cancelled');
  check('cancel: the page says so (with the best allocation so far when there is one)', (await page.textContent('#job-status')).includes('Cancelled')
    && (!cancelled.result || await page.isVisible('#alloc-cancelled')));
}

// ---- simulation: seed 000's two-stage start-up against the API, the downloads, a refused request, cancel ----
async function simulationView(page, shot) {
  log('simulation view');
  check('the simulation view is in the navigation', await page.isVisible('#nav-simulation'));
  const file = 'dynamics-seed000-row1.json';
  const example = await loadExample(page, '#simulation', file);
  check('the settings show the example\'s end time and output step', await page.inputValue('#sim-f-dynamics-time-end_s') === String(example.dynamics.time.end_s)
    && Number(await page.inputValue('#sim-f-dynamics-time-output_step_s')) === example.dynamics.time.output_step_s);

  // a refused request: a negative end time, the API's problem next to the end-time field with its pointer
  await page.fill('#sim-f-dynamics-time-end_s', '-1');
  // (wait for the field's input handler to have rewritten the request: once seen read at once)
  await page.waitForFunction(() => { try { return JSON.parse(document.querySelector('#sim-request').value).dynamics.time.end_s === -1; } catch { return false; } }, null, { timeout: 5000 }).catch(() => {});
  const bad = JSON.parse(await page.inputValue('#sim-request'));
  check('the end-time field writes its member into the request', bad.dynamics.time.end_s === -1);
  const refused = await apiJson('POST', '/v1/simulations', bad);
  const badMsg = refused.status === 422 && refused.json.errors.find(e => e.pointer === '/dynamics/time/end_s');
  await page.click('#sim-submit');
  await page.waitForSelector('#sim-problems:not([hidden])');
  check('a negative end time is refused (422) and the API\'s message shows next to the end-time field', !!badMsg
    && await page.$eval('#sim-f-dynamics-time-end_s ~ .problem-msg', e => e.dataset.text) === badMsg.message
    && await page.$eval('#sim-f-dynamics-time-end_s', e => e.getAttribute('aria-invalid') === 'true'), badMsg ? badMsg.message : `${refused.status}`);
  const problems = await page.textContent('#sim-problems');
  check('the problem summary names the pointer /dynamics/time/end_s and says 422', problems.includes(`/dynamics/time/end_s: ${badMsg && badMsg.message}`) && problems.includes('(422)'), problems);
  check('focus moves to the problem summary', await page.evaluate(() => document.activeElement && document.activeElement.id === 'sim-problems'));
  await (await page.$('#simulation')).screenshot({ path: path.join(artifacts, '07a-simulation-invalid.png') });
  await page.fill('#sim-f-dynamics-time-end_s', String(example.dynamics.time.end_s));
  check('putting the end time back gives the example again', canonical(JSON.parse(await page.inputValue('#sim-request'))) === canonical(example));

  // the run
  await page.click('#sim-submit');
  const { jobPath, job } = await waitJob(page, 'simulations', 'done', '#sim-carrier-plot', 60000);
  const r = job.result, d = r.dynamics, tr = d.transient, st = d.settled;
  log(`simulation done: ${tr.points} output times, ${d.stages} stages`);
  check('the page shows the job at #/v1/simulations/ID', /^\/v1\/simulations\/[0-9a-f]{32}$/.test(jobPath), jobPath);
  check('the example is the two-stage screw', d.stages === 2 && tr.stages.length === 2 && st.stages.length === 2);
  check('progress counts simulated time, in s', await page.textContent('#job-unit') === 'Simulated time'
    && (await page.textContent('#job-samples')).startsWith(`${example.dynamics.time.end_s} s of ${example.dynamics.time.end_s} s`), await page.textContent('#job-samples'));
  check('the job view sits below the simulation request', await page.evaluate(() => document.querySelector('#simulation').nextElementSibling.id === 'job'));

  // plots: both carriers, with the settled ratios dashed; efficiency, torque, speed and the forces
  const curves = async sel => page.$$eval(`${sel} path.series`, ps => ps.map(p => ({ key: p.dataset.series, n: Number(p.dataset.points), d: p.getAttribute('d').length })));
  const refLines = async sel => page.$$eval(`${sel} line.ref-line`, ls => ls.map(l => ({ key: l.dataset.series, v: Number(l.dataset.value) })));
  const carrier = await curves('#sim-carrier-plot');
  check('the carrier plot has both carriers\' curves, each with every output time', carrier.length === 2 && carrier[0].key === 'stage1' && carrier[1].key === 'stage2'
    && carrier.every(c => c.n === tr.points && c.d > 100), JSON.stringify(carrier));
  const carrierRefs = await refLines('#sim-carrier-plot');
  check('the settled carrier ratios are dashed lines at the API\'s values', carrierRefs.length === 2 && st.stages.every((s, k) => carrierRefs[k].key === `stage${k + 1}` && carrierRefs[k].v === s.carrier_ratio),
    JSON.stringify(carrierRefs));
  const legend = await page.$$eval('#sim-carrier-plot g.legend text', ts => ts.map(t => t.textContent));
  check('the carrier plot has a legend naming both carriers and the settled lines', legend.includes('stage 1 carrier') && legend.includes('stage 2 carrier') && legend.includes('settled'), legend.join(', '));
  const axisLabels = await page.$$eval('#sim-carrier-plot text.label', ts => ts.map(t => t.textContent));
  check('the carrier plot\'s axes are labelled with their units', axisLabels.includes('time (ms)') && axisLabels.some(t => t.startsWith('carrier ratio')), axisLabels.join(', '));
  for (const [id, key, value] of [['#sim-efficiency-plot', 'efficiency', st.efficiency], ['#sim-torque-plot', 'input_torque_Nm', st.input_torque_Nm], ['#sim-speed-plot', 'screw_speed_rad_s', st.screw_speed_rad_s]]) {
    const c = await curves(id), refs = await refLines(id);
    check(`${id.slice(1)}: the curve of ${key} with its settled value ${value} dashed`, c.length >= 1 && c[0].key === key && c[0].n === tr.points && refs.length === 1 && refs[0].v === value,
      JSON.stringify([c, refs]));
  }
  for (const [key, stages] of [['contact_normal_force_N', [1, 2]], ['nut_contact_force_N', [1, 2]], ['gear_tooth_force_N', [1, 2]], ['cage_force_N', [1, 2]], ['spline_force_N', [2]]]) {
    const id = `#sim-force-plot-${key}`;
    const c = await curves(id), refs = await refLines(id);
    check(`${key}: a curve per stage (${stages.join(', ')}) and the settled values dashed`, JSON.stringify(c.map(x => x.key)) === JSON.stringify(stages.map(k => `stage${k}`))
      && stages.every((k, i) => refs[i] && refs[i].v === st.stages[k - 1][key]), JSON.stringify([c, refs]));
  }

  // the plotted window: the first 0.5 ms, the start-up, the whole run again
  await page.fill('#sim-window', '0.5');
  await page.press('#sim-window', 'Tab');
  const first = tr.time_s.filter(t => t * 1e3 <= 0.5 * (1 + 1e-12)).length;
  await page.waitForSelector(`#sim-plots[data-points="${first}"]`);
  const windowed = await curves('#sim-carrier-plot');
  const forcesWindowed = await curves('#sim-force-plot-cage_force_N');
  check(`plotting the first 0.5 ms draws its ${first} output times in every plot, the forces too`, windowed.length === 2 && windowed.every(c => c.n === first)
    && forcesWindowed.every(c => c.n === first) && (await page.textContent('#sim-window-hint')).includes(`first ${first} of ${tr.points}`), JSON.stringify(windowed));
  await page.click('#sim-window-all');
  await page.waitForSelector(`#sim-plots[data-points="${tr.points}"]`);
  check('"Whole run" draws every output time again', (await curves('#sim-carrier-plot')).every(c => c.n === tr.points) && await page.inputValue('#sim-window') === String(Number((1e3 * tr.time_s[tr.points - 1]).toPrecision(6))));

  // the settled table against the API (the text as shown, the value in data-value)
  const settled = await page.$$eval('#sim-settled td[data-key]', tds => Object.fromEntries(tds.map(t => [t.dataset.key, { v: t.dataset.value, text: t.textContent }])));
  const eff = settled.efficiency;
  check(`the settled table shows the API's settled efficiency ${st.efficiency}`, eff && Number(eff.v) === st.efficiency && eff.text === String(Number(st.efficiency.toPrecision(6))), JSON.stringify(eff));
  check('the settled table shows the statics engine\'s efficiency and the input torque', Number(settled.efficiency_statics.v) === st.efficiency_statics
    && settled.efficiency_statics.text === String(Number(st.efficiency_statics.toPrecision(6))) && Number(settled.input_torque_Nm.v) === st.input_torque_Nm
    && settled.input_torque_Nm.text === `${Number(st.input_torque_Nm.toPrecision(6))} N m`, JSON.stringify([settled.efficiency_statics, settled.input_torque_Nm]));
  check('per stage: settled ratio, k*, statics ratio and the 90 % and 99 % times as the API says', st.stages.every(s => ['carrier_ratio', 'carrier_ratio_min_slip', 'carrier_ratio_statics',
    'time_to_90_percent_s', 'time_to_99_percent_s'].every(k => settled[`stage${s.stage}.${k}`] && Number(settled[`stage${s.stage}.${k}`].v) === s[k])),
    JSON.stringify(Object.keys(settled)));
  check('stage 2\'s k* shown as the API gives it', settled['stage2.carrier_ratio_min_slip'].text === String(Number(st.stages[1].carrier_ratio_min_slip.toPrecision(6))), settled['stage2.carrier_ratio_min_slip'].text);
  const checks = await page.$$eval('#sim-checks td[data-key]', tds => Object.fromEntries(tds.map(t => [t.dataset.key, t.dataset.value === undefined ? t.textContent : Number(t.dataset.value)])));
  check('the checks: power balance and Newton–Euler maxima with their limits as the API says', checks.max_power_balance_relative === d.checks.max_power_balance_relative
    && checks.max_power_balance_relative_limit === d.checks.power_balance_limit && checks.max_newton_euler_residual === d.checks.max_newton_euler_residual
    && checks.max_newton_euler_residual_limit === d.checks.newton_euler_limit && checks.max_power_balance_relative_ok === 'passed' && d.checks.passed, JSON.stringify(checks));

  // "Download CSV": the columns and header of `prsm simulate --csv` (and of the service's samples.csv),
  // a row per output time, every number the service's to the JSON's precision
  const [csvDownload] = await Promise.all([page.waitForEvent('download'), page.click('#sim-csv-download')]);
  const csvText = fs.readFileSync(await csvDownload.path(), 'utf8');
  const cliCsv = path.join(fs.mkdtempSync(path.join(os.tmpdir(), 'prsm-sim-')), 'series.csv');
  const cli = spawnSync(path.resolve(args.prsm), ['simulate', path.join(source, 'studies', file), '--csv', cliCsv], { encoding: 'utf8', maxBuffer: 1 << 28 });
  const cliLines = cli.status === 0 ? fs.readFileSync(cliCsv, 'utf8').trimEnd().split('\n') : [];
  fs.rmSync(path.dirname(cliCsv), { recursive: true, force: true });
  const server = await apiJson('GET', job.links.samples_csv);
  const serverLines = server.text.trimEnd().split('\n');
  const lines = csvText.trimEnd().split('\n');
  check('the CSV download is named after the job', csvDownload.suggestedFilename() === `simulation-${job.id}.csv`, csvDownload.suggestedFilename());
  check('the CSV has the header of `prsm simulate --csv` (both carriers\' columns)', cli.status === 0 && lines[0] === cliLines[0] && lines[0] === serverLines[0]
    && lines[0].includes('stage2_carrier_ratio'), `${lines[0].slice(0, 120)} | ${cli.stderr}`);
  check(`the CSV has a row per output time (${tr.points})`, lines.length === tr.points + 1 && cliLines.length === lines.length && serverLines.length === lines.length, `${lines.length} ${cliLines.length} ${serverLines.length}`);
  let cells = 0, identical = 0;
  const apart = [];
  lines.slice(1).forEach((line, i) => {
    const a = line.split(','), b = serverLines[i + 1].split(',');
    if (a.length !== b.length) { apart.push(`row ${i + 1}: ${a.length} cells against ${b.length}`); return; }
    a.forEach((x, j) => {
      cells++;
      if (x === b[j]) { identical++; return; }
      const p = Number(x), q = Number(b[j]);
      // the JSON carries a number to within one part in 2^52 (cJSON prints 15 digits when they read back that close)
      if (x === '' || b[j] === '' || !(Math.abs(p - q) <= 2.3e-16 * Math.max(Math.abs(p), Math.abs(q)))) apart.push(`row ${i + 1} ${lines[0].split(',')[j]}: ${x} against ${b[j]}`);
    });
  });
  check(`every CSV cell is the service's value, empty where it is empty (${identical} of ${cells} character for character, the rest within the JSON's precision)`, cells > 0 && apart.length === 0, apart.slice(0, 5).join('; '));
  await page.waitForFunction(() => document.querySelector('#sim-download-status').textContent.includes('.csv'));

  // "Download JSON": the result document
  const [jsonDownload] = await Promise.all([page.waitForEvent('download'), page.click('#sim-json-download')]);
  const downloaded = JSON.parse(fs.readFileSync(await jsonDownload.path(), 'utf8'));
  check('the JSON download is the API\'s result', jsonDownload.suggestedFilename() === `simulation-${job.id}.json` && canonical(downloaded) === canonical(r));

  await shot('07-simulation.png');
  await (await page.$('#results')).screenshot({ path: path.join(artifacts, '07b-simulation-results.png') });
  await a11yAudit(page, 'simulation');
  await contrastAudit(page, 'simulation');
  await layoutAudit(page, 'simulation');
  await laptopShot(page, '17-laptop-simulation.png', '#sim-carrier-card');

  // cancel: the same screw simulated for 500 s (50001 output times), cancelled once it has started
  await loadExample(page, '#simulation', file);
  await page.fill('#sim-f-dynamics-time-end_s', '500');
  await page.fill('#sim-f-dynamics-time-output_step_s', '0.01');
  await page.click('#sim-submit');
  await page.waitForFunction(p => location.hash.startsWith('#/v1/simulations/') && location.hash !== `#${p}` && document.querySelector('#job-state').dataset.state === 'running'
    && document.querySelector('#job-progress').value > 0, jobPath, { timeout: 30000 });
  const runPath = await page.evaluate(() => location.hash.slice(1));
  check('a running simulation shows its progress in simulated time', await page.textContent('#job-unit') === 'Simulated time'
    && /^[\d.e−+]+ s of 500 s \(\d+\.\d %\)$/.test(await page.textContent('#job-samples')), await page.textContent('#job-samples'));
  await (await page.$('#job')).screenshot({ path: path.join(artifacts, '07c-simulation-running.png') });
  await page.click('#job-cancel');
  await page.waitForSelector('#job-state[data-state=cancelled]');
  const cancelled = (await apiJson('GET', runPath)).json;
  check('cancel: the API says the simulation is cancelled', cancelled.state === 'cancelled' && !cancelled.result, cancelled.state);
  check('cancel: the page says so and the button is disabled', (await page.textContent('#job-status')).includes('Cancelled') && await page.isDisabled('#job-cancel')
    && await page.isHidden('#results'));

  // a run that does not converge (validation case V1 allowed 5 steps): the job fails, and its problem shows with its pointer
  await loadExample(page, '#simulation', 'dynamics-case-a-v1.json');
  await editRequest(page, '#sim-request', doc => { doc.dynamics.time.max_steps = 5; });
  await page.click('#sim-submit');
  const { job: failed } = await waitJob(page, 'simulations', 'failed', '#job-problem:not([hidden])', 30000, runPath);
  const failure = failed.problem && failed.problem.errors && failed.problem.errors[0];
  check('a simulation that does not converge: the page shows the job\'s problem with its pointer', !!failure && failure.pointer === '/dynamics/time'
    && (await page.textContent('#job-problem')).includes(`${failure.pointer}: ${failure.message}`) && (await page.textContent('#job-status')).includes('failed'),
    await page.textContent('#job-problem'));
  await vibrationViews(page);
}

// ---- the vibration analyses (studies/vibration-*.json): a sweep's bifurcation diagram, V4a's steady state ----
async function vibrationViews(page) {
  log('vibration views');
  const before = await page.evaluate(() => location.hash.slice(1));
  await loadExample(page, '#simulation', 'vibration-gear-pair-sweep.json');
  await page.click('#sim-submit');
  const { jobPath, job } = await waitJob(page, 'simulations', 'done', '#vib-bifurcation-plot', 60000, before);
  const s = job.result.dynamics.sweep;
  log(`sweep done: ${s.up.length} points up, ${s.down.length} down`);
  const want = dir => { const ok = s[dir].filter(q => q.converged); return { points: ok.length, values: ok.reduce((n, q) => n + q.poincare.length, 0) }; };
  const got = await page.$$eval('#vib-bifurcation-plot path.xy-points', ps => Object.fromEntries(ps.map(q => [q.dataset.series,
    { points: Number(q.dataset.sweepPoints), values: Number(q.dataset.points), drawn: Number(q.dataset.drawn), fill: q.getAttribute('fill'), stroke: q.getAttribute('stroke') }])));
  check('sweep: the bifurcation diagram draws both directions, with the API result\'s points and Poincaré values', ['up', 'down'].every(d => got[d] && got[d].points === want(d).points
    && got[d].values === want(d).values && got[d].drawn > 0), JSON.stringify({ got, up: want('up'), down: want('down') }));
  check('sweep: the two directions look different (filled against open markers)', got.up && got.down && got.up.fill !== 'none' && got.down.fill === 'none' && !!got.down.stroke);
  const legend = await page.$$eval('#vib-bifurcation-plot g.legend text', ts => ts.map(t => t.textContent));
  const axes = await page.$$eval('#vib-bifurcation-plot text.label', ts => ts.map(t => t.textContent));
  check('sweep: the legend names both directions and the axes say what and in which unit', legend.some(t => t.startsWith('sweep up')) && legend.some(t => t.startsWith('sweep down'))
    && axes.some(t => t.startsWith('frequency ratio') && t.includes('(–)')) && axes.some(t => t.includes('half backlashes')), JSON.stringify([legend, axes]));
  check('sweep: the failed points are counted, not drawn', Number(await page.getAttribute('#vib-failed', 'data-failed')) === s.failed_points);
  await (await page.$('#results')).screenshot({ path: path.join(artifacts, '07d-vibration-sweep.png') });

  await loadExample(page, '#simulation', 'vibration-gear-pair-v4a.json');
  await page.click('#sim-submit');
  const { job: v4a } = await waitJob(page, 'simulations', 'done', '#vib-spectrum-plot', 60000, jobPath);
  const v = v4a.result.dynamics.vibration;
  const cls = await page.textContent('#vib-classification');
  check('V4a: the page says period 1, as the API does', v.classification === 'periodic' && v.period === 1 && cls.includes('Periodic, period 1')
    && await page.getAttribute('#vib-classification', 'data-period') === '1', cls);
  check('V4a: the Lyapunov exponents are shown', (await page.textContent('#vib-lyapunov')).includes(v.lyapunov.exponents_per_tau.map(x => String(Number(x.toPrecision(4))).replace('-', '−'))[0]));
  const labels = await page.$$eval('#vib-spectrum-plot text.stem-label', ts => ts.map(t => ({ text: t.textContent, names: t.dataset.names.split(' ') })));
  const forcing = v.spectrum.find(l => l.name === 'forcing');
  const stem = await page.$eval('#vib-spectrum-plot line.stem[data-name="forcing"]', l => Number(l.dataset.value)).catch(() => null);
  check('V4a: the spectrum plot marks the forcing line with its label and amplitude', labels.some(l => l.names.includes('forcing') && l.text.includes('forcing')) && stem === forcing.amplitude,
    JSON.stringify(labels));
  check('V4a: the Poincaré section and the phase portrait are drawn', Number(await page.getAttribute('#vib-poincare-plot path.xy-points', 'data-points')) === v.poincare.points
    && Number(await page.getAttribute('#vib-phase-plot path.xy-line', 'data-points')) === v.phase_portrait.points);
  check('V4a: the extremes table has every observable', (await page.$$('#vib-extremes tbody tr')).length === v.extremes.length);
  await (await page.$('#results')).screenshot({ path: path.join(artifacts, '07e-vibration-v4a.png') });
  await a11yAudit(page, 'vibration');
  await contrastAudit(page, 'vibration');
  await layoutAudit(page, 'vibration');
}


// ---- calibration against measured data (issue 17 item 5): validation case V6 ----------------------
// The web example is tests/data/calibrate-case-a-v6.json with the curve of tests/data/v6-measured-te.csv
// inlined as measured.te arrays: the same members, the same numbers. (The file itself is picked with the
// view's file input below: its text becomes measured.te_csv.)
function calibrationExampleIsV6(file) {
  const got = JSON.parse(fs.readFileSync(path.join(source, 'web/examples', file), 'utf8'));
  const base = JSON.parse(fs.readFileSync(path.join(source, 'tests/data/calibrate-case-a-v6.json'), 'utf8'));
  const rows = fs.readFileSync(path.join(source, 'tests/data/v6-measured-te.csv'), 'utf8').split('\n').map(l => l.trim()).filter(l => l && !l.startsWith('#')).map(l => l.split(','));
  const te = Object.fromEntries(rows[0].map((name, i) => [name, rows.slice(1).map(r => Number(r[i]))]));
  const want = { ...base, measured: { ...base.measured, te } };
  check(`web/examples/${file} is tests/data/calibrate-case-a-v6.json with tests/data/v6-measured-te.csv inlined`, canonical(got) === canonical(want));
}

async function calibrationView(page, shot) {
  log('calibration view');
  check('the calibration view is in the navigation', await page.isVisible('#nav-calibration'));
  const file = 'calibrate-case-a-v6.json';
  const example = await loadExample(page, '#calibration', file);
  check('the settings show the example\'s model and noise', await page.inputValue('#cal-f-dynamics-calibrate-model') === 'line'
    && Number(await page.inputValue('#cal-f-measured-te_noise_sd_um')) === example.measured.te_noise_sd_um);

  // a refused request: an unknown model, the API's problem next to the model field with its pointer
  await page.selectOption('#cal-f-dynamics-calibrate-model', 'physical');
  // (the request holds the curve, some 100 kB of text: set at once, with the input event a person's edit fires)
  await page.evaluate(() => {
    const t = document.getElementById('cal-request'), doc = JSON.parse(t.value);
    doc.dynamics.calibrate.model = 'spline';
    doc.design.geometry.pitch_mm = -2;
    t.value = JSON.stringify(doc, null, 2);
    t.dispatchEvent(new Event('input', { bubbles: true }));
  });
  const bad = JSON.parse(await page.inputValue('#cal-request'));
  const refused = await apiJson('POST', '/v1/calibrations', bad);
  check('the service refuses the invalid calibration (422)', refused.status === 422, String(refused.status));
  const before = await page.evaluate(() => location.hash.slice(1));
  await page.click('#cal-submit');
  await page.waitForSelector('#cal-problems:not([hidden])');
  const listed = await page.$$eval('#cal-problems li', ls => ls.map(l => l.dataset.pointer));
  check('a refused calibration lists every problem with its pointer', refused.json && refused.json.errors.every(e => listed.includes(e.pointer))
    && listed.includes('/dynamics/calibrate/model') && listed.includes('/design/geometry/pitch_mm'), JSON.stringify(listed));
  check('the model problem is next to the model field', await page.$eval('#cal-f-dynamics-calibrate-model', e => e.getAttribute('aria-invalid') === 'true'));

  // V6 as it is: submitted, done, drawn
  await page.evaluate(() => { document.getElementById('cal-note').textContent = ''; });
  await loadExample(page, '#calibration', file);
  await page.click('#cal-submit');
  const { job } = await waitJob(page, 'calibrations', 'done', '#cal-estimates', 120000, before);
  const r = job.result, cal = r.calibration;
  log(`calibration done: k ${cal.carrier_ratio.estimate}`);
  const series = await page.$$eval('#cal-overlay-plot path.xy-line', ps => ps.map(q => ({ key: q.dataset.series, points: Number(q.dataset.points), d: q.getAttribute('d').length })));
  check('overlay: two series, measured and model, each with every point of the curve', series.length === 2 && series.map(q => q.key).join() === 'measured,model'
    && series.every(q => q.points === example.measured.te.te_um.length && q.d > 100), JSON.stringify(series));
  const axes = await page.$$eval('#cal-overlay-plot text.label', ts => ts.map(t => t.textContent));
  check('overlay: the axes say what and in which unit', axes.some(t => t.includes('travel') && t.includes('(mm)')) && axes.some(t => t.includes('transmission error') && t.includes('(µm)')), JSON.stringify(axes));
  const rms = Number(await page.getAttribute('#cal-overlay-rms', 'data-value'));
  const n = example.measured.te.te_um.length, p = cal.parameters.length;
  check('overlay: the model curve is the fit (its RMS residual gives the result\'s s)', Math.abs(rms * Math.sqrt(n / (n - p)) / cal.residual_sd_um - 1) < 1e-6, `${rms} ${cal.residual_sd_um}`);
  await page.selectOption('#cal-x-axis', 'angle');
  const axes2 = await page.$$eval('#cal-overlay-plot text.label', ts => ts.map(t => t.textContent));
  check('overlay: against the screw angle on request', axes2.some(t => t.includes('screw angle') && t.includes('(rev)'))
    && (await page.$$('#cal-overlay-plot path.xy-line')).length === 2, JSON.stringify(axes2));

  const named = r.identification.lines.filter(l => !l.above_nyquist);
  const stems = await page.$$eval('#cal-spectrum-plot line.stem', ls => ls.map(l => ({ name: l.dataset.name, value: Number(l.dataset.value) })));
  const labels = (await page.$$eval('#cal-spectrum-plot text.stem-label', ts => ts.map(t => t.dataset.names.split(' ')))).flat();
  check('spectrum: every named line is marked with its amplitude and labelled', named.length >= 6 && named.every(l => stems.some(s => s.name === l.name && s.value === l.amplitude_um) && labels.includes(l.name)),
    JSON.stringify({ stems, labels }));
  check('spectrum: the detrended spectrum is drawn with every bin', Number(await page.getAttribute('#cal-spectrum-plot path.xy-line', 'data-points')) === r.identification.spectrum.amplitude_um.length);

  const rows = await page.$$eval('#cal-estimates tbody tr', trs => trs.map(tr => ({ name: tr.dataset.name,
    estimate: Number(tr.querySelector('[data-key=estimate]').dataset.value), se: Number(tr.querySelector('[data-key=standard_error]').dataset.value) })));
  check('estimates: the table holds every parameter with the API\'s estimate and standard error', rows.length === cal.parameters.length
    && cal.parameters.every((q, i) => rows[i].name === q.name && rows[i].estimate === q.estimate && rows[i].se === q.standard_error), JSON.stringify(rows).slice(0, 300));
  const kRow = rows.find(q => q.name === 'carrier_ratio');
  check('estimates: k as the API gives it', !!kRow && kRow.estimate === cal.carrier_ratio.estimate && Math.abs(kRow.estimate - 0.3724996) < 2e-7, JSON.stringify(kRow));
  const whiskers = await page.$$('#cal-estimates-plot line.whisker');
  check('estimates: a chart of the lines with ± one standard error', (await page.$$('#cal-estimates-plot circle.marker')).length === cal.lines.length && whiskers.length === 3 * cal.lines.length);
  const cav = await page.$$eval('#cal-caveats li', ls => ls.map(l => ({ code: l.dataset.code, triggered: l.dataset.triggered === 'true' })));
  check('caveats: every caveat listed, marked as the API says', cav.length === cal.caveats.length && cal.caveats.every((c, i) => cav[i].code === c.code && cav[i].triggered === c.triggered), JSON.stringify(cav));
  await shot('18-calibration.png');
  await (await page.$('#results')).screenshot({ path: path.join(artifacts, '18b-calibration-results.png') });

  // the bench file picked as it is: its text becomes measured.te_csv, the service reads it, the
  // overlay draws it; the same k as the inlined arrays
  await page.evaluate(() => { document.getElementById('cal-note').textContent = ''; });
  await loadExample(page, '#calibration', file);
  await page.setInputFiles('#cal-csv', path.join(source, 'tests/data/v6-measured-te.csv'));
  await page.waitForFunction(() => document.getElementById('cal-request').value.includes('te_csv'));
  const withCsv = JSON.parse(await page.inputValue('#cal-request'));
  check('a picked CSV file goes into measured.te_csv in place of the arrays', typeof withCsv.measured.te_csv === 'string'
    && withCsv.measured.te_csv === fs.readFileSync(path.join(source, 'tests/data/v6-measured-te.csv'), 'utf8') && !('te' in withCsv.measured));
  const before2 = await page.evaluate(() => location.hash.slice(1));
  await page.click('#cal-submit');
  const done2 = await waitJob(page, 'calibrations', 'done', '#cal-estimates', 120000, before2);
  const r2 = done2.job.result;
  check('the CSV calibration: source csv, 960 points, the same k', r2.measured.source === 'csv' && r2.measured.points === 960
    && r2.calibration.carrier_ratio.estimate === cal.carrier_ratio.estimate, JSON.stringify(r2.measured));
  const series2 = await page.$$eval('#cal-overlay-plot path.xy-line', ps => ps.map(q => Number(q.dataset.points)));
  check('the CSV calibration: the overlay draws the file\'s 960 points, measured and model', series2.length === 2 && series2.every(n => n === 960), JSON.stringify(series2));
  await a11yAudit(page, 'calibration');
  await contrastAudit(page, 'calibration');
  await layoutAudit(page, 'calibration');
}

main().then(() => {
  log(`${passes} passed, ${failures} failed; screenshots in ${artifacts}`);
  process.exit(failures ? 1 : 0);
}).catch(e => {
  console.error(`run.mjs: ${e.stack || e}`);
  process.exit(1);
});
