// The 3D view's orbit camera: a target, a distance, yaw and pitch, a vertical field of view.
// Every function returns a new camera and leaves its argument alone; none touches the DOM.
//
//   eye = target + dist · (cos pitch · sin yaw, sin pitch, cos pitch · cos yaw), up = +y
//
// fitOrbit frames a set of points exactly: for a view direction, each point gives a lower
// bound on the distance along each screen axis, and a sideways shift of the target balances
// the two sides (closed form, below), so every point lands inside the margin.
import { add, boxCorners, cross, dot, length, lookAt, multiply, normalize, perspective, scale, sub } from './math.mjs';

export const UP = [0, 1, 0];
/** Pitch stays short of straight up or down, where `UP` is parallel to the view. */
export const MAX_PITCH = 1.55;
/** The field of view the 3D view opens with. */
export const OVERVIEW_FOV = 40 * Math.PI / 180;

const clampPitch = p => Math.max(-MAX_PITCH, Math.min(MAX_PITCH, p));

/** Unit vectors of the view: w from the target to the eye, r to the right, u up on screen. */
export function basis(yaw, pitch) {
  const cp = Math.cos(pitch);
  const w = [cp * Math.sin(yaw), Math.sin(pitch), cp * Math.cos(yaw)];
  const r = normalize(cross(UP, w));
  return { w, r, u: cross(w, r) };
}

/** The eye of orbit camera `o`. */
export const eyeOf = o => add(o.target, scale(basis(o.yaw, o.pitch).w, o.dist));

/** Near and far planes: near a hundredth of the distance, far past everything within
 * `o.radius` of the target. */
export const depthRange = o => [o.dist * 0.01, 4 * (o.dist + o.radius)];

/** The projection · view matrix of `o` for a viewport of width / height `aspect`. */
export function viewProjection(o, aspect) {
  const [near, far] = depthRange(o);
  return multiply(perspective(o.fov, aspect, near, far), lookAt(eyeOf(o), o.target, UP));
}

/** A drag of (dx, dy) pixels: turns round the target, at the same distance. */
export const orbit = (o, dx, dy) => ({ ...o, yaw: o.yaw - dx * 0.01, pitch: clampPitch(o.pitch + dy * 0.01) });

/** A pan drag of (dx, dy) pixels in a viewport `height` pixels high: the target moves with
 * the pointer, in the plane facing the eye. */
export function pan(o, dx, dy, height) {
  const { r, u } = basis(o.yaw, o.pitch);
  const k = o.dist * Math.tan(o.fov / 2) * 2 / height;
  return { ...o, target: add(o.target, add(scale(r, -dx * k), scale(u, dy * k))) };
}

/** A wheel turn of `deltaY`: closer for negative values, further for positive ones. */
export const zoom = (o, deltaY) => ({ ...o, dist: Math.max(1e-3, o.dist * Math.exp(deltaY * 0.001)) });

/** The orbit camera as a render camera (the server's settings JSON). */
export const toRenderCamera = o => ({
  position: eyeOf(o), look_at: o.target.slice(), up: UP.slice(), fov_degrees: o.fov * 180 / Math.PI,
});

/** A render camera as an orbit camera; its up hint is replaced by +y. */
export function fromRenderCamera(c, radius = 1) {
  const d = sub(c.position, c.look_at), dist = length(d) || 1;
  return {
    target: c.look_at.slice(), dist, radius,
    yaw: Math.atan2(d[0], d[2]), pitch: clampPitch(Math.asin(Math.max(-1, Math.min(1, d[1] / dist)))),
    fov: c.fov_degrees * Math.PI / 180,
  };
}

/** The render camera's frame for a `width` × `height` image, as raywave's CameraRays builds
 * it (src/render/camera.rs): the eye, and the image's corners one unit in front of it,
 * top-left first, clockwise; the field of view spans the longer side. */
export function renderFrame(c, width, height) {
  const forward = normalize(sub(c.look_at, c.position));
  const right = normalize(cross(forward, c.up)), up = cross(right, forward);
  const half = Math.tan(c.fov_degrees * Math.PI / 360), side = Math.max(width, height);
  const hx = half * width / side, hy = half * height / side;
  const corner = (sx, sy) => add(add(add(c.position, forward), scale(right, sx * hx)), scale(up, sy * hy));
  return { eye: c.position.slice(), corners: [corner(-1, 1), corner(1, 1), corner(1, -1), corner(-1, -1)] };
}

