// mote view: sphere impostors in plain WebGL2.
// Each particle is one quad facing the camera (or, while the camera moves
// in a large scene, one point); the fragment shader cuts the
// disc, shades it as a sphere and writes the sphere's depth, so that
// intersecting spheres (clumps) look right. window.moteScene holds what the
// page shows, for tests and the console. A trajectory file comes frame by
// frame over HTTP; a live run over a WebSocket (/api/live), one frame at a
// time: the page says "ready" after drawing one and gets the latest then.
"use strict";

const $ = (id) => document.getElementById(id);
const scene = { meta: null, frame: 0, n: 0, time: 0, playing: false, speed: 1,
                color: "species", range: [0, 1], loaded: 0, errors: [], picked: null,
                live: false, step: 0, paused: false, log: [], ended: null, rows: 0, tracked: 0 };
window.moteScene = scene;

function fail(message) {
  scene.errors.push(message);
  const e = $("error");
  e.textContent = message;
  e.style.display = "block";
  publish();
}
window.addEventListener("error", (e) => {
  // An error already shown (thrown to stop the script) is not shown twice.
  if (e.error && e.error.shown) return;
  fail(`${e.message} (${e.filename}:${e.lineno})`);
});
window.addEventListener("unhandledrejection", (e) => fail(String(e.reason)));
const consoleError = console.error;
console.error = (...args) => { scene.errors.push(args.join(" ")); consoleError(...args); };

// The page's state as JSON in a hidden element, for tests that read the DOM
// (headless Chromium's --dump-dom) and for anyone curious.
function publish() {
  const { meta, ...rest } = scene;
  $("state").textContent = JSON.stringify({ ...rest, frames: meta ? meta.frames : 0 });
}
const params = new URLSearchParams(location.search);
if (params.get("color")) scene.color = params.get("color");

const canvas = $("view");
const gl = canvas.getContext("webgl2", { antialias: true });
if (!gl) {
  // Without WebGL2 nothing can be drawn: say why, rather than the "null"
  // of the first call on a missing context.
  const why = "this browser gives the page no WebGL2 context (turned off, or no graphics driver): " +
    "try another browser, or enable hardware acceleration";
  fail(why);
  throw Object.assign(new Error(why), { shown: true });
}

// Colour maps of both sphere programs: viridis for quantities, a palette
// of eight for species.
const COLORS = `vec3 viridis(float t) {
  const vec3 c0 = vec3(0.2777, 0.0054, 0.3341), c1 = vec3(0.1050, 1.4046, 1.3846);
  const vec3 c2 = vec3(-0.3309, 0.2148, 0.0950), c3 = vec3(-4.6342, -5.7991, -19.3324);
  const vec3 c4 = vec3(6.2283, 14.1799, 56.6906), c5 = vec3(4.7764, -13.7451, -65.3530);
  const vec3 c6 = vec3(-5.4355, 4.6459, 26.3124);
  return c0 + t * (c1 + t * (c2 + t * (c3 + t * (c4 + t * (c5 + t * c6)))));
}
vec3 palette(float i) {
  const vec3 P[8] = vec3[8](vec3(0.84, 0.15, 0.16), vec3(0.12, 0.47, 0.71), vec3(0.17, 0.63, 0.17),
    vec3(1.0, 0.5, 0.05), vec3(0.58, 0.4, 0.74), vec3(0.55, 0.34, 0.29), vec3(0.89, 0.47, 0.76),
    vec3(0.5, 0.5, 0.5));
  return P[int(mod(i, 8.0))];
}
`;

const SPHERE_VS = `#version 300 es
layout(location = 0) in vec4 sphere;
layout(location = 1) in float value;
uniform mat4 view, proj;
uniform vec2 range;
uniform int categorical;
out vec2 corner;
out vec3 color;
out vec3 centre;
out float radius;
const vec2 C[4] = vec2[4](vec2(-1, -1), vec2(1, -1), vec2(-1, 1), vec2(1, 1));
${COLORS}void main() {
  corner = C[gl_VertexID & 3];  // vertex 4i + c is corner c of sphere i
  radius = sphere.w;
  vec4 c = view * vec4(sphere.xyz, 1.0);
  centre = c.xyz;
  gl_Position = proj * (c + vec4(corner * radius * 1.1, 0.0, 0.0));
  float t = clamp((value - range.x) / max(range.y - range.x, 1e-30), 0.0, 1.0);
  color = categorical == 1 ? palette(value) : viridis(t);
}`;

