// The ray tree's table and lines (src/view/assets/tree.mjs) on a tree written by hand in the
// shape of raywave.ray-tree/1 (docs/TRACE.md): a camera ray, a reflection, a shadow ray that
// sees its light, one blocked by a sphere and one not tested.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { DASHES, lines, outcome, rows, style, title } from '../../src/view/assets/tree.mjs';
import { near } from './helpers.mjs';

const hit = (shape, index, t, face = null) => ({ t, primitive: { shape, index, face } });
const TREE = {
  pixel: { x: 3, y: 4 },
  sum: [0.25, 0.5, 0.125],
  check: { agrees: true, reference: [0.25, 0.5, 0.125], wavefront: [0.25, 0.5, 0.125] },
  segments: [
    { id: 0, parent: null, kind: 'camera', depth: 0, origin: [0, 0, 8], end: [0, 0, -1], hit: hit('triangle', 2, 9, 1), contribution: [0.1, 0.2, 0.05] },
    { id: 1, parent: 0, kind: 'reflection', depth: 1, origin: [0, 0, -1], end: [0, 1, 0], hit: null, contribution: [0.05, 0.1, 0.025] },
    { id: 2, parent: 0, kind: 'shadow', depth: 0, origin: [0, 0, -1], end: [0, 1, 1], shadow: { light: 0, blocked: false }, contribution: [0.1, 0.2, 0.05] },
    { id: 3, parent: 0, kind: 'shadow', depth: 0, origin: [0, 0, -1], end: [0, 1, 3], shadow: { light: 1, blocked: true, blocker: { point: [0, 0.25, 0], t: 1.25, primitive: { shape: 'sphere', index: 1 } } }, contribution: [0, 0, 0] },
    { id: 4, parent: 1, kind: 'shadow', depth: 1, origin: [0, 1, 0], end: [1, 1, 1], shadow: { light: 0, blocked: null }, contribution: [0, 0, 0] },
  ],
};
const COLOURS = { camera: [1, 1, 1], reflection: [1, 0, 0], shadow_visible: [0, 1, 0], shadow_blocked: [1, 0, 1], shadow_untested: [0.5, 1, 0.5] };

test('each segment gets its style', () => {
  assert.deepEqual(TREE.segments.map(style), ['camera', 'reflection', 'shadow_visible', 'shadow_blocked', 'shadow_untested']);
  // A shadow record without `blocked` was not tested.
  assert.equal(style({ kind: 'shadow', shadow: { light: 0 } }), 'shadow_untested');
});

test('the table: one row per segment, its cells in the columns\' order', () => {
  const r = rows(TREE);
  assert.equal(r.length, TREE.segments.length);
  assert.deepEqual(r[0].cells, ['0', '', 'camera', '0', 'hit triangle 2 (face 1) at t = 9.000', '0.10000 0.20000 0.05000']);
  assert.deepEqual(r[3].cells.slice(0, 4), ['3', '0', 'shadow', '0']);
  assert.equal(r[3].cells[4], 'light 1: blocked by sphere 1 at t = 1.250');
  assert.equal(r[3].className, 'shadow_blocked');
  assert.equal(outcome(TREE.segments[1]), 'missed: background');
  assert.equal(outcome(TREE.segments[2]), 'light 0: seen');
  assert.equal(outcome(TREE.segments[4]), 'light 0: not tested (shadows off)');
});

test('the title gives the pixel, the count, the sum and the check', () => {
  assert.equal(title(TREE), 'pixel (3, 4): 5 segments, contributions sum to 0.25000 0.50000 0.12500, equal to both engines\' render of it');
  const off = { ...TREE, check: { agrees: false, reference: [1, 0, 0], wavefront: [0, 1, 0] } };
  assert.match(title(off), /NOT equal to the engines' render \(reference 1\.00000 0\.00000 0\.00000, wavefront 0\.00000 1\.00000 0\.00000\)$/);
});

test('lines: one per segment, a blocked shadow ray solid to its blocker then dashed on its line', () => {
  const l = lines(TREE.segments, COLOURS);
  assert.equal(l.length, TREE.segments.length - 1 + 1 + DASHES);
  assert.deepEqual(l[0], { a: [0, 0, 8], b: [0, 0, -1], c: [1, 1, 1] });
  const blocked = TREE.segments[3], blocker = blocked.shadow.blocker.point;
  const solid = l[3];
  assert.deepEqual([solid.a, solid.b], [blocked.origin, blocker]);
  const dashes = l.slice(4, 4 + DASHES);
  // From the blocker to the end, on that line, with gaps: the dashes cover half of it.
  near(dashes[0].a, blocker, 1e-12, 'first dash starts at the blocker');
  let covered = 0;
  const dir = blocked.end.map((v, k) => v - blocker[k]), len = Math.hypot(...dir);
  for (const d of dashes) {
    assert.deepEqual(d.c, COLOURS.shadow_blocked);
    for (const p of [d.a, d.b]) {
      const t = p.map((v, k) => (v - blocker[k]) / len).reduce((s, v, k) => s + v * dir[k] / len, 0);
      near(p, blocker.map((v, k) => v + t * dir[k]), 1e-12, 'on the line');
      assert.ok(t >= -1e-12 && t <= 1 + 1e-12);
    }
    covered += Math.hypot(...d.b.map((v, k) => v - d.a[k]));
  }
  near(covered, len / 2, 1e-9, 'half dashed');
  assert.deepEqual(l[l.length - 1].c, COLOURS.shadow_untested);
});