/** The overview's direction: the render camera's, turned 0.8 rad aside and 0.35 rad up, so
 * that its frustum and what it looks at are seen from the side. */
export function overviewAngles(c) {
  const o = fromRenderCamera(c);
  return { yaw: o.yaw + 0.8, pitch: clampPitch(o.pitch + 0.35) };
}

/** An orbit camera looking from (yaw, pitch) with field of view `fov` that frames every
 * point of `points` inside `margin` of a viewport of width / height `aspect`.
 *
 * In view coordinates (x right, y up, z towards the eye, about a target c), a point is on
 * screen when |x − s| <= (dist − z)·tan_x, where s is a sideways shift of the target. That is
 * dist >= z + (x − s)/tan_x and dist >= z − (x − s)/tan_x for every point: with A and B the
 * largest z + x/tan_x and z − x/tan_x, the least distance is (A + B)/2 at s = (A − B)·tan_x/2.
 * Likewise vertically; the larger distance keeps both axes inside, and each axis is then
 * centred at that distance (`centred`). Points stay at least 5% of the distance in front of
 * the eye, clear of the near plane. */
export function fitOrbit(points, { yaw, pitch, fov, aspect = 1, margin = 0.9 }) {
  pitch = clampPitch(pitch);
  const { w, r, u } = basis(yaw, pitch);
  const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
  for (const p of points) for (let k = 0; k < 3; k++) { lo[k] = Math.min(lo[k], p[k]); hi[k] = Math.max(hi[k], p[k]); }
  const centre = points.length ? scale(add(lo, hi), 0.5) : [0, 0, 0];
  const tanY = Math.tan(fov / 2) * margin, tanX = tanY * aspect;
  const axis = (along, tan) => {
    let a = -Infinity, b = -Infinity;
    for (const p of points) {
      const d = sub(p, centre), z = dot(d, w), x = dot(d, along);
      a = Math.max(a, z + x / tan); b = Math.max(b, z - x / tan);
    }
    return { dist: (a + b) / 2 };
  };
  let dist = Math.max(axis(r, tanX).dist, axis(u, tanY).dist, 1e-3);
  for (const p of points) dist = Math.max(dist, dot(sub(p, centre), w) / 0.95);
  const target = add(centre, add(scale(r, centred(points, centre, w, r, dist)), scale(u, centred(points, centre, w, u, dist))));
  const radius = Math.max(1e-3, ...points.map(p => length(sub(p, target))));
  return { target, dist, yaw, pitch, fov, radius };
}

/** The shift s along `along` that centres `points` on screen for an eye `dist` from
 * `centre` along `w`: where the largest and the smallest (x − s)/depth are opposite. Their
 * sum falls as s grows, so bisection finds it. At the distance the axis itself needs this is
 * the closed form's shift; on the other axis, with room to spare, it centres rather than
 * leaving the points against one edge. */
function centred(points, centre, w, along, dist) {
  const xs = points.map(p => { const d = sub(p, centre); return [dot(d, along), dist - dot(d, w)]; });
  const balance = s => {
    let hi = -Infinity, lo = Infinity;
    for (const [x, depth] of xs) { const t = (x - s) / depth; hi = Math.max(hi, t); lo = Math.min(lo, t); }
    return hi + lo;
  };
  let a = Math.min(...xs.map(p => p[0])), b = Math.max(...xs.map(p => p[0]));
  for (let k = 0; k < 100 && b - a > 1e-12 * (1 + Math.abs(a) + Math.abs(b)); k++) {
    const m = (a + b) / 2;
    if (balance(m) > 0) a = m; else b = m;
  }
  return (a + b) / 2;
}

/** What the 3D view opens with: the scene's bounds and the render camera's frame (eye and
 * image corners, for a `width` × `height` render) together, seen from the overview's side. */
export function fitScene(bounds, camera, width, height, aspect = 1) {
  const frame = renderFrame(camera, width, height);
  return fitOrbit([...boxCorners(bounds), frame.eye, ...frame.corners],
    { ...overviewAngles(camera), fov: OVERVIEW_FOV, aspect });
}
