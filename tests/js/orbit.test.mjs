// The orbit camera of src/view/assets/orbit.mjs: orbiting keeps the distance, pans keep the
// direction, cameras survive the round trip to the server's JSON, the render camera's frame
// is the one src/render/camera.rs builds, and fitting puts every point on screen.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { boxCorners, dot, length, normalize, onScreen, project, sub } from '../../src/view/assets/math.mjs';
import {
  MAX_PITCH, basis, eyeOf, fitOrbit, fitScene, fromRenderCamera, orbit, pan, renderFrame, toRenderCamera,
  viewProjection, zoom,
} from '../../src/view/assets/orbit.mjs';
import { between, near, point, seeded } from './helpers.mjs';

const camera = rand => ({
  target: point(rand, 3), dist: between(rand, 0.5, 20), yaw: between(rand, -3, 3),
  pitch: between(rand, -1.5, 1.5), fov: between(rand, 0.2, 1.5), radius: 2,
});

// The lab's Cornell box and its camera (src/render/scene: Camera::default).
const BOX = [[-1, -1, -1], [1, 1, 1]];
const LAB_CAMERA = { position: [0, 0, 8], look_at: [0, 0, 0], up: [0, 1, 0], fov_degrees: 20 };

test('orbit keeps the distance to the target and the target, and clamps the pitch', () => {
  const rand = seeded(10);
  for (let i = 0; i < 200; i++) {
    const o = camera(rand);
    const moved = orbit(o, between(rand, -300, 300), between(rand, -300, 300));
    near(length(sub(eyeOf(moved), moved.target)), o.dist, 1e-9, 'distance');
    assert.deepEqual(moved.target, o.target);
    assert.ok(Math.abs(moved.pitch) <= MAX_PITCH);
  }
  // The argument is left alone.
  const o = { target: [0, 0, 0], dist: 3, yaw: 0, pitch: 0, fov: 1, radius: 1 };
  orbit(o, 50, 50);
  assert.equal(o.yaw, 0);
});

test('a drag right turns the view to the left round the target', () => {
  const o = { target: [0, 0, 0], dist: 5, yaw: 0, pitch: 0, fov: 1, radius: 1 };
  // From +z, dragging right moves the eye towards -x (the scene turns with the hand).
  assert.ok(eyeOf(orbit(o, 100, 0))[0] < 0);
});

test('pan moves the target across the screen and keeps the view direction and distance', () => {
  const rand = seeded(11);
  for (let i = 0; i < 100; i++) {
    const o = camera(rand);
    const p = pan(o, between(rand, -50, 50), between(rand, -50, 50), 560);
    const { w } = basis(o.yaw, o.pitch);
    near(dot(sub(p.target, o.target), w), 0, 1e-9, 'the target moves in the screen plane');
    near(length(sub(eyeOf(p), p.target)), o.dist, 1e-9, 'distance');
    near(sub(eyeOf(p), p.target), sub(eyeOf(o), o.target), 1e-9, 'direction');
  }
  // A pan of the full viewport height moves the target by the view's height at its distance.
  const o = { target: [0, 0, 0], dist: 4, yaw: 0, pitch: 0, fov: 1, radius: 1 };
  near(pan(o, 0, 560, 560).target, [0, 2 * 4 * Math.tan(0.5), 0], 1e-9, 'a full-height pan');
});

test('zoom scales the distance, never to zero', () => {
  const o = { target: [0, 0, 0], dist: 4, yaw: 0, pitch: 0, fov: 1, radius: 1 };
  assert.ok(zoom(o, 100).dist > 4);
  assert.ok(zoom(o, -100).dist < 4);
  near(zoom(zoom(o, 250), -250).dist, 4, 1e-12);
  assert.ok(zoom(o, -1e6).dist > 0);
});

test('orbit camera -> render camera -> orbit camera is the same camera', () => {
  const rand = seeded(12);
  for (let i = 0; i < 200; i++) {
    const o = camera(rand);
    const c = toRenderCamera(o);
    assert.deepEqual(Object.keys(c).sort(), ['fov_degrees', 'look_at', 'position', 'up']);
    const back = fromRenderCamera(c, o.radius);
    near(back.target, o.target, 1e-9, 'target');
    near(back.dist, o.dist, 1e-9, 'dist');
    near(back.pitch, o.pitch, 1e-9, 'pitch');
    near(Math.cos(back.yaw - o.yaw), 1, 1e-9, 'yaw');
    near(back.fov, o.fov, 1e-12, 'fov');
    near(eyeOf(back), eyeOf(o), 1e-9, 'eye');
  }
});

test('render camera -> orbit camera -> render camera keeps position, look_at and fov', () => {
  const rand = seeded(13);
  for (let i = 0; i < 100; i++) {
    const c = { position: point(rand, 5), look_at: point(rand, 5), up: [0, 1, 0], fov_degrees: between(rand, 5, 120) };
    // Cameras looking within MAX_PITCH of straight up or down are clamped: keep to the rest.
    const d = normalize(sub(c.position, c.look_at));
    if (Math.abs(d[1]) > Math.sin(MAX_PITCH)) continue;
    const back = toRenderCamera(fromRenderCamera(c));
    near(back.position, c.position, 1e-9, 'position');
    near(back.look_at, c.look_at, 1e-12, 'look_at');
    near(back.fov_degrees, c.fov_degrees, 1e-9, 'fov');
  }
});