// Shading of both sphere programs: q is the fragment's place on the
// sphere's disc (unit radius); the sphere's depth is written, so that
// overlapping spheres (clumps) intersect exactly.
const SHADE = `
uniform mat4 proj;
out vec4 fragment;
void shade(vec2 q, vec3 color, vec3 centre, float radius) {
  float d2 = dot(q, q);
  if (d2 > 1.0) discard;
  vec3 n = vec3(q, sqrt(1.0 - d2));
  vec3 l = normalize(vec3(0.4, 0.6, 1.0));
  float diffuse = max(dot(n, l), 0.0);
  float specular = pow(max(dot(reflect(-l, n), vec3(0.0, 0.0, 1.0)), 0.0), 24.0);
  fragment = vec4(color * (0.3 + 0.7 * diffuse) + 0.2 * specular, 1.0);
  vec4 p = proj * vec4(centre + n * radius, 1.0);
  gl_FragDepth = 0.5 * p.z / p.w + 0.5;
}`;
const SPHERE_FS = `#version 300 es
precision highp float;
in vec2 corner;
in vec3 color;
in vec3 centre;
in float radius;
${SHADE}
void main() { shade(corner * 1.1, color, centre, radius); }`;

// Level of detail: one point per sphere (a quarter of the vertices),
// sized to the sphere's projected diameter with the quads' margin, shaded
// and depth-written as the quads are. Points are clipped by their centre,
// so spheres cut by the view's edge may drop out: the quads draw at rest.
const POINT_VS = `#version 300 es
layout(location = 0) in vec4 sphere;
layout(location = 1) in float value;
uniform mat4 view, proj;
uniform vec2 range;
uniform int categorical;
uniform float pixels;
out vec3 color;
out vec3 centre;
out float radius;
${COLORS}
void main() {
  vec4 c = view * vec4(sphere.xyz, 1.0);
  centre = c.xyz;
  radius = sphere.w;
  gl_Position = proj * c;
  gl_PointSize = max(1.1 * sphere.w * proj[1][1] * pixels / max(-c.z, 1e-30), 1.0);
  float t = clamp((value - range.x) / max(range.y - range.x, 1e-30), 0.0, 1.0);
  color = categorical == 1 ? palette(value) : viridis(t);
}`;
const POINT_FS = `#version 300 es
precision highp float;
in vec3 color;
in vec3 centre;
in float radius;
${SHADE}
void main() { shade(vec2(2.0 * gl_PointCoord.x - 1.0, 1.0 - 2.0 * gl_PointCoord.y) * 1.1, color, centre, radius); }`;

const LINE_VS = `#version 300 es
layout(location = 0) in vec3 p;
uniform mat4 view, proj;
void main() { gl_Position = proj * view * vec4(p, 1.0); }`;
const LINE_FS = `#version 300 es
precision highp float;
uniform vec3 tint;
out vec4 fragment;
void main() { fragment = vec4(tint, 1.0); }`;

function program(vs, fs) {
  const make = (type, source) => {
    const s = gl.createShader(type);
    gl.shaderSource(s, source);
    gl.compileShader(s);
    if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) throw new Error(gl.getShaderInfoLog(s));
    return s;
  };
  const p = gl.createProgram();
  gl.attachShader(p, make(gl.VERTEX_SHADER, vs));
  gl.attachShader(p, make(gl.FRAGMENT_SHADER, fs));
  gl.linkProgram(p);
  if (!gl.getProgramParameter(p, gl.LINK_STATUS)) throw new Error(gl.getProgramInfoLog(p));
  return p;
}

// Column-major 4×4 matrices.
function perspective(fovy, aspect, near, far) {
  const f = 1 / Math.tan(fovy / 2), d = near - far;
  return [f / aspect, 0, 0, 0, 0, f, 0, 0, 0, 0, (far + near) / d, -1, 0, 0, 2 * far * near / d, 0];
}
function lookAt(eye, target, up) {
  const sub = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
  const norm = (a) => { const l = Math.hypot(...a) || 1; return a.map((x) => x / l); };
  const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
  const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
  const z = norm(sub(eye, target)), x = norm(cross(up, z)), y = cross(z, x);
  return [x[0], y[0], z[0], 0, x[1], y[1], z[1], 0, x[2], y[2], z[2], 0, -dot(x, eye), -dot(y, eye), -dot(z, eye), 1];
}

const camera = { target: [0, 0, 0], distance: 1, theta: 0.8, phi: 1.1, home: null };
function resetCamera() {
  Object.assign(camera, JSON.parse(camera.home));
  draw();
}
function eye() {
  const c = camera, s = Math.sin(c.phi);
  return [c.target[0] + c.distance * s * Math.cos(c.theta), c.target[1] + c.distance * s * Math.sin(c.theta),
          c.target[2] + c.distance * Math.cos(c.phi)];
}

let wallVao, wallBuf, wallCount = 0, quadVao, quadBuf, indexBuf;
let spheres, points, pointVao, lines, lineVao, sphereBuf, valueBuf, lineBuf, boxCount = 0;

