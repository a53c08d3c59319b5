// The page's only way to the server: same-origin requests to prsm serve's API.
// Every failure becomes an ApiError carrying the RFC 7807 problem document (schemas/problem.schema.json)
// so callers can put each problem next to the field its JSON pointer names.
//
// The API token: a service started with --token-file (or PRSM_TOKEN) wants
// "Authorization: Bearer <token>" on POST and DELETE. The page keeps the token the user types in
// sessionStorage only (this tab, until it closes: never localStorage, never an export) and sends it
// on POST and DELETE only. A 401 fires the window event "prsm:unauthorized" so the page can point
// at the token field; describe() says the same in words.

const TOKEN_KEY = 'prsm.token';
let token = '';
try { token = sessionStorage.getItem(TOKEN_KEY) || ''; } catch { /* storage off: the field still works for this page */ }
export function getToken() { return token; }
export function setToken(value) {
  token = String(value || '').trim();
  try {
    if (token) sessionStorage.setItem(TOKEN_KEY, token); else sessionStorage.removeItem(TOKEN_KEY);
  } catch { /* storage off */ }
}

export class ApiError extends Error {
  constructor(status, problem) {
    super(problem && problem.detail ? problem.detail : `HTTP ${status}`);
    this.status = status;
    this.problem = problem || { title: `HTTP ${status}`, status, detail: `HTTP ${status}`, errors: [] };
  }
  get errors() { return Array.isArray(this.problem.errors) ? this.problem.errors : []; }
  get unauthorized() { return this.status === 401; }
}

// What to tell the user about a 401: where the token goes, and whether the one sent was refused.
export function tokenAdvice(sent) {
  return sent
    ? 'The service refused the API token (401): check the “API token” field at the top of the page.'
    : 'The service needs an API token for this (401): enter it in the “API token” field at the top of the page.';
}

async function parse(response) {
  const type = response.headers.get('content-type') || '';
  if (type.includes('json')) {
    try { return await response.json(); } catch { return null; }
  }
  return null;
}

// method, path ("/v1/..."), optional JSON body and AbortSignal. Resolves {status, body, headers}.
export async function request(method, path, body, signal) {
  const init = { method, headers: { Accept: 'application/json, application/problem+json' }, signal };
  const writes = method === 'POST' || method === 'DELETE';
  const sent = writes && !!token;
  if (sent) init.headers.Authorization = `Bearer ${token}`;
  if (body !== undefined) {
    init.headers['Content-Type'] = 'application/json';
    init.body = JSON.stringify(body);
  }
  let response;
  try {
    response = await fetch(path, init);
  } catch (e) {
    if (e.name === 'AbortError') throw e;
    throw new ApiError(0, { title: 'Network error', status: 0, detail: `the service did not answer (${e.message})`, errors: [] });
  }
  const doc = await parse(response);
  if (!response.ok) {
    let problem = doc;
    if (!problem || typeof problem !== 'object') problem = { title: response.statusText, status: response.status, detail: `HTTP ${response.status}`, errors: [] };
    const retry = response.headers.get('retry-after');
    if (retry) problem.retry_after_s = Number(retry);
    const err = new ApiError(response.status, problem);
    if (response.status === 401) {
      err.tokenSent = sent;
      window.dispatchEvent(new CustomEvent('prsm:unauthorized', { detail: { sent, method, path } }));
    }
    throw err;
  }
  return { status: response.status, body: doc, headers: response.headers };
}

export const api = {
  openapi: () => request('GET', '/v1/openapi.json').then(r => r.body),
  schema: name => request('GET', `/v1/schemas/${encodeURIComponent(name)}`).then(r => r.body),
  version: () => request('GET', '/v1/version').then(r => r.body),
  // The analysis; over the service's synchronous budget the answer is an analysis job (202, or
  // 200 with the cached job): it is polled at its Location until done, and its result returned.
  async analyze(doc, signal) {
    const r = await request('POST', '/v1/designs/analyze', doc, signal);
    let job = r.body;
    if (!(job && typeof job === 'object' && typeof job.state === 'string' && typeof job.id === 'string')) return job;
    const path = r.headers.get('location') || `/v1/analyses/${job.id}`;
    for (let wait = 100; job.state === 'queued' || job.state === 'running'; wait = Math.min(2 * wait, 1000)) {
      await new Promise((resolve, reject) => {
        const t = setTimeout(resolve, wait);
        if (signal) signal.addEventListener('abort', () => { clearTimeout(t); reject(new DOMException('aborted', 'AbortError')); }, { once: true });
      });
      job = (await request('GET', path, undefined, signal)).body;
    }
    if (job.state === 'done') return job.result;
    throw new ApiError(job.problem && job.problem.status || 500,
      job.problem || { title: 'Analysis job ' + job.state, status: 500, detail: `the analysis job was ${job.state}`, errors: [] });
  },
  // collection: "studies" (later "optimizations", "allocations"): same job machinery for each kind
  submit: (collection, doc) => request('POST', `/v1/${collection}`, doc),
  job: path => request('GET', path).then(r => r.body),
  cancel: path => request('DELETE', path).then(r => r.body),
  list: (collection, limit) => request('GET', `/v1/${collection}?limit=${limit}`).then(r => r.body),
  async text(path) {
    const r = await fetch(path);
    if (!r.ok) throw new ApiError(r.status, await parse(r));
    return r.text();
  },
  async example(name) {
    const r = await fetch(`examples/${encodeURIComponent(name)}`);
    if (!r.ok) throw new ApiError(r.status, await parse(r));
    return r.json();
  },
};

// One line for a problem list: "pointer: message" items joined, for places without a field.
export function describe(err) {
  if (!(err instanceof ApiError)) return String(err && err.message ? err.message : err);
  if (err.unauthorized) return tokenAdvice(err.tokenSent);
  const p = err.problem;
  const list = err.errors.map(e => (e.pointer ? `${e.pointer}: ` : '') + e.message);
  const head = `${p.title || 'Error'} (${err.status || 'no answer'})`;
  return list.length ? `${head}: ${list.join('; ')}` : `${head}: ${p.detail || ''}`;
}
