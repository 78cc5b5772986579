// The page: settings -> progressive render (polled level by level), rays per second by kind,
// a click on the render -> that pixel's ray tree in the 3D view and the side panel.
'use strict';

const $ = id => document.getElementById(id);
const NUMBERS = ['width', 'height', 'bounces', 'shadow_samples', 'aa', 'seed'];

const app = {
  view: null,        // the 3D view (gl.js), or null without WebGL
  job: null,         // the job shown: its status from the server
  camera: null,      // the render camera sent with the settings (null: the scene's)
  sceneCamera: null, // the scene's own camera
  poll: null,
  shownLevel: 0,     // the finest level of the job on screen (1-based)
};

function showError(text) { $('error').textContent = text || ''; }

// fetch, with the server's JSON error message as the exception.
async function api(path, options) {
  const r = await fetch(path, options);
  const text = await r.text();
  let body = null;
  try { body = JSON.parse(text); } catch (_) { body = null; }
  if (!r.ok) throw new Error((body && body.error) || `${r.status} ${text}`);
  return body;
}

function settingsFromForm() {
  const f = $('settings'), s = {};
  for (const el of f.elements) {
    if (!el.name) continue;
    s[el.name] = NUMBERS.includes(el.name) ? Number(el.value) : el.value;
  }
  if (app.camera) s.camera = app.camera;
  return s;
}

function fillForm(settings) {
  const f = $('settings');
  for (const el of f.elements) if (el.name && settings[el.name] !== undefined) el.value = settings[el.name];
}

function options(select, names) {
  select.innerHTML = '';
  for (const n of names) { const o = document.createElement('option'); o.textContent = n; select.appendChild(o); }
}

// Rates in millions; a kind the engine did not time (the reference) is null and shows '-'.
const mega = x => (x === null || x === undefined ? '-' : (x / 1e6).toFixed(2));

function showStats(status) {
  const body = $('stats').querySelector('tbody');
  body.innerHTML = '';
  status.levels.forEach((l, k) => {
    const r = l.rays_per_second;
    const tr = document.createElement('tr');
    for (const v of [k, `${l.width}×${l.height}`, l.seconds.toFixed(3), mega(r.camera_per_thread_second), mega(r.shadow_per_thread_second), mega(r.reflection_per_thread_second), mega(r.total_per_second)]) {
      const td = document.createElement('td'); td.textContent = v; tr.appendChild(td);
    }
    body.appendChild(tr);
  });
  const [done, total] = status.progress;
  const levels = status.sizes.length;
  const fraction = status.state === 'done' ? 1 : (status.levels.length + (total ? done / total : 0)) / levels;
  $('progress-bar').style.width = `${Math.round(100 * fraction)}%`;
}

// Shows level k of the job once it is loaded, so the image never goes blank between levels.
function showLevel(status, k) {
  const img = new Image();
  img.onload = () => {
    // Images may load out of order: never replace a finer level by a coarser one.
    if (!app.job || app.job.job !== status.job || k + 1 <= app.shownLevel) return;
    app.shownLevel = k + 1;
    const el = $('render');
    el.src = img.src;
    el.dataset.level = String(k + 1);
    const full = status.sizes[status.sizes.length - 1];
    el.style.height = `${512 * full[1] / full[0]}px`;
    $('render-info').textContent = `job ${status.job}: level ${k + 1} of ${status.sizes.length}, ` +
      `${status.sizes[k][0]}×${status.sizes[k][1]} of ${full[0]}×${full[1]}`;
  };
  img.src = `/api/render/${status.job}/${k}.png`;
}

async function pollJob(id) {
  let shown = 0;
  clearInterval(app.poll);
  const tick = async () => {
    if (!app.job || app.job.job !== id) return;
    let status;
    try { status = await api(`/api/render/${id}`); } catch (e) { showError(e.message); clearInterval(app.poll); return; }
    if (!app.job || app.job.job !== id) return;
    app.job = status;
    // Levels that arrived together: only the finest is worth loading.
    if (shown < status.levels.length) { shown = status.levels.length; showLevel(status, shown - 1); }
    showStats(status);
    const el = $('render');
    el.dataset.levels = String(status.sizes.length);
    el.dataset.state = status.state;
    if (status.state === 'failed') showError(`render failed: ${status.error}`);
    if (['done', 'failed', 'superseded'].includes(status.state)) clearInterval(app.poll);
  };
  app.poll = setInterval(tick, 120);
  tick();
}