// The box's twelve edges, if the frame has a cell.
function setBox(cell, o) {
  if (!cell || !(Math.abs(cell[0][0] * cell[1][1] * cell[2][2]) > 0)) return;
  const corner = (i, j, k) => [0, 1, 2].map((a) => o[a] + i * cell[0][a] + j * cell[1][a] + k * cell[2][a]);
  const edges = [];
  for (const [a, b] of [[[0,0,0],[1,0,0]],[[0,1,0],[1,1,0]],[[0,0,1],[1,0,1]],[[0,1,1],[1,1,1]],
                        [[0,0,0],[0,1,0]],[[1,0,0],[1,1,0]],[[0,0,1],[0,1,1]],[[1,0,1],[1,1,1]],
                        [[0,0,0],[0,0,1]],[[1,0,0],[1,0,1]],[[0,1,0],[0,1,1]],[[1,1,0],[1,1,1]]]) {
    edges.push(...corner(...a), ...corner(...b));
  }
  gl.bindBuffer(gl.ARRAY_BUFFER, lineBuf);
  gl.bufferData(gl.ARRAY_BUFFER, new Float32Array(edges), gl.STATIC_DRAW);
  boxCount = 24;
}

function setup() {
  if (!gl) throw new Error("WebGL2 is not available in this browser");
  spheres = program(SPHERE_VS, SPHERE_FS);
  lines = program(LINE_VS, LINE_FS);
  points = program(POINT_VS, POINT_FS);
  // The quads: four vertices per sphere, each with the sphere and its
  // value (not instanced: SwiftShader draws instances 4.7 times slower).
  quadVao = gl.createVertexArray();
  gl.bindVertexArray(quadVao);
  quadBuf = gl.createBuffer();
  gl.bindBuffer(gl.ARRAY_BUFFER, quadBuf);
  gl.enableVertexAttribArray(0);
  gl.vertexAttribPointer(0, 4, gl.FLOAT, false, 20, 0);
  gl.enableVertexAttribArray(1);
  gl.vertexAttribPointer(1, 1, gl.FLOAT, false, 20, 16);
  indexBuf = gl.createBuffer();
  gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, indexBuf);
  sphereBuf = gl.createBuffer();
  valueBuf = gl.createBuffer();
  // The spheres and values as they come, one vertex per sphere.
  pointVao = gl.createVertexArray();
  gl.bindVertexArray(pointVao);
  gl.bindBuffer(gl.ARRAY_BUFFER, sphereBuf);
  gl.enableVertexAttribArray(0);
  gl.vertexAttribPointer(0, 4, gl.FLOAT, false, 0, 0);
  gl.bindBuffer(gl.ARRAY_BUFFER, valueBuf);
  gl.enableVertexAttribArray(1);
  gl.vertexAttribPointer(1, 1, gl.FLOAT, false, 0, 0);
  // Lines (box, walls): a buffer of x, y, z pairs each.
  const lineArray = () => {
    const vao = gl.createVertexArray(), buf = gl.createBuffer();
    gl.bindVertexArray(vao);
    gl.bindBuffer(gl.ARRAY_BUFFER, buf);
    gl.enableVertexAttribArray(0);
    gl.vertexAttribPointer(0, 3, gl.FLOAT, false, 0, 0);
    return [vao, buf];
  };
  [wallVao, wallBuf] = lineArray();
  [lineVao, lineBuf] = lineArray();
  gl.bindVertexArray(null);
  gl.enable(gl.DEPTH_TEST);
  gl.clearColor(1, 1, 1, 1);
}

function frameCamera(data) {
  const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
  for (let i = 0; i < data.n; i++) {
    for (let a = 0; a < 3; a++) {
      const x = data.spheres[4 * i + a];
      lo[a] = Math.min(lo[a], x);
      hi[a] = Math.max(hi[a], x);
    }
  }
  if (!(lo[0] <= hi[0])) { lo.fill(0); hi.fill(1); }
  camera.target = lo.map((l, a) => 0.5 * (l + hi[a]));
  camera.distance = 1.6 * Math.max(Math.hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]), 1e-30);
  camera.home = JSON.stringify(camera);
}

// Waits until the GPU drew everything asked so far: reading a pixel back
// does (Chromium's gl.finish returns before its GPU process is done).
const onePixel = new Uint8Array(4);
function sync() {
  gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, onePixel);
}

