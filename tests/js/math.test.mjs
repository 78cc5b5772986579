// The matrices of src/view/assets/math.mjs against what OpenGL's conventions require.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { boxCorners, cross, dot, lookAt, multiply, onScreen, perspective, project, sub, transform } from '../../src/view/assets/math.mjs';
import { near, point, seeded } from './helpers.mjs';

test('lookAt puts the eye at the origin and the target on -z, at its distance', () => {
  const rand = seeded(1);
  for (let i = 0; i < 50; i++) {
    const eye = point(rand, 5), target = point(rand, 5);
    const d = Math.hypot(...sub(target, eye));
    const m = lookAt(eye, target, [0, 1, 0]);
    near(transform(m, eye).slice(0, 3), [0, 0, 0], 1e-9, 'eye');
    near(transform(m, target).slice(0, 3), [0, 0, -d], 1e-9, 'target');
    // A point above the eye (along +y) comes out with y >= 0: up stays up.
    const above = transform(m, [eye[0], eye[1] + 1, eye[2]]);
    assert.ok(above[1] >= -1e-12, `up went down: ${above}`);
  }
});

test('lookAt is a rotation: lengths are kept', () => {
  const rand = seeded(2);
  const m = lookAt([1, 2, 3], [-1, 0, 0.5], [0, 1, 0]);
  for (let i = 0; i < 20; i++) {
    const a = point(rand, 3), b = point(rand, 3);
    const ta = transform(m, a), tb = transform(m, b);
    near(Math.hypot(...sub(ta, tb).slice(0, 3)), Math.hypot(...sub(a, b)), 1e-9, 'distance');
  }
});

test('perspective maps the near plane to z = -1, the far plane to +1 and the fov to the edge', () => {
  const fov = 0.8, near_ = 0.5, far = 40, aspect = 1.5;
  const p = perspective(fov, aspect, near_, far);
  near(project(p, [0, 0, -near_]).z, -1, 1e-9, 'near');
  near(project(p, [0, 0, -far]).z, 1, 1e-9, 'far');
  const y = 7 * Math.tan(fov / 2), x = y * aspect;
  const top = project(p, [x, y, -7]);
  near([top.x, top.y], [1, 1], 1e-9, 'corner of the frustum');
  assert.equal(project(p, [0, 0, 3]).w < 0, true, 'behind the eye has w < 0');
});

test('multiply composes: (a·b)·p = a·(b·p)', () => {
  const rand = seeded(3);
  const a = Array.from({ length: 16 }, rand), b = Array.from({ length: 16 }, rand);
  for (let i = 0; i < 10; i++) {
    const p = point(rand);
    // b·p is homogeneous (w != 1): a acts on all four components.
    const bp = transform(b, p);
    const abp = [0, 0, 0, 0].map((_, r) => a[r] * bp[0] + a[4 + r] * bp[1] + a[8 + r] * bp[2] + a[12 + r] * bp[3]);
    near(transform(multiply(a, b), p), abp, 1e-9, 'a·b');
  }
});

test('onScreen refuses points behind the eye or outside the edges', () => {
  assert.equal(onScreen({ x: 0, y: 0, z: 0, w: 1 }), true);
  assert.equal(onScreen({ x: 0, y: 0, z: 0, w: -1 }), false);
  assert.equal(onScreen({ x: 1.01, y: 0, z: 0, w: 1 }), false);
  assert.equal(onScreen({ x: 0, y: -1.01, z: 0, w: 1 }), false);
});

test('boxCorners are the 8 distinct corners', () => {
  const c = boxCorners([[-1, -2, -3], [1, 2, 3]]);
  assert.equal(new Set(c.map(String)).size, 8);
  for (const p of c) assert.deepEqual(p.map(Math.abs), [1, 2, 3]);
  // cross and dot agree: a × b is perpendicular to both.
  const n = cross(c[1], c[2]);
  near(dot(n, c[1]), 0, 1e-12); near(dot(n, c[2]), 0, 1e-12);
});
