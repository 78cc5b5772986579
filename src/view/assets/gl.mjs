// The 3D view: the scene (flat-shaded triangles, tessellated spheres, light outlines), the
// render camera's frame and one pixel's ray tree, drawn with plain WebGL 1 from an orbit
// camera (orbit.mjs). Drag orbits, shift-drag or right-drag pans, the wheel zooms.
import { cross, normalize, onScreen, project, sub } from './math.mjs';
import { eyeOf, fitScene, orbit, pan, toRenderCamera, viewProjection, zoom } from './orbit.mjs';
import { lines as treeLines } from './tree.mjs';

const MESH_VS = `attribute vec3 p; attribute vec3 n; attribute vec3 c; uniform mat4 mvp;
  uniform vec3 eye; varying vec3 vc;
  void main() { gl_Position = mvp * vec4(p, 1.0);
    float l = abs(dot(normalize(n), normalize(eye - p)));
    vc = c * (0.35 + 0.65 * l); }`;
const LINE_VS = `attribute vec3 p; attribute vec3 c; uniform mat4 mvp; varying vec3 vc;
  void main() { gl_Position = mvp * vec4(p, 1.0); vc = c; }`;
const FS = `precision mediump float; varying vec3 vc;
  void main() { gl_FragColor = vec4(vc, 1.0); }`;

/** The colours of the rays: raywave::trace::palette's, sent with the scene (the lab's: camera
 * white, reflection red, shadow green, blocked shadow magenta); these until it comes. */
export const COLOURS = {
  camera: [1, 1, 1], reflection: [1, 0.16, 0.16], shadow_visible: [0.16, 0.9, 0.16],
  shadow_blocked: [0.9, 0, 0.9], shadow_untested: [0.63, 1, 0.63], main_camera: [1, 0.82, 0],
  light: [1, 1, 0.6],
};

function sphereMesh(s, out) {
  const [cx, cy, cz] = s.center, r = s.radius, rings = 16, segs = 24;
  const pt = (i, j) => {
    const th = Math.PI * i / rings, ph = 2 * Math.PI * j / segs;
    const n = [Math.sin(th) * Math.cos(ph), Math.cos(th), Math.sin(th) * Math.sin(ph)];
    return { p: [cx + r * n[0], cy + r * n[1], cz + r * n[2]], n };
  };
  for (let i = 0; i < rings; i++) for (let j = 0; j < segs; j++) {
    const a = pt(i, j), b = pt(i + 1, j), c = pt(i + 1, j + 1), d = pt(i, j + 1);
    // Counter-clockwise seen from outside.
    for (const v of [a, d, c, a, c, b]) { out.p.push(...v.p); out.n.push(...v.n); out.c.push(...s.color); }
  }
}

/** The view on `canvas`, or null without WebGL (the canvas's data-webgl says which).
 * `onMove(camera)` is called after each drag or wheel turn with the orbit camera. */