async function render() {
  showError('');
  try {
    const status = await api('/api/render', { method: 'POST', body: JSON.stringify(settingsFromForm()) });
    app.job = status;
    app.shownLevel = 0;
    const el = $('render');
    el.dataset.job = String(status.job);
    el.dataset.level = '0';
    el.dataset.state = status.state;
    if (app.view) app.view.setFrame(status.frame);
    pollJob(status.job);
  } catch (e) { showError(e.message); }
}

// What a segment did, in words.
function outcome(s) {
  if (s.kind === 'shadow') {
    const sh = s.shadow || {};
    if (sh.blocked === null || sh.blocked === undefined) return `light ${sh.light}: not tested (shadows off)`;
    if (!sh.blocked) return `light ${sh.light}: seen`;
    const b = sh.blocker;
    return `light ${sh.light}: blocked` + (b ? ` by ${b.primitive.shape} ${b.primitive.index} at t = ${b.t.toPrecision(4)}` : '');
  }
  if (!s.hit) return 'missed: background';
  const p = s.hit.primitive;
  return `hit ${p.shape} ${p.index}` + (p.face !== null && p.face !== undefined ? ` (face ${p.face})` : '') + ` at t = ${s.hit.t.toPrecision(4)}`;
}

// The tree's side panel: one row per segment with what it added to the pixel, and the JSON.
function showTree(tree) {
  const body = $('segments').querySelector('tbody');
  body.innerHTML = '';
  tree.segments.forEach(s => {
    const tr = document.createElement('tr');
    tr.className = RayView.style(s);
    const contribution = s.contribution.map(v => v.toFixed(5)).join(' ');
    for (const v of [s.id, s.parent === null ? '' : s.parent, s.kind, s.depth, outcome(s), contribution]) {
      const td = document.createElement('td'); td.textContent = v; tr.appendChild(td);
    }
    body.appendChild(tr);
  });
  $('tree-json').textContent = JSON.stringify(tree, null, 1);
  const sum = tree.sum.map(v => v.toFixed(5)).join(' ');
  const check = tree.check ? (tree.check.agrees ? ', equal to both engines\' render of it' :
    `, NOT equal to the engines' render (reference ${tree.check.reference.map(v => v.toFixed(5)).join(' ')}, wavefront ${tree.check.wavefront.map(v => v.toFixed(5)).join(' ')})`) : '';
  $('tree-title').textContent = `pixel (${tree.pixel.x}, ${tree.pixel.y}): ${tree.segments.length} segments, ` +
    `contributions sum to ${sum}${check}`;
  const t = $('tree');
  t.dataset.x = String(tree.pixel.x); t.dataset.y = String(tree.pixel.y);
  t.dataset.segments = String(tree.segments.length);
  if (app.view) app.view.setTree(tree.segments);
}

async function pick(event) {
  if (!app.job) return;
  const el = $('render');
  const [w, h] = app.job.sizes[app.job.sizes.length - 1];
  const rect = el.getBoundingClientRect();
  const x = Math.min(w - 1, Math.max(0, Math.floor((event.clientX - rect.left) / rect.width * w)));
  const y = Math.min(h - 1, Math.max(0, Math.floor((event.clientY - rect.top) / rect.height * h)));
  const m = $('marker');
  m.hidden = false;
  m.style.left = `${(x + 0.5) / w * rect.width}px`;
  m.style.top = `${(y + 0.5) / h * rect.height}px`;
  try { showTree(await api(`/api/pixel?job=${app.job.job}&x=${x}&y=${y}`)); } catch (e) { showError(e.message); }
}

async function start() {
  let info;
  try { info = await api('/api/scene'); } catch (e) { showError(`cannot load the scene: ${e.message}`); return; }
  $('source').textContent = info.scene.source + (info.scene.truncated ?
    ` (3D view: first ${info.scene.positions.length / 9} of ${info.scene.triangle_count} triangles)` : '');
  $('simd').textContent = `SIMD: ${info.simd}`;
  options($('settings').elements.sampler, info.samplers);
  options($('settings').elements.engine, info.engines);
  fillForm(info.settings);
  app.sceneCamera = info.settings.camera;
  try {
    app.view = RayView.create($('view3d'));
  } catch (e) { showError(`WebGL: ${e.message}`); }
  if (app.view) { app.view.setPalette(info.palette); app.view.setScene(info.scene); app.view.overview(app.sceneCamera); }
  Compare.init(info.samplers, settingsFromForm);
  $('settings').addEventListener('change', render);
  $('render').addEventListener('click', pick);
  $('use-view').addEventListener('click', () => { if (app.view) { app.camera = app.view.camera(); render(); } });
  $('reset-camera').addEventListener('click', () => {
    app.camera = null;
    if (app.view) app.view.overview(app.sceneCamera);
    render();
  });
  render();
}

start();