test('the render frame: corners one unit ahead, the fov across the longer side, top-left first', () => {
  const c = { position: [1, 2, 3], look_at: [0, 0, 0], up: [0, 1, 0], fov_degrees: 30 };
  const forward = normalize(sub(c.look_at, c.position));
  for (const [w, h] of [[64, 64], [100, 50], [30, 90]]) {
    const f = renderFrame(c, w, h);
    assert.deepEqual(f.eye, c.position);
    for (const corner of f.corners) near(dot(sub(corner, f.eye), forward), 1, 1e-12, 'one unit ahead');
    // The longer side spans the field of view: its edges' midpoints are fov/2 off the axis.
    const mid = (a, b) => a.map((v, k) => (v + b[k]) / 2);
    const [tl, tr, br, bl] = f.corners;
    const edge = w >= h ? mid(tr, br) : mid(tl, tr);
    const angle = Math.acos(dot(normalize(sub(edge, f.eye)), forward));
    near(angle, 15 * Math.PI / 180, 1e-9, 'half the fov');
    // Width over height, and top-left first, clockwise: seen through the camera, tl is left
    // of tr and above bl.
    near(length(sub(tr, tl)) / length(sub(bl, tl)), w / h, 1e-9, 'aspect');
    const view = viewProjection(fromRenderCamera(c), 1);
    const [ptl, ptr, , pbl] = f.corners.map(p => project(view, p));
    assert.ok(ptl.x < ptr.x && ptl.y > pbl.y, 'top-left, then clockwise');
  }
});

// Every point inside the margin: |ndc| <= margin (up to rounding), in front of the near plane.
// And centred: on each axis the extremes are equally far from the middle.
function assertFramed(o, points, aspect, margin) {
  const m = viewProjection(o, aspect);
  let widest = 0;
  const lo = [Infinity, Infinity], hi = [-Infinity, -Infinity];
  for (const p of points) {
    const q = project(m, p);
    assert.ok(onScreen(q), `point ${p} is off screen: ${JSON.stringify(q)}`);
    assert.ok(Math.abs(q.x) <= margin + 1e-9 && Math.abs(q.y) <= margin + 1e-9, `point ${p} outside the margin: ${JSON.stringify(q)}`);
    widest = Math.max(widest, Math.abs(q.x), Math.abs(q.y));
    [q.x, q.y].forEach((v, k) => { lo[k] = Math.min(lo[k], v); hi[k] = Math.max(hi[k], v); });
  }
  for (const k of [0, 1]) near(lo[k] + hi[k], 0, 1e-6, `centred on axis ${k} (${lo[k]} to ${hi[k]})`);
  return widest;
}

test('fitOrbit puts every point inside the margin, and is tight on one axis', () => {
  const rand = seeded(14);
  for (let i = 0; i < 300; i++) {
    const n = 1 + Math.floor(rand() * 20), s = between(rand, 0.01, 100);
    const centre = point(rand, 50);
    const points = Array.from({ length: n }, () => point(rand, s).map((v, k) => v + centre[k]));
    const aspect = between(rand, 0.5, 2), margin = between(rand, 0.5, 0.95);
    const o = fitOrbit(points, { yaw: between(rand, -3, 3), pitch: between(rand, -1.4, 1.4), fov: between(rand, 0.3, 1.4), aspect, margin });
    const widest = assertFramed(o, points, aspect, margin);
    // The least distance: some point touches the margin, unless the near-plane rule (points
    // 5% of the distance ahead) set the distance, or there is one point.
    if (n > 1) {
      const { w } = basis(o.yaw, o.pitch);
      const nearRule = Math.max(...points.map(p => dot(sub(p, o.target), w))) / 0.95;
      if (nearRule < o.dist * (1 - 1e-9)) near(widest, margin, 1e-6, 'tight');
    }
  }
});

test('fitScene frames the lab box and the render camera, eye and image corners', () => {
  const o = fitScene(BOX, LAB_CAMERA, 64, 64, 1);
  const frame = renderFrame(LAB_CAMERA, 64, 64);
  assertFramed(o, [...boxCorners(BOX), frame.eye, ...frame.corners], 1, 0.9);
  // The box is not a speck: its corners spread over at least a tenth of the view.
  const m = viewProjection(o, 1);
  const xs = boxCorners(BOX).map(p => project(m, p).x);
  assert.ok(Math.max(...xs) - Math.min(...xs) > 0.2, `the box spans ${Math.max(...xs) - Math.min(...xs)}`);
});

test('fitScene frames far cameras, close cameras and wide images', () => {
  const rand = seeded(15);
  for (let i = 0; i < 100; i++) {
    const lo = point(rand, 10), size = point(rand, 5).map(Math.abs);
    const bounds = [lo, lo.map((v, k) => v + size[k] + 1e-3)];
    const camera = { position: point(rand, 40), look_at: point(rand, 10), up: [0, 1, 0], fov_degrees: between(rand, 10, 90) };
    const [w, h] = [1 + Math.floor(rand() * 2048), 1 + Math.floor(rand() * 2048)];
    const aspect = between(rand, 0.6, 1.8);
    const o = fitScene(bounds, camera, w, h, aspect);
    const frame = renderFrame(camera, w, h);
    assertFramed(o, [...boxCorners(bounds), frame.eye, ...frame.corners], aspect, 0.9);
  }
});
