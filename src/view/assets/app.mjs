// The page: settings -> progressive render (polled level by level, each level drawn 1:1 into
// the render canvas), rays per second by kind, a pixel -> its ray tree in the 3D view and the
// side panel, the lab's keys. The logic lives in the modules it imports (tested under node,
// tests/js/); this file reads and writes the DOM.
import { initCompare } from './compare.mjs';
import { debounce } from './debounce.mjs';
import { createView } from './gl.mjs';
import { renderFrame } from './orbit.mjs';
import { KEYS, costLegend, keyAction, pixelAt, progress } from './render.mjs';
import { validate } from './settings.mjs';
import { api, errorMessage, urlWithoutToken } from './token.mjs';
import { rows, title } from './tree.mjs';

const $ = id => document.getElementById(id);
/** How long the orbit re-render waits after the last move. */
const FOLLOW_MS = 200;

const app = {
  view: null,        // the 3D view (gl.mjs), or null without WebGL
  job: null,         // the job shown: its status from the server
  camera: null,      // the render camera sent with the settings (null: the scene's)
  sceneCamera: null, // the scene's own camera
  choices: {},       // the server's samplers and engines
  poll: null,
  shownLevel: 0,     // the finest level of the job on screen (1-based)
  pointer: null,     // the pointer over the render, in client coordinates, or null
  traces: 0,         // traces asked for (the latest is the one shown)
};

function showError(text) { $('error').textContent = text || ''; }

/** The form's settings, checked; errors are shown and marked on their fields. */
function formSettings() {
  const values = {};
  for (const el of $('settings').elements) if (el.name) values[el.name] = el.value;
  const { settings, errors } = validate(values, app.choices);
  for (const el of $('settings').elements) {
    if (el.name) el.toggleAttribute('aria-invalid', errors.some(e => e.field === el.name));
  }
  if (app.camera) settings.camera = app.camera;
  return { settings, errors };
}

function fillForm(settings) {
  for (const el of $('settings').elements) if (el.name && settings[el.name] !== undefined) el.value = settings[el.name];
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
    const r = l.rays;
    const tr = document.createElement('tr');
    for (const v of [k, `${l.width}×${l.height}`, r.total.seconds.toFixed(3), mega(r.camera.rays_per_thread_second), mega(r.shadow.rays_per_thread_second), mega(r.reflection.rays_per_thread_second), mega(r.total.rays_per_second)]) {
      const td = document.createElement('td'); td.textContent = v; tr.appendChild(td);
    }
    body.appendChild(tr);
  });
  const p = progress(status);
  $('progress-bar').style.width = `${Math.round(1000 * p.fraction) / 10}%`;
  $('progress-text').textContent = p.text;
}

/** Draws level k of the job into the render canvas at 1:1 once it is loaded, so the image
 * never goes blank between levels. The PNG is decoded without colour conversion: the canvas
 * holds the server's bytes. */
async function showLevel(status, k) {
  let bitmap;
  try {
    const r = await fetch(`/api/render/${status.job}/${k}.png`);
    if (!r.ok) {
      const text = await r.text();
      let body = null;
      try { body = JSON.parse(text); } catch (_) { body = null; }
      throw new Error(errorMessage(r.status, body, text));
    }
    bitmap = await createImageBitmap(await r.blob(), { colorSpaceConversion: 'none', premultiplyAlpha: 'none' });
  } catch (e) { showError(e.message); return; }
  // Levels may load out of order: never replace a finer level by a coarser one.
  if (!app.job || app.job.job !== status.job || k + 1 <= app.shownLevel) return;
  app.shownLevel = k + 1;
  const canvas = $('render');
  canvas.width = bitmap.width;
  canvas.height = bitmap.height;
  canvas.getContext('2d').drawImage(bitmap, 0, 0);
  bitmap.close();
  canvas.dataset.level = String(k + 1);
  const full = status.sizes[status.sizes.length - 1];
  canvas.style.height = `${512 * full[1] / full[0]}px`;
  $('render-info').textContent = `job ${status.job}: level ${k + 1} of ${status.sizes.length}, ` +
    `${status.sizes[k][0]}×${status.sizes[k][1]} of ${full[0]}×${full[1]}`;
  showCost(status, k);
}

/** Lays level k's cost map over the render, or takes the overlay away when it has none. */
function showCost(status, k) {
  const overlay = $('cost-overlay');
  const legend = costLegend(status.levels[k] && status.levels[k].cost);
  overlay.hidden = legend === null;
  $('cost-legend').hidden = legend === null;
  if (legend === null) { overlay.removeAttribute('src'); overlay.dataset.level = '0'; return; }
  overlay.src = `/api/render/${status.job}/${k}.cost.png`;
  overlay.dataset.level = String(k + 1);
  $('cost-text').textContent = legend;
}

function pollJob(id) {
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
  const { settings, errors } = formSettings();
  if (errors.length) { showError(errors.map(e => e.message).join('; ')); return; }
  showError('');
  try {
    const status = await api('/api/render', { method: 'POST', body: JSON.stringify(settings) });
    app.job = status;
    app.shownLevel = 0;
    const el = $('render');
    el.dataset.job = String(status.job);
    el.dataset.level = '0';
    el.dataset.state = status.state;
    showStats(status);
    if (app.view) app.view.setFrame(status.frame);
    pollJob(status.job);
  } catch (e) { showError(e.message); }
}

