// The 3D view: the scene (flat-shaded triangles, tessellated spheres), the render camera's
// frame and one pixel's ray tree, drawn with plain WebGL 1 from an orbit camera.
// Mouse: drag orbits, shift-drag or right-drag pans, the wheel zooms.
'use strict';

const RayView = (() => {
  // Column-major 4×4 matrices.
  function perspective(fovy, aspect, near, far) {
    const f = 1 / Math.tan(fovy / 2), nf = 1 / (near - far);
    return [f / aspect, 0, 0, 0, 0, f, 0, 0, 0, 0, (far + near) * nf, -1, 0, 0, 2 * far * near * nf, 0];
  }
  const sub = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
  const add = (a, b) => [a[0] + b[0], a[1] + b[1], a[2] + b[2]];
  const scale = (a, s) => [a[0] * s, a[1] * s, a[2] * s];
  const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
  const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
  const norm = a => { const l = Math.hypot(a[0], a[1], a[2]) || 1; return scale(a, 1 / l); };
  function lookAt(eye, target, up) {
    const z = norm(sub(eye, target)), x = norm(cross(up, z)), y = cross(z, x);
    return [x[0], y[0], z[0], 0, x[1], y[1], z[1], 0, x[2], y[2], z[2], 0,
      -dot(x, eye), -dot(y, eye), -dot(z, eye), 1];
  }
  function mul(a, b) {
    const o = new Array(16).fill(0);
    for (let c = 0; c < 4; c++) for (let r = 0; r < 4; r++)
      for (let k = 0; k < 4; k++) o[c * 4 + r] += a[k * 4 + r] * b[c * 4 + k];
    return o;
  }

  const MESH_VS = `attribute vec3 p; attribute vec3 n; attribute vec3 c; uniform mat4 mvp;
    uniform vec3 eye; varying vec3 vc;
    void main() { gl_Position = mvp * vec4(p, 1.0);
      float l = abs(dot(normalize(n), normalize(eye - p)));
      vc = c * (0.35 + 0.65 * l); }`;
  const LINE_VS = `attribute vec3 p; attribute vec3 c; uniform mat4 mvp; varying vec3 vc;
    void main() { gl_Position = mvp * vec4(p, 1.0); vc = c; }`;
  const FS = `precision mediump float; varying vec3 vc; uniform float alpha;
    void main() { gl_FragColor = vec4(vc, alpha); }`;

  // The colours of the rays: raywave::trace::palette's, sent with the scene (the lab's:
  // camera white, reflection red, shadow green, blocked shadow magenta); these until it comes.
  const COLOURS = {
    camera: [1, 1, 1], reflection: [1, 0.16, 0.16], shadow_visible: [0.16, 0.9, 0.16],
    shadow_blocked: [0.9, 0, 0.9], shadow_untested: [0.63, 1, 0.63], main_camera: [1, 0.82, 0],
    light: [1, 1, 0.6],
  };

  // The style of a segment of a raywave::trace RayTree.
  function style(seg) {
    if (seg.kind !== 'shadow') return seg.kind;
    const blocked = seg.shadow ? seg.shadow.blocked : null;
    return blocked === null ? 'shadow_untested' : blocked ? 'shadow_blocked' : 'shadow_visible';
  }

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

  function create(canvas) {
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
      mesh: null, lines: { scene: null, frame: null, tree: null },
      target: [0, 0, 0], dist: 5, yaw: 0, pitch: 0, fov: 0.6, radius: 1,
    };

    function eye() {
      const cp = Math.cos(state.pitch);
      return add(state.target, scale([cp * Math.sin(state.yaw), Math.sin(state.pitch), cp * Math.cos(state.yaw)], state.dist));
    }
    function matrix() {
      const proj = perspective(state.fov, canvas.width / canvas.height, state.dist * 0.01, 4 * (state.dist + state.radius));
      return mul(proj, lookAt(eye(), state.target, [0, 1, 0]));
    }
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
        gl.uniform3fv(gl.getUniformLocation(meshProg, 'eye'), eye());
        gl.uniform1f(gl.getUniformLocation(meshProg, 'alpha'), 1);
        attrib(meshProg, 'p', state.mesh.p); attrib(meshProg, 'n', state.mesh.n); attrib(meshProg, 'c', state.mesh.c);
        gl.drawArrays(gl.TRIANGLES, 0, state.mesh.count);
        gl.disable(gl.CULL_FACE);
      }
      gl.useProgram(lineProg);
      gl.uniformMatrix4fv(gl.getUniformLocation(lineProg, 'mvp'), false, mvp);
      gl.uniform1f(gl.getUniformLocation(lineProg, 'alpha'), 1);
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
        const nrm = norm(cross(sub(v(1), v(0)), sub(v(2), v(0))));
        for (let k = 0; k < 3; k++) { out.p.push(...v(k)); out.n.push(...nrm); out.c.push(col[3 * t], col[3 * t + 1], col[3 * t + 2]); }
      }
      for (const s of scene.spheres) sphereMesh(s, out);
      state.mesh = { p: buffer(out.p), n: buffer(out.n), c: buffer(out.c), count: out.p.length / 3 };
      const lights = [];
      for (const corners of scene.lights)
        corners.forEach((a, i) => lights.push({ a, b: corners[(i + 1) % corners.length], c: COLOURS.light }));
      state.lines.scene = lineSet(lights);
      const [lo, hi] = scene.bounds;
      state.target = scale(add(lo, hi), 0.5);
      state.radius = Math.max(Math.hypot(...sub(hi, lo)) / 2, 1e-3);
      draw();
    }

    // An overview of the scene and the render camera together: the orbit camera looks at a
    // point a third of the way from what the render camera looks at towards its eye, from
    // twice the eye's distance, turned 45° aside and 20° up, with a 40° field of view.
    function overview(cam) {
      const d = sub(cam.position, cam.look_at), len = Math.hypot(...d) || 1;
      state.target = add(cam.look_at, scale(d, 0.35));
      state.dist = 2 * len;
      state.yaw = Math.atan2(d[0], d[2]) + 0.8;
      state.pitch = Math.max(-1.5, Math.min(1.5, Math.asin(Math.max(-1, Math.min(1, d[1] / len))) + 0.35));
      state.fov = 40 * Math.PI / 180;
      draw();
    }

    // The orbit camera as a render camera.
    function camera() {
      return { position: eye(), look_at: state.target.slice(), up: [0, 1, 0], fov_degrees: state.fov * 180 / Math.PI };
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

    // Each segment of the tree as lines; a blocked shadow ray solid up to its blocker and
    // dashed beyond it.
    function setTree(segments) {
      const s = [];
      for (const seg of segments) {
        const st = style(seg), colour = COLOURS[st] || [1, 1, 1];
        if (st === 'shadow_blocked') {
          const blocker = seg.shadow.blocker ? seg.shadow.blocker.point : seg.origin;
          s.push({ a: seg.origin, b: blocker, c: colour });
          const dashes = 16;
          const at = t => add(blocker, scale(sub(seg.end, blocker), t));
          for (let k = 0; k < dashes; k += 2) s.push({ a: at(k / dashes), b: at((k + 1) / dashes), c: colour });
        } else s.push({ a: seg.origin, b: seg.end, c: colour });
      }
      state.lines.tree = lineSet(s);
      canvas.dataset.segments = String(segments.length);
      draw();
    }

    // Takes the server's palette (0-255 per channel).
    function setPalette(palette) {
      for (const k of Object.keys(palette)) COLOURS[k] = palette[k].map(v => v / 255);
    }

    // Mouse: orbit, pan, zoom.
    let drag = null;
    canvas.addEventListener('contextmenu', e => e.preventDefault());
    canvas.addEventListener('pointerdown', e => { drag = { x: e.clientX, y: e.clientY, pan: e.shiftKey || e.button === 2 }; canvas.setPointerCapture(e.pointerId); });
    canvas.addEventListener('pointerup', () => { drag = null; });
    canvas.addEventListener('pointermove', e => {
      if (!drag) return;
      const dx = e.clientX - drag.x, dy = e.clientY - drag.y;
      drag.x = e.clientX; drag.y = e.clientY;
      if (drag.pan) {
        const z = norm(sub(eye(), state.target)), x = norm(cross([0, 1, 0], z)), y = cross(z, x);
        const k = state.dist * Math.tan(state.fov / 2) * 2 / canvas.clientHeight;
        state.target = add(state.target, add(scale(x, -dx * k), scale(y, dy * k)));
      } else {
        state.yaw -= dx * 0.01;
        state.pitch = Math.max(-1.55, Math.min(1.55, state.pitch + dy * 0.01));
      }
      draw();
    });
    canvas.addEventListener('wheel', e => {
      e.preventDefault();
      state.dist = Math.max(1e-3, state.dist * Math.exp(e.deltaY * 0.001));
      draw();
    }, { passive: false });

    canvas.dataset.webgl = 'ok';
    return { setScene, setFrame, setTree, setPalette, overview, camera, draw };
  }

  return { create, style, COLOURS };
})();
