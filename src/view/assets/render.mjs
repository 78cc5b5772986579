// The render panel's logic: the progress of a job, the pixel under the pointer, and the
// lab's keys. No DOM here: the page passes in what it read.

/** How far a job is (its status from GET /api/render/{job}): `fraction` of the whole (levels
 * done plus the share of the one being rendered), `text` as "level k of n: done/total tiles"
 * ("rows" for the reference engine, which reports rows). */
export function progress(status) {
  const n = status.sizes.length, finished = status.levels.length;
  const [done, total] = status.progress || [0, 0];
  const unit = status.settings && status.settings.engine === 'reference' ? 'rows' : 'tiles';
  const all = status.state === 'done';
  // While a level renders it is the next one; once every level is in, the last.
  const level = Math.min(n, all ? n : finished + 1);
  const fraction = all ? 1 : Math.min(1, (finished + (total ? done / total : 0)) / Math.max(1, n));
  const what = { queued: 'queued', superseded: 'superseded', failed: 'failed' }[status.state];
  const text = `level ${level} of ${n}: ${done}/${total} ${unit}` + (what ? ` (${what})` : '');
  return { fraction, text, level, levels: n, done, total };
}

/** What the cost-map overlay's legend says for a level's `cost` (its status's `cost`: kind,
 * measure, high, largest, per_ray), or null when the level has none. */
export function costLegend(cost) {
  if (!cost) return null;
  const rays = { camera: 'camera rays', shadow: 'shadow rays', reflection: 'mirror rays', all: 'all rays' }[cost.kind] || cost.kind;
  const what = { nodes: 'BVH nodes visited', tests: 'primitives tested' }[cost.measure] || cost.measure;
  const mean = cost.per_ray === null || cost.per_ray === undefined ? 'no rays' : `${cost.per_ray.toFixed(2)} per ray`;
  const largest = Number.isInteger(cost.largest) ? String(cost.largest) : cost.largest.toFixed(2);
  return `cost map, ${rays}: ${what} per pixel and camera sample, 0 to ${cost.high} (largest ${largest}); ${mean}`;
}

/** The pixel (x, y) of a `width` × `height` image, from the top-left, under client point
 * (cx, cy) over an element whose box is `rect` ({left, top, width, height}); null off it. */
export function pixelAt(cx, cy, rect, width, height) {
  const u = (cx - rect.left) / rect.width, v = (cy - rect.top) / rect.height;
  if (!(u >= 0 && u < 1 && v >= 0 && v < 1)) return null;
  return { x: Math.min(width - 1, Math.floor(u * width)), y: Math.min(height - 1, Math.floor(v * height)) };
}

/** The lab's keys, as the page lists them. */
export const KEYS = [
  ['r', 'render', 'render again with the settings and camera shown'],
  ['t', 'trace', 'trace the pixel under the pointer (over the render)'],
  ['Escape', 'clear', 'clear the ray tree'],
];

/** What a keydown does: 'render', 'trace', 'clear' or null. Keys typed into a field, or with
 * Ctrl, Alt or Meta held (the browser's own shortcuts), do nothing. `event` needs `key`,
 * the modifier flags and `target.tagName`. */
export function keyAction(event) {
  if (event.ctrlKey || event.altKey || event.metaKey) return null;
  const tag = event.target && event.target.tagName ? event.target.tagName.toUpperCase() : '';
  if (['INPUT', 'SELECT', 'TEXTAREA'].includes(tag) || (event.target && event.target.isContentEditable)) return null;
  const key = event.key.length === 1 ? event.key.toLowerCase() : event.key;
  const found = KEYS.find(([k]) => k === key);
  return found ? found[1] : null;
}