function showTree(tree) {
  const body = $('segments').querySelector('tbody');
  body.innerHTML = '';
  for (const row of rows(tree)) {
    const tr = document.createElement('tr');
    tr.className = row.className;
    for (const v of row.cells) { const td = document.createElement('td'); td.textContent = v; tr.appendChild(td); }
    body.appendChild(tr);
  }
  $('tree-json').textContent = JSON.stringify(tree, null, 1);
  $('tree-title').textContent = title(tree);
  const t = $('tree');
  t.dataset.x = String(tree.pixel.x); t.dataset.y = String(tree.pixel.y);
  t.dataset.segments = String(tree.segments.length);
  if (app.view) app.view.setTree(tree.segments);
}

function clearTree() {
  app.traces++;
  $('segments').querySelector('tbody').innerHTML = '';
  $('tree-json').textContent = '';
  $('tree-title').textContent = '';
  const t = $('tree');
  t.dataset.x = ''; t.dataset.y = ''; t.dataset.segments = '0';
  $('marker').hidden = true;
  if (app.view) app.view.setTree([]);
}

/** Traces the full-size pixel under client point (cx, cy) over the render. */
async function trace(cx, cy) {
  if (!app.job) return;
  const canvas = $('render');
  const [w, h] = app.job.sizes[app.job.sizes.length - 1];
  const rect = canvas.getBoundingClientRect();
  const p = pixelAt(cx, cy, rect, w, h);
  if (!p) return;
  const m = $('marker');
  m.hidden = false;
  m.style.left = `${(p.x + 0.5) / w * rect.width}px`;
  m.style.top = `${(p.y + 0.5) / h * rect.height}px`;
  // Only the latest trace is shown: an earlier one that answers late is dropped.
  const asked = ++app.traces;
  try {
    const tree = await api(`/api/pixel?job=${app.job.job}&x=${p.x}&y=${p.y}`);
    if (asked === app.traces) showTree(tree);
  } catch (e) { if (asked === app.traces) showError(e.message); }
}

function onKey(event) {
  const action = keyAction(event);
  if (!action) return;
  event.preventDefault();
  if (action === 'render') render();
  else if (action === 'clear') clearTree();
  else if (action === 'trace') {
    if (app.pointer) trace(app.pointer.x, app.pointer.y);
    else showError('t traces the pixel under the pointer: point at the render first');
  }
}

function listKeys() {
  const list = $('keys');
  for (const [key, , what] of KEYS) {
    const li = document.createElement('li');
    const k = document.createElement('kbd');
    k.textContent = key;
    li.appendChild(k);
    li.appendChild(document.createTextNode(` ${what}`));
    list.appendChild(li);
  }
}

/** The full-size image's width and height as the form has them. */
function formSize() {
  const { settings } = formSettings();
  return [settings.width || 1, settings.height || 1];
}

async function start() {
  // The token has been traded for a cookie: keep it out of the history and off the screen.
  history.replaceState(history.state, '', urlWithoutToken(location.href));
  listKeys();
  let info;
  try { info = await api('/api/scene'); } catch (e) { showError(`cannot load the scene: ${e.message}`); return; }
  $('source').textContent = info.scene.source + (info.scene.truncated ?
    ` (3D view: first ${info.scene.positions.length / 9} of ${info.scene.triangle_count} triangles)` : '');
  $('simd').textContent = `SIMD: ${info.simd}`;
  app.choices = { sampler: info.samplers, engine: info.engines };
  options($('settings').elements.sampler, info.samplers);
  options($('settings').elements.engine, info.engines);
  fillForm(info.settings);
  app.sceneCamera = info.settings.camera;
  const follow = debounce(camera => { app.camera = camera; render(); }, FOLLOW_MS);
  try {
    app.view = createView($('view3d'), { onMove: camera => { if ($('follow').checked) follow(camera); } });
  } catch (e) { showError(`WebGL: ${e.message}`); }
  const fit = () => {
    if (!app.view) return;
    const [w, h] = formSize();
    const camera = app.camera || app.sceneCamera;
    app.view.fit(camera, w, h);
    app.view.setFrame(renderFrame(camera, w, h));
  };
  if (app.view) { app.view.setPalette(info.palette); app.view.setScene(info.scene); fit(); }
  initCompare(info.samplers, () => formSettings().settings);
  $('settings').addEventListener('change', render);
  $('render').addEventListener('click', e => trace(e.clientX, e.clientY));
  $('render').addEventListener('pointermove', e => { app.pointer = { x: e.clientX, y: e.clientY }; });
  $('render').addEventListener('pointerleave', () => { app.pointer = null; });
  document.addEventListener('keydown', onKey);
  $('use-view').addEventListener('click', () => { if (app.view) { app.camera = app.view.camera(); render(); } });
  $('fit-view').addEventListener('click', fit);
  $('reset-camera').addEventListener('click', () => { app.camera = null; fit(); render(); });
  // For the browser test (tests/commands/view_browser.rs): the view, to project points.
  window.raywave = { app, renderFrame };
  render();
}

start();