// Level of detail: while the camera moves, a scene whose full draw takes
// longer than INTERACTIVE_MS is drawn as points (one vertex per sphere
// instead of four: SwiftShader draws them ten times faster), and in full
// once the camera rests. A large scene's first draw is points too, so it
// shows at once; the full draw follows.
const INTERACTIVE_MS = 40, LARGE = 20000;
let fullCost = 0, settle = null;
function draw(moving) {
  if (!scene.meta || !gl) return;
  const slow = fullCost > INTERACTIVE_MS || (!fullCost && scene.n > LARGE);
  const lod = (!!moving || !scene.drawn) && slow;
  const w = canvas.clientWidth, h = canvas.clientHeight, dpr = window.devicePixelRatio || 1;
  if (canvas.width !== Math.round(w * dpr) || canvas.height !== Math.round(h * dpr)) {
    canvas.width = Math.round(w * dpr);
    canvas.height = Math.round(h * dpr);
  }
  scene.lod = lod;
  const t0 = performance.now();
  gl.viewport(0, 0, canvas.width, canvas.height);
  gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
  const view = lookAt(eye(), camera.target, [0, 0, 1]);
  const proj = perspective(0.7, canvas.width / Math.max(canvas.height, 1), camera.distance * 0.01, camera.distance * 10);
  const prog = lod ? points : spheres;
  gl.useProgram(prog);
  gl.uniformMatrix4fv(gl.getUniformLocation(prog, "view"), false, view);
  gl.uniformMatrix4fv(gl.getUniformLocation(prog, "proj"), false, proj);
  gl.uniform2f(gl.getUniformLocation(prog, "range"), scene.range[0], scene.range[1]);
  gl.uniform1i(gl.getUniformLocation(prog, "categorical"), scene.color === "species" ? 1 : 0);
  if (lod) {
    gl.uniform1f(gl.getUniformLocation(prog, "pixels"), canvas.height);
    gl.bindVertexArray(pointVao);
    gl.drawArrays(gl.POINTS, 0, scene.n);
  } else {
    gl.bindVertexArray(quadVao);
    gl.drawElements(gl.TRIANGLES, 6 * scene.n, gl.UNSIGNED_INT, 0);
  }
  if (boxCount || wallCount) {
    gl.useProgram(lines);
    gl.uniformMatrix4fv(gl.getUniformLocation(lines, "view"), false, view);
    gl.uniformMatrix4fv(gl.getUniformLocation(lines, "proj"), false, proj);
    const tint = gl.getUniformLocation(lines, "tint");
    if (boxCount) {
      gl.uniform3f(tint, 0.3, 0.3, 0.3);
      gl.bindVertexArray(lineVao);
      gl.drawArrays(gl.LINES, 0, boxCount);
    }
    if (wallCount) {
      gl.uniform3f(tint, 0.1, 0.45, 0.75);
      gl.bindVertexArray(wallVao);
      gl.drawArrays(gl.LINES, 0, wallCount);
    }
  }
  gl.bindVertexArray(null);
  scene.drawn = (scene.drawn || 0) + 1;
  if (scene.n > LARGE) {
    // Large scenes: time the draw (the wait costs nothing the next draw
    // would not wait for anyway).
    sync();
    if (!lod) fullCost = performance.now() - t0;
  }
  if (lod) {
    clearTimeout(settle);
    settle = setTimeout(() => draw(false), 200);
  }
}

function legend() {
  const c = $("legend"), g = c.getContext("2d");
  g.clearRect(0, 0, c.width, c.height);
  g.fillStyle = "#222";
  g.font = "12px system-ui, sans-serif";
  if (scene.color === "species") {
    const colors = ["#d62728", "#1f77b4", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2", "#7f7f7f"];
    scene.meta.species.slice(0, 4).forEach((s, i) => {
      g.fillStyle = colors[i % 8];
      g.fillRect(8, 8 + 12 * i, 10, 10);
      g.fillStyle = "#222";
      g.fillText(s, 24, 17 + 12 * i);
    });
    return;
  }
  const grad = g.createLinearGradient(8, 0, c.width - 8, 0);
  [[0, "#440154"], [0.25, "#3b528b"], [0.5, "#21918c"], [0.75, "#5ec962"], [1, "#fde725"]]
    .forEach(([t, col]) => grad.addColorStop(t, col));
  g.fillStyle = grad;
  g.fillRect(8, 22, c.width - 16, 14);
  g.fillStyle = "#222";
  g.fillText(scene.color, 8, 16);
  g.fillText(scene.range[0].toPrecision(3), 8, 52);
  const hiText = scene.range[1].toPrecision(3);
  g.fillText(hiText, c.width - 8 - g.measureText(hiText).width, 52);
}

// A frame's bytes: u32 N, N × (x, y, z, r), N values, little-endian.
function decode(buf) {
  const n = new DataView(buf).getUint32(0, true);
  return { n, spheres: new Float32Array(buf, 4, 4 * n), values: new Float32Array(buf, 4 + 16 * n, n) };
}

async function fetchFrame(k) {
  const r = await fetch(`/api/frame/${k}?color=${encodeURIComponent(scene.color)}`);
  if (!r.ok) throw new Error(`frame ${k}: ${await r.text()}`);
  return decode(await r.arrayBuffer());
}

// Hands a decoded frame to the GPU and sets the colour range.
// The quads' vertices (the sphere and its value, four times) and the two
// triangles of each.
function expand(data) {
  const n = data.n, s = data.spheres, v = data.values;
  const out = new Float32Array(20 * n), idx = new Uint32Array(6 * n);
  for (let i = 0; i < n; i++) {
    for (let c = 0; c < 4; c++) {
      const o = 20 * i + 5 * c;
      out[o] = s[4 * i]; out[o + 1] = s[4 * i + 1]; out[o + 2] = s[4 * i + 2]; out[o + 3] = s[4 * i + 3];
      out[o + 4] = v[i];
    }
    idx.set([4 * i, 4 * i + 1, 4 * i + 2, 4 * i + 2, 4 * i + 1, 4 * i + 3], 6 * i);
  }
  gl.bindVertexArray(quadVao);
  gl.bindBuffer(gl.ARRAY_BUFFER, quadBuf);
  gl.bufferData(gl.ARRAY_BUFFER, out, gl.DYNAMIC_DRAW);
  gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, indexBuf);
  gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, idx, gl.DYNAMIC_DRAW);
  gl.bindVertexArray(null);
}

