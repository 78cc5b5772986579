// Vectors (arrays of 3 numbers) and column-major 4×4 matrices, as WebGL takes them: the
// page's maths, free of the DOM so that node's test runner can import it (tests/js/).

export const sub = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
export const add = (a, b) => [a[0] + b[0], a[1] + b[1], a[2] + b[2]];
export const scale = (a, s) => [a[0] * s, a[1] * s, a[2] * s];
export const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
export const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
export const length = a => Math.hypot(a[0], a[1], a[2]);
/** `a` scaled to unit length (a zero vector stays zero). */
export const normalize = a => scale(a, 1 / (length(a) || 1));

/** OpenGL's projection: full vertical field of view `fovy` (radians), width / height `aspect`,
 * depths `near` and `far` mapped to NDC z = -1 and +1. */
export function perspective(fovy, aspect, near, far) {
  const f = 1 / Math.tan(fovy / 2), nf = 1 / (near - far);
  return [f / aspect, 0, 0, 0, 0, f, 0, 0, 0, 0, (far + near) * nf, -1, 0, 0, 2 * far * near * nf, 0];
}

/** The view matrix of an eye at `eye` looking at `target`, `up` the up hint: the eye goes to
 * the origin, the view direction to -z, `up` into the y-z half-plane with y > 0. */
export function lookAt(eye, target, up) {
  const z = normalize(sub(eye, target)), x = normalize(cross(up, z)), y = cross(z, x);
  return [x[0], y[0], z[0], 0, x[1], y[1], z[1], 0, x[2], y[2], z[2], 0,
    -dot(x, eye), -dot(y, eye), -dot(z, eye), 1];
}

/** The product a · b of two column-major 4×4 matrices. */
export function multiply(a, b) {
  const o = new Array(16).fill(0);
  for (let c = 0; c < 4; c++) for (let r = 0; r < 4; r++)
    for (let k = 0; k < 4; k++) o[c * 4 + r] += a[k * 4 + r] * b[c * 4 + k];
  return o;
}

/** The point `p` through matrix `m`: [x, y, z, w] in clip space. */
export function transform(m, p) {
  const out = [0, 0, 0, 0];
  for (let r = 0; r < 4; r++) out[r] = m[r] * p[0] + m[4 + r] * p[1] + m[8 + r] * p[2] + m[12 + r];
  return out;
}

/** The point `p` through matrix `m` in normalized device coordinates, with its clip w (the
 * depth in front of the eye: a point behind it has w <= 0 and is not on screen). */
export function project(m, p) {
  const [x, y, z, w] = transform(m, p);
  return { x: x / w, y: y / w, z: z / w, w };
}

/** Whether a projected point is on screen: in front of the eye and inside [-1, 1]³. */
export const onScreen = q => q.w > 0 && Math.abs(q.x) <= 1 && Math.abs(q.y) <= 1 && Math.abs(q.z) <= 1;

/** The 8 corners of the box `bounds` = [min, max]. */
export function boxCorners([lo, hi]) {
  const out = [];
  for (let k = 0; k < 8; k++) out.push([k & 1 ? hi[0] : lo[0], k & 2 ? hi[1] : lo[1], k & 4 ? hi[2] : lo[2]]);
  return out;
}
