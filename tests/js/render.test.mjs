// The render panel's logic (src/view/assets/render.mjs): the progress line, the pixel under
// the pointer, the lab's keys.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { KEYS, costLegend, keyAction, pixelAt, progress } from '../../src/view/assets/render.mjs';

const SIZES = [[8, 8], [16, 16], [32, 32], [64, 64]];
const level = () => ({ width: 1, height: 1 });

test('progress: the level being rendered, its work units, and the share of the whole', () => {
  let p = progress({ state: 'running', sizes: SIZES, levels: [level(), level()], progress: [3, 12], settings: { engine: 'wavefront' } });
  assert.equal(p.text, 'level 3 of 4: 3/12 tiles');
  assert.equal(p.fraction, (2 + 3 / 12) / 4);
  p = progress({ state: 'done', sizes: SIZES, levels: SIZES.map(level), progress: [12, 12], settings: { engine: 'reference' } });
  assert.equal(p.text, 'level 4 of 4: 12/12 rows');
  assert.equal(p.fraction, 1);
  p = progress({ state: 'queued', sizes: SIZES, levels: [], progress: [0, 0], settings: {} });
  assert.equal(p.text, 'level 1 of 4: 0/0 tiles (queued)');
  assert.equal(p.fraction, 0);
  p = progress({ state: 'superseded', sizes: SIZES, levels: [level()], progress: [2, 9], settings: {} });
  assert.equal(p.text, 'level 2 of 4: 2/9 tiles (superseded)');
  // One level only (a tiny image).
  p = progress({ state: 'running', sizes: [[2, 2]], levels: [], progress: [1, 2], settings: {} });
  assert.deepEqual([p.text, p.fraction], ['level 1 of 1: 1/2 tiles', 0.5]);
});

test('pixelAt maps the element\'s box onto the image, from the top-left, and nothing off it', () => {
  const rect = { left: 100, top: 50, width: 512, height: 256 };
  assert.deepEqual(pixelAt(100, 50, rect, 64, 32), { x: 0, y: 0 });
  assert.deepEqual(pixelAt(100 + 8 * 32 + 4, 50 + 8 * 16 + 4, rect, 64, 32), { x: 32, y: 16 });
  assert.deepEqual(pixelAt(611.9, 305.9, rect, 64, 32), { x: 63, y: 31 });
  for (const [x, y] of [[99.9, 60], [612, 60], [300, 49], [300, 306]]) assert.equal(pixelAt(x, y, rect, 64, 32), null, `${x}, ${y}`);
});

const key = (k, extra = {}) => ({ key: k, target: { tagName: 'BODY' }, ...extra });

test('the lab\'s keys: r renders, t traces, Escape clears', () => {
  assert.equal(keyAction(key('r')), 'render');
  assert.equal(keyAction(key('R')), 'render');
  assert.equal(keyAction(key('t')), 'trace');
  assert.equal(keyAction(key('Escape')), 'clear');
  assert.equal(keyAction(key('x')), null);
  assert.deepEqual(KEYS.map(k => k[0]), ['r', 't', 'Escape']);
});

test('keys typed into a field, or with Ctrl, Alt or Meta, are the field\'s or the browser\'s', () => {
  for (const tag of ['INPUT', 'select', 'TEXTAREA']) assert.equal(keyAction(key('r', { target: { tagName: tag } })), null, tag);
  assert.equal(keyAction(key('r', { target: { tagName: 'DIV', isContentEditable: true } })), null);
  for (const m of ['ctrlKey', 'altKey', 'metaKey']) assert.equal(keyAction(key('r', { [m]: true })), null, m);
  assert.equal(keyAction(key('t', { shiftKey: true })), 'trace');
});

test('the cost-map legend names the rays, the count, the scale and the mean per ray', () => {
  assert.equal(costLegend(null), null);
  assert.equal(costLegend(undefined), null);
  assert.equal(
    costLegend({ kind: 'shadow', measure: 'nodes', high: 20, largest: 23, per_ray: 2.0231 }),
    'cost map, shadow rays: BVH nodes visited per pixel and camera sample, 0 to 20 (largest 23); 2.02 per ray',
  );
  assert.equal(
    costLegend({ kind: 'all', measure: 'tests', high: 4, largest: 0.5, per_ray: null }),
    'cost map, all rays: primitives tested per pixel and camera sample, 0 to 4 (largest 0.50); no rays',
  );
});