function upload(data) {
  if (!camera.home) frameCamera(data);
  gl.bindBuffer(gl.ARRAY_BUFFER, sphereBuf);
  gl.bufferData(gl.ARRAY_BUFFER, data.spheres, gl.DYNAMIC_DRAW);
  gl.bindBuffer(gl.ARRAY_BUFFER, valueBuf);
  gl.bufferData(gl.ARRAY_BUFFER, data.values, gl.DYNAMIC_DRAW);
  expand(data);
  let lo = Infinity, hi = -Infinity;
  for (const v of data.values) { if (v < lo) lo = v; if (v > hi) hi = v; }
  scene.range = lo <= hi ? [lo, hi > lo ? hi : lo + 1] : [0, 1];
  scene.n = data.n;
  current = data;
}

let pending = false;
let current = null;

// The inspector: the sphere under a pixel, by casting the camera's ray
// through it (exact ray–sphere tests on the CPU), and its columns.
function pickAt(px, py) {
  if (!current) return null;
  const e = eye(), t = camera.target;
  const norm = (a) => { const l = Math.hypot(...a) || 1; return a.map((x) => x / l); };
  const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
  const f = norm([t[0] - e[0], t[1] - e[1], t[2] - e[2]]);
  const r = norm(cross(f, [0, 0, 1])), u = cross(r, f);
  const w = canvas.clientWidth, h = canvas.clientHeight, tan = Math.tan(0.35);
  const x = (2 * px / w - 1) * tan * (w / h), y = (1 - 2 * py / h) * tan;
  const d = norm([0, 1, 2].map((a) => f[a] + x * r[a] + y * u[a]));
  let best = Infinity, hit = null;
  const s = current.spheres;
  for (let i = 0; i < current.n; i++) {
    const oc = [e[0] - s[4 * i], e[1] - s[4 * i + 1], e[2] - s[4 * i + 2]];
    const b = oc[0] * d[0] + oc[1] * d[1] + oc[2] * d[2];
    const c = oc[0] * oc[0] + oc[1] * oc[1] + oc[2] * oc[2] - s[4 * i + 3] * s[4 * i + 3];
    const disc = b * b - c;
    if (disc >= 0) {
      const tt = -b - Math.sqrt(disc);
      if (tt > 0 && tt < best) { best = tt; hit = i; }
    }
  }
  return hit;
}

// Shows one particle's columns in the inspector.
function showParticle(p) {
  const panel = $("inspector");
  scene.inspected = p;
  panel.textContent = Object.entries(p)
    .map(([k, v]) => `${k}: ${Array.isArray(v) ? v.map((x) => Number(x).toPrecision(6)).join(", ") : v}`)
    .join("\n");
  panel.style.display = "block";
}

async function inspect(i) {
  const changed = i !== scene.picked;
  scene.picked = i;
  if (i === null) {
    $("inspector").style.display = "none";
    $("pickplot").style.display = "none";
    if (live) live.send(JSON.stringify({ do: "pick", index: null }));
    publish();
    return;
  }
  if (live) {
    // The particle comes with every frame from now on; its history starts here.
    if (changed) { track = { time: [], speed: [], x: [], y: [], z: [] }; live.send(JSON.stringify({ do: "pick", index: i })); }
    $("pickname").textContent = `#${i}`;
    $("pickplot").style.display = "block";
    publish();
    return;
  }
  const r = await fetch(`/api/particle/${scene.frame}/${i}`);
  if (!r.ok) { fail(await r.text()); return; }
  showParticle(await r.json());
  if (changed) {
    const t = await fetch(`/api/track/${i}`);
    if (t.ok) { track = await t.json(); scene.tracked = track.time.length; }
  }
  $("pickname").textContent = `#${i}`;
  $("pickplot").style.display = "block";
  plots();
  publish();
}