export function createView(canvas, { onMove = () => {} } = {}) {
  const gl = canvas.getContext('webgl', { antialias: true });
  if (!gl) { canvas.dataset.webgl = 'unavailable'; return null; }
  const program = (vs, fs) => {
    const pr = gl.createProgram();
    for (const [type, src] of [[gl.VERTEX_SHADER, vs], [gl.FRAGMENT_SHADER, fs]]) {
      const sh = gl.createShader(type);
      gl.shaderSource(sh, src); gl.compileShader(sh);
      if (!gl.getShaderParameter(sh, gl.COMPILE_STATUS)) throw new Error(gl.getShaderInfoLog(sh));
      gl.attachShader(pr, sh);
    }
    gl.linkProgram(pr);
    return pr;
  };
  const meshProg = program(MESH_VS, FS), lineProg = program(LINE_VS, FS);
  const buffer = data => {
    const b = gl.createBuffer();
    gl.bindBuffer(gl.ARRAY_BUFFER, b);
    gl.bufferData(gl.ARRAY_BUFFER, new Float32Array(data), gl.STATIC_DRAW);
    return b;
  };
  const state = {
    mesh: null, bounds: [[-1, -1, -1], [1, 1, 1]], lines: { scene: null, frame: null, tree: null },
    cam: { target: [0, 0, 0], dist: 5, yaw: 0, pitch: 0, fov: 0.7, radius: 1 },
  };
  const aspect = () => canvas.width / canvas.height;
  const matrix = () => viewProjection(state.cam, aspect());

  function lineSet(segments) {
    const p = [], c = [];
    for (const s of segments) { p.push(...s.a, ...s.b); c.push(...s.c, ...s.c); }
    return { p: buffer(p), c: buffer(c), count: p.length / 3 };
  }
  function attrib(prog, name, buf) {
    const loc = gl.getAttribLocation(prog, name);
    if (loc < 0) return;
    gl.bindBuffer(gl.ARRAY_BUFFER, buf);
    gl.enableVertexAttribArray(loc);
    gl.vertexAttribPointer(loc, 3, gl.FLOAT, false, 0, 0);
  }
  function draw() {
    gl.viewport(0, 0, canvas.width, canvas.height);
    gl.clearColor(0.05, 0.05, 0.06, 1);
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
    const mvp = matrix();
    if (state.mesh) {
      gl.useProgram(meshProg);
      gl.enable(gl.DEPTH_TEST);
      // Walls face into the box: culling back faces lets the orbit camera see in from outside.
      gl.enable(gl.CULL_FACE);
      gl.uniformMatrix4fv(gl.getUniformLocation(meshProg, 'mvp'), false, mvp);
      gl.uniform3fv(gl.getUniformLocation(meshProg, 'eye'), eyeOf(state.cam));
      attrib(meshProg, 'p', state.mesh.p); attrib(meshProg, 'n', state.mesh.n); attrib(meshProg, 'c', state.mesh.c);
      gl.drawArrays(gl.TRIANGLES, 0, state.mesh.count);
      gl.disable(gl.CULL_FACE);
    }
    gl.useProgram(lineProg);
    gl.uniformMatrix4fv(gl.getUniformLocation(lineProg, 'mvp'), false, mvp);
    // Rays and the camera frame are drawn over the scene, as the lab's window does.
    gl.disable(gl.DEPTH_TEST);
    for (const set of [state.lines.scene, state.lines.frame, state.lines.tree]) {
      if (!set || set.count === 0) continue;
      attrib(lineProg, 'p', set.p); attrib(lineProg, 'c', set.c);
      gl.drawArrays(gl.LINES, 0, set.count);
    }
  }

  function setScene(scene) {
    const out = { p: [], n: [], c: [] };
    const pos = scene.positions, col = scene.colors;
    for (let t = 0; t < pos.length / 9; t++) {
      const v = k => [pos[9 * t + 3 * k], pos[9 * t + 3 * k + 1], pos[9 * t + 3 * k + 2]];
      const nrm = normalize(cross(sub(v(1), v(0)), sub(v(2), v(0))));
      for (let k = 0; k < 3; k++) { out.p.push(...v(k)); out.n.push(...nrm); out.c.push(col[3 * t], col[3 * t + 1], col[3 * t + 2]); }
    }
    for (const s of scene.spheres) sphereMesh(s, out);
    state.mesh = { p: buffer(out.p), n: buffer(out.n), c: buffer(out.c), count: out.p.length / 3 };
    const outline = [];
    for (const corners of scene.lights)
      corners.forEach((a, i) => outline.push({ a, b: corners[(i + 1) % corners.length], c: COLOURS.light }));
    state.lines.scene = lineSet(outline);
    state.bounds = scene.bounds;
    draw();
  }

  /** Frames the scene's bounds and `camera`'s frustum for a `width` × `height` render. */
  function fit(camera, width, height) {
    state.cam = fitScene(state.bounds, camera, width, height, aspect());
    draw();
  }

  function setFrame(frame) {
    const s = [];
    frame.corners.forEach((c, i) => {
      s.push({ a: frame.eye, b: c, c: COLOURS.main_camera });
      s.push({ a: c, b: frame.corners[(i + 1) % 4], c: COLOURS.main_camera });
    });
    state.lines.frame = lineSet(s);
    draw();
  }

  function setTree(segments) {
    state.lines.tree = lineSet(treeLines(segments, COLOURS));
    canvas.dataset.segments = String(segments.length);
    draw();
  }

  /** Takes the server's palette (0-255 per channel). */
  function setPalette(palette) {
    for (const k of Object.keys(palette)) COLOURS[k] = palette[k].map(v => v / 255);
  }

  // Pointer: orbit, pan; wheel: zoom.
  let drag = null;
  const moved = () => { draw(); onMove(toRenderCamera(state.cam)); };
  canvas.addEventListener('contextmenu', e => e.preventDefault());
  canvas.addEventListener('pointerdown', e => {
    drag = { x: e.clientX, y: e.clientY, pan: e.shiftKey || e.button === 2 };
    canvas.setPointerCapture(e.pointerId);
  });
  canvas.addEventListener('pointerup', () => { drag = null; });
  canvas.addEventListener('pointercancel', () => { drag = null; });
  canvas.addEventListener('pointermove', e => {
    if (!drag) return;
    const dx = e.clientX - drag.x, dy = e.clientY - drag.y;
    if (dx === 0 && dy === 0) return;
    drag.x = e.clientX; drag.y = e.clientY;
    state.cam = drag.pan ? pan(state.cam, dx, dy, canvas.clientHeight) : orbit(state.cam, dx, dy);
    moved();
  });
  canvas.addEventListener('wheel', e => {
    e.preventDefault();
    state.cam = zoom(state.cam, e.deltaY);
    moved();
  }, { passive: false });

  canvas.dataset.webgl = 'ok';
  return {
    setScene, setFrame, setTree, setPalette, fit, draw,
    /** The orbit camera as a render camera. */
    camera: () => toRenderCamera(state.cam),
    /** Where `points` fall on the canvas now: normalized device coordinates and clip w. */
    project: points => { const m = matrix(); return points.map(p => project(m, p)); },
    /** Whether every one of `points` is on screen. */
    shows: points => { const m = matrix(); return points.every(p => onScreen(project(m, p))); },
  };
}