// Line plots on a 2-D canvas: y against x, axes with their ranges, and
// dashed marks at `marks` (the times of the run's events).
function linePlot(canvas, x, y, marks) {
  const g = canvas.getContext("2d"), w = canvas.width, h = canvas.height;
  const left = 52, bottom = 18, top = 6, right = 6;
  g.clearRect(0, 0, w, h);
  g.font = "10px system-ui, sans-serif";
  g.fillStyle = "#222";
  const finite = (v) => Number.isFinite(v);
  let x0 = Infinity, x1 = -Infinity, y0 = Infinity, y1 = -Infinity;
  for (let i = 0; i < x.length; i++) {
    if (!finite(x[i]) || !finite(y[i])) continue;
    x0 = Math.min(x0, x[i]); x1 = Math.max(x1, x[i]);
    y0 = Math.min(y0, y[i]); y1 = Math.max(y1, y[i]);
  }
  if (!(x0 <= x1)) { g.fillText("no data yet", left, h / 2); return; }
  if (x1 === x0) x1 = x0 + 1;
  if (y1 === y0) { const pad = Math.abs(y0) * 0.01 || 1; y0 -= pad; y1 += pad; }
  const px = (v) => left + (w - left - right) * (v - x0) / (x1 - x0);
  const py = (v) => h - bottom - (h - bottom - top) * (v - y0) / (y1 - y0);
  g.strokeStyle = "#999";
  g.strokeRect(left, top, w - left - right, h - top - bottom);
  g.fillText(y1.toPrecision(4), 2, top + 8);
  g.fillText(y0.toPrecision(4), 2, h - bottom);
  g.fillText(x0.toPrecision(4), left, h - 4);
  const xe = x1.toPrecision(4);
  g.fillText(xe, w - right - g.measureText(xe).width, h - 4);
  g.strokeStyle = "#c60";
  g.setLineDash([3, 3]);
  for (const m of marks || []) {
    if (m >= x0 && m <= x1) { g.beginPath(); g.moveTo(px(m), top); g.lineTo(px(m), h - bottom); g.stroke(); }
  }
  g.setLineDash([]);
  g.strokeStyle = "#1f77b4";
  g.lineWidth = 1.5;
  g.beginPath();
  let pen = false;
  for (let i = 0; i < x.length; i++) {
    if (!finite(x[i]) || !finite(y[i])) { pen = false; continue; }
    if (pen) g.lineTo(px(x[i]), py(y[i])); else g.moveTo(px(x[i]), py(y[i]));
    pen = true;
  }
  g.stroke();
}

// The observables table (time first) and the picked particle's history.
let table = { columns: [], rows: [], events: [] };
let track = { time: [], speed: [], x: [], y: [], z: [] };
function addTable(part) {
  if (part.columns && part.columns.length) {
    table.columns = part.columns;
    const select = $("obscol");
    select.innerHTML = "";
    part.columns.slice(1).forEach((c) => {
      const o = document.createElement("option");
      o.textContent = c;
      o.selected = c === "total_energy";
      select.appendChild(o);
    });
    $("obsplot").style.display = "block";
  }
  // The run's own first plot where it names one (a Brownian run:
  // potential_energy), else the total energy a Newtonian run conserves.
  if (part.plot && table.columns.includes(part.plot)) $("obscol").value = part.plot;
  table.rows.push(...part.rows);
  table.events.push(...part.events);
  scene.rows = table.rows.length;
  scene.plotted = $("obscol").value;
  scene.events = table.events;
}
function plots() {
  if (table.columns.length) {
    const k = table.columns.indexOf($("obscol").value);
    const marks = table.events.map((e) => Number((/t = ([^:]+):/.exec(e) || [])[1]));
    if (k > 0) linePlot($("obscanvas"), table.rows.map((r) => r[0]), table.rows.map((r) => r[k]), marks);
  }
  if (scene.picked !== null && scene.picked !== undefined && track.time.length) {
    linePlot($("pickcanvas"), track.time, track[$("pickcol").value] || []);
  }
}
function trackLive(p) {
  const v = p.velocity || [NaN, NaN, NaN];
  track.time.push(p.time);
  track.speed.push(Math.hypot(...v));
  (track.force = track.force || []).push(p.force ? Math.hypot(...p.force) : NaN);
  track.x.push(p.position[0]);
  track.y.push(p.position[1]);
  track.z.push(p.position[2]);
  scene.tracked = track.time.length;
}

// A live run: frames, status and the table come over the socket.
let live = null;
function note(line) {
  scene.log.push(line);
  const log = $("log");
  log.textContent = scene.log.slice(-50).join("\n");
  log.scrollTop = log.scrollHeight;
}
function liveStatus() {
  const state = scene.ended ? "ended" : scene.paused ? "paused" : "running";
  $("status").textContent = `${state}   step ${scene.step}   t = ${Number(scene.time).toPrecision(6)}   N = ${scene.n}`;
}
function connectLive() {
  return new Promise((resolve) => {
    // The run's token came in the URL mote view printed; without it the
    // server refuses the socket.
    const token = params.get("token") || "";
    if (!token) note("this live run needs its token: open the URL mote view printed (…/?token=…)");
    const ws = new WebSocket(`ws://${location.host}/api/live?token=${encodeURIComponent(token)}`);
    ws.binaryType = "arraybuffer";
    live = ws;
    let head = null;
    ws.onopen = () => ws.send(JSON.stringify({ do: "color", quantity: scene.color }));
    ws.onclose = () => { if (!scene.ended) note("the connection to the run closed"); };
    ws.onmessage = (e) => {
      if (typeof e.data === "string") {
        const m = JSON.parse(e.data);
        if (m.type === "status") {
          scene.step = m.step;
          scene.time = m.time;
          scene.paused = m.paused;
          setPlaying(!m.paused && !m.ended);
          m.log.forEach(note);
          if (m.ended && !scene.ended) {
            scene.ended = m.ended;
            if (m.failed) fail(m.ended); else note(`run ended: ${m.ended}`);
          }
          liveStatus();
          publish();
        } else if (m.type === "frame") {
          head = m;
        } else if (m.type === "observables") {
          addTable(m.table);
          plots();
          publish();
        } else if (m.type === "error") {
          note(`refused: ${m.message}`);
          publish();
        }
        return;
      }
      const data = decode(e.data);
      if (!boxCount) setBox(head.cell, head.origin);
      // The walls, where they are now (moving and turning ones move).
      gl.bindBuffer(gl.ARRAY_BUFFER, wallBuf);
      gl.bufferData(gl.ARRAY_BUFFER, new Float32Array(head.walls.flat()), gl.DYNAMIC_DRAW);
      wallCount = 2 * head.walls.length;
      scene.walls = head.walls.length;
      if (head.quantities.join() !== scene.meta.quantities.slice(1).join()) {
        scene.meta.quantities = ["species", ...head.quantities];
        colorOptions();
      }
      scene.meta.species = head.species;
      upload(data);
      scene.time = head.time;
      scene.step = head.step;
      scene.loaded += 1;
      if (head.particle) { showParticle(head.particle); trackLive(head.particle); plots(); }
      legend();
      draw();
      liveStatus();
      publish();
      resolve();
      requestAnimationFrame(() => { if (ws.readyState === 1) ws.send(JSON.stringify({ do: "ready" })); });
    };
  });
}
function steer(what) {
  const number = (id) => Number($(id).value);
  const message = what === "field"
    ? { do: "set", what, kind: $("fieldkind").value, vector: [number("fx"), number("fy"), number("fz")] }
    : { do: "set", what, value: number(what) };
  live.send(JSON.stringify(message));
}
async function show(k) {
  if (pending) return;
  pending = true;
  try {
    const data = await fetchFrame(k);
    upload(data);
    scene.frame = k;
    if (scene.picked !== null && scene.picked !== undefined) inspect(scene.picked);
    scene.time = scene.meta.time[k];
    scene.loaded += 1;
    $("scrub").value = k;
    $("status").textContent = `frame ${k + 1}/${scene.meta.frames}   t = ${scene.time.toPrecision(6)}   N = ${data.n}`;
    legend();
    draw();
    publish();
  } catch (e) {
    fail(String(e.message || e));
  } finally {
    pending = false;
  }
}

function setPlaying(on) {
  scene.playing = on;
  $("play").textContent = on ? "❚❚" : "▶︎";
}

let last = 0;
function tick(now) {
  const interval = 100 / scene.speed;
  if (!live && scene.playing && !pending && now - last >= interval) {
    last = now;
    if (scene.frame + 1 < scene.meta.frames) show(scene.frame + 1);
    else setPlaying(false);
  }
  requestAnimationFrame(tick);
}

function controls() {
  // In a live run, play and pause hold and release the simulation itself.
  const toggle = () => {
    if (live) live.send(JSON.stringify({ do: scene.paused ? "resume" : "pause" }));
    else setPlaying(!scene.playing);
  };
  $("play").onclick = toggle;
  document.querySelectorAll("[data-set]").forEach((b) => { b.onclick = () => steer(b.dataset.set); });
  $("obscol").onchange = plots;
  $("pickcol").onchange = plots;
  $("step").onclick = () => { setPlaying(false); show(Math.min(scene.frame + 1, scene.meta.frames - 1)); };
  $("back").onclick = () => { setPlaying(false); show(Math.max(scene.frame - 1, 0)); };
  $("scrub").oninput = (e) => show(Number(e.target.value));
  $("speed").onchange = (e) => { scene.speed = Number(e.target.value); };
  $("color").onchange = (e) => {
    scene.color = e.target.value;
    if (live) live.send(JSON.stringify({ do: "color", quantity: scene.color }));
    else show(scene.frame);
  };
  $("reset").onclick = resetCamera;
  let drag = null;
  canvas.addEventListener("pointerdown", (e) => {
    drag = { x: e.clientX, y: e.clientY, x0: e.clientX, y0: e.clientY, pan: e.shiftKey || e.button === 2 };
  });
  window.addEventListener("pointerup", (e) => {
    if (drag && !drag.pan && Math.hypot(e.clientX - drag.x0, e.clientY - drag.y0) < 4) {
      const box = canvas.getBoundingClientRect();
      inspect(pickAt(e.clientX - box.left, e.clientY - box.top));
    }
    drag = null;
  });
  window.addEventListener("pointermove", (e) => {
    if (!drag) return;
    const dx = e.clientX - drag.x, dy = e.clientY - drag.y;
    drag.x = e.clientX;
    drag.y = e.clientY;
    if (drag.pan) {
      const s = camera.distance / canvas.clientHeight, t = camera.theta;
      camera.target[0] += s * (dx * Math.sin(t));
      camera.target[1] -= s * (dx * Math.cos(t));
      camera.target[2] += s * dy;
    } else {
      camera.theta -= dx * 0.01;
      camera.phi = Math.min(Math.max(camera.phi - dy * 0.01, 0.01), Math.PI - 0.01);
    }
    draw(true);
  });
  canvas.addEventListener("contextmenu", (e) => e.preventDefault());
  canvas.addEventListener("wheel", (e) => {
    e.preventDefault();
    camera.distance *= Math.exp(e.deltaY * 0.001);
    draw(true);
  }, { passive: false });
  window.addEventListener("keydown", (e) => {
    if (e.target.tagName === "INPUT") return;
    if (e.key === " ") { toggle(); e.preventDefault(); }
    else if (e.key === "ArrowRight") $("step").onclick();
    else if (e.key === "ArrowLeft") $("back").onclick();
    else if (e.key === "r") resetCamera();
  });
  window.addEventListener("resize", draw);
}

// ?bench=K: K redraws of the first frame with the camera turning, each
// waited for (a pixel read back): frames per second at full resolution in
// moteScene.fps, and while moving (level of detail) in moteScene.movingFps.
function bench(count) {
  let t0 = performance.now();
  for (let i = 0; i < count; i++) {
    camera.theta += 0.02;
    draw(false);
    sync();
  }
  scene.fps = count / ((performance.now() - t0) / 1000);
  t0 = performance.now();
  for (let i = 0; i < count; i++) {
    camera.theta += 0.02;
    draw(true);
    sync();
  }
  scene.movingFps = count / ((performance.now() - t0) / 1000);
  publish();
}

// The colour menu: species and the quantities the frames carry.
function colorOptions() {
  const select = $("color");
  select.innerHTML = "";
  for (const q of scene.meta.quantities) {
    const o = document.createElement("option");
    o.textContent = q;
    o.selected = q === scene.color;
    select.appendChild(o);
  }
}

// ?set=WHAT:VALUE (dt, damping, temperature) or ?set=field:KIND:X,Y,Z
// steers a live run once its first frame is shown (for tests and links).
function steerFromUrl() {
  const spec = params.get("set");
  if (!spec) return;
  const [what, a, b] = spec.split(":");
  if (what === "field") {
    $("fieldkind").value = a;
    b.split(",").forEach((v, k) => { $(["fx", "fy", "fz"][k]).value = v; });
  } else {
    $(what).value = a;
  }
  steer(what);
}

async function main() {
  try {
    const r = await fetch("/api/meta");
    if (!r.ok) throw new Error(await r.text());
    scene.meta = await r.json();
    $("label").textContent = scene.meta.label;
    document.title = `mote view: ${scene.meta.label}`;
    colorOptions();
    if (scene.meta.error) {
      // The input could not be read: say why, here as in the terminal.
      fail(scene.meta.error);
      return;
    }
    setup();
    controls();
    if (scene.meta.live) {
      scene.live = true;
      for (const id of ["back", "step", "scrub", "speedbox"]) $(id).style.display = "none";
      $("steer").style.display = "block";
      await connectLive();
      scene.loadMs = performance.now();
      publish();
      if (params.get("pause") === "1") live.send(JSON.stringify({ do: "pause" }));
      steerFromUrl();
      if (params.get("run") === "1") live.send(JSON.stringify({ do: "resume" }));
    } else {
      $("scrub").max = Math.max(scene.meta.frames - 1, 0);
      setBox(scene.meta.cell, scene.meta.origin);
      await show(0);
      scene.loadMs = performance.now();
      if (scene.meta.observables) {
        const t = await fetch("/api/observables");
        if (t.ok) { addTable(await t.json()); plots(); }
      }
      publish();
      if (params.get("play") === "1") setPlaying(true);
      if (params.get("bench")) bench(Number(params.get("bench")));
    }
    if (params.get("pick")) {
      const [fx, fy] = params.get("pick").split(",").map(Number);
      await inspect(pickAt(fx * canvas.clientWidth, fy * canvas.clientHeight));
    }
    requestAnimationFrame(tick);
  } catch (e) {
    fail(String(e.message || e));
  }
}

main();
