// The page: the library compiled to WebAssembly (web/src/exports.rs, plain C ABI exports),
// seven mechanisms each in a scene with one fixed-timestep clock, drawn at the display's
// rate from states interpolated between the last two steps. No dependency, no network.
'use strict';

const METHODS = ['RK4', 'Stormer-Verlet', 'semi-implicit Euler'];
// The world box of each panel: centre x, centre y, half width (m); `follow`: the view
// follows the first point (the cart, the torso).
const VIEWS = [
  { cx: 0, cy: -0.5, hw: 1.6 },
  { cx: 0, cy: 0, hw: 2.9 },
  { cx: 0, cy: -1.3, hw: 3.3 },
  { cx: 0.5, cy: -0.15, hw: 1.4 },
  { cx: 0, cy: 0.3, hw: 2.6, floor: -0.13, follow: true },
  { cx: 0, cy: -0.6, hw: 2.9, floor: -0.8 },
  { cx: 0.8, cy: 1.3, hw: 3.3, floor: 0, follow: true },
];
const PLOT_SECONDS = 6;
const DRAG_GAIN = 12; // 1/s: a dragged point moves towards the pointer at this rate
const PUSH = 15; // N: the cart's force under an arrow key

// The module: built with WebAssembly SIMD (`simd128`: the scenes' banks in lanes step their
// instances side by side on 128-bit vectors) where the browser validates a SIMD instruction,
// else the scalar build (the same bits, one by one). `?scalar` in the address forces the
// latter. The probe: (module (func (result v128) i32.const 0 i8x16.splat i8x16.popcnt)).
const SIMD_PROBE = new Uint8Array([0, 97, 115, 109, 1, 0, 0, 0, 1, 5, 1, 96, 0, 1, 123, 3,
  2, 1, 0, 10, 10, 1, 8, 0, 65, 0, 253, 15, 253, 98, 11]);
const SIMD = !new URLSearchParams(location.search).has('scalar') &&
  WebAssembly.validate(SIMD_PROBE);
const MODULE = SIMD ? 'lagrange_web_simd128.wasm' : 'lagrange_web.wasm';

const state = {
  wasm: null,
  build: SIMD ? 'simd128' : 'scalar',
  panels: [],
  frames: 0,
  paused: false,
  last: null,
  drag: null,
  keys: { left: false, right: false },
  scenario: {},
  // The sandbox: its drag, its slowest step (ms), and the scripted run's outcome.
  sandbox: { drag: null, slowest: 0, stepMs: 0, script: null },
  shownErrors: [],
  nonFinite: 0,
};
window.lagrange = state;

function ex() { return state.wasm.exports; }

// Until main() has instantiated the module and built the panels, nothing may read it: every
// entry point (the test's probes, keys, pointers) answers NOT_READY or does nothing.
function ready() { return state.ready === true; }
const NOT_READY = JSON.stringify({ ready: false });

function text(len = ex().lg_text_len()) {
  const bytes = new Uint8Array(ex().memory.buffer, ex().lg_text(), len);
  return new TextDecoder().decode(bytes);
}

// The panel's points: { main, twin, exact } arrays of [x, y].
function points(p) {
  const n = ex().lg_points(p);
  const v = new Float64Array(ex().memory.buffer, ex().lg_numbers(), n);
  const counts = [v[0], v[1], v[2]];
  const groups = [];
  let at = 3;
  for (const c of counts) {
    const g = [];
    for (let k = 0; k < c; k++, at += 2) {
      if (!Number.isFinite(v[at]) || !Number.isFinite(v[at + 1])) { state.nonFinite++; continue; }
      g.push([v[at], v[at + 1]]);
    }
    groups.push(g);
  }
  return { main: groups[0], twin: groups[1], exact: groups[2] };
}

function showError(panel, message) {
  const ui = state.panels[panel];
  const line = `${new Date().toLocaleTimeString()} ${message} (instance reset)`;
  ui.error.textContent = line;
  ui.errorUntil = performance.now() + 6000;
  state.shownErrors.push({ panel, message });
}

// Takes the panel's kept error, if any, onto the page.
function checkError(p) {
  const len = ex().lg_take_error(p);
  if (len > 0) { showError(p, text(len)); return true; }
  return false;
}

function refreshDt(p) {
  const ui = state.panels[p];
  const dt = ex().lg_dt(p);
  ui.dtText.value = dt.toPrecision(4);
  ui.dtRange.value = Math.log10(dt);
  ui.samples.length = 0;
}

function setDt(p, dt) {
  if (ex().lg_set_dt(p, dt) !== 0) { checkError(p); refreshDt(p); return false; }
  refreshDt(p);
  return true;
}

function el(tag, attrs = {}, parent = null) {
  const e = document.createElement(tag);
  Object.assign(e, attrs);
  if (parent) parent.appendChild(e);
  return e;
}

function buildPanels(names) {
  const root = document.getElementById('panels');
  names.forEach((name, p) => {
    const box = el('div', { className: 'panel' }, root);
    el('h3', { textContent: name }, box);
    const canvas = el('canvas', { className: 'scene' }, box);
    const row1 = el('div', { className: 'row' }, box);
    el('span', { textContent: 'integrator' }, row1);
    const method = el('select', {}, row1);
    METHODS.forEach((m, k) => el('option', { value: k, textContent: m }, method));
    const reset = el('button', { textContent: 'reset' }, row1);
    const row2 = el('div', { className: 'row' }, box);
    el('span', { textContent: 'dt' }, row2);
    const dtRange = el('input', { type: 'range', min: -3.5, max: -1.2, step: 0.01 }, row2);
    const dtText = el('input', { className: 'dt', type: 'text' }, row2);
    el('span', { textContent: 's' }, row2);
    const plot = el('canvas', { className: 'energy' }, box);
    const info = el('div', { className: 'info' }, box);
    const error = el('div', { className: 'error' }, box);
    const ui = { canvas, plot, method, dtRange, dtText, info, error, errorUntil: 0,
      samples: [], view: { ...VIEWS[p] }, status: 0,
      cost: { ms: 0, steps: 0, since: 0, shown: '' }, slowest: 0 };
    state.panels.push(ui);
    method.addEventListener('change', () => {
      if (ex().lg_set_method(p, Number(method.value)) !== 0) showError(p, text());
      refreshDt(p);
    });
    reset.addEventListener('click', () => { ex().lg_reset(p); refreshDt(p); });
    dtRange.addEventListener('input', () => setDt(p, 10 ** Number(dtRange.value)));
    // Whatever is typed goes to the library: "0", "NaN", "abc" (NaN) are its to refuse.
    dtText.addEventListener('change', () => setDt(p, Number(dtText.value)));
    canvas.addEventListener('pointerdown', (e) => startDrag(p, e));
  });
}

// World (m) to canvas pixels for panel `p`.
function transform(p) {
  const ui = state.panels[p];
  const c = ui.canvas;
  const scale = c.width / (2 * ui.view.hw);
  return {
    scale,
    x: (wx) => c.width / 2 + (wx - ui.view.cx) * scale,
    y: (wy) => c.height / 2 - (wy - ui.view.cy) * scale,
    wx: (px) => ui.view.cx + (px - c.width / 2) / scale,
    wy: (py) => ui.view.cy - (py - c.height / 2) / scale,
  };
}

function pointer(p, e) {
  const c = state.panels[p].canvas;
  const r = c.getBoundingClientRect();
  const px = (e.clientX - r.left) * c.width / r.width;
  const py = (e.clientY - r.top) * c.height / r.height;
  const t = transform(p);
  return [t.wx(px), t.wy(py), px, py];
}

function startDrag(p, e) {
  const [wx, wy, px, py] = pointer(p, e);
  const t = transform(p);
  const main = points(p).main;
  let best = -1;
  let bestDist = 30 * (window.devicePixelRatio || 1);
  main.forEach(([x, y], k) => {
    const d = Math.hypot(t.x(x) - px, t.y(y) - py);
    if (d < bestDist) { best = k; bestDist = d; }
  });
  if (best < 0) return;
  state.panels[p].canvas.setPointerCapture(e.pointerId);
  state.drag = { p, point: best, target: [wx, wy], trail: [[performance.now(), wx, wy]] };
  e.preventDefault();
}

window.addEventListener('pointermove', (e) => {
  const d = state.drag;
  if (!d) return;
  const [wx, wy] = pointer(d.p, e);
  d.target = [wx, wy];
  d.trail.push([performance.now(), wx, wy]);
  while (d.trail.length > 2 && performance.now() - d.trail[0][0] > 100) d.trail.shift();
});

window.addEventListener('pointerup', () => {
  const d = state.drag;
  if (!d) return;
  state.drag = null;
  // The throw: the pointer's velocity over its last 100 ms, as it is (however absurd).
  const [t0, x0, y0] = d.trail[0];
  const [t1, x1, y1] = d.trail[d.trail.length - 1];
  const dt = (t1 - t0) / 1000;
  if (dt > 0) drag(d.p, d.point, (x1 - x0) / dt, (y1 - y0) / dt);
});

function drag(p, point, vx, vy) {
  if (ex().lg_drag(p, point, vx, vy) !== 0) { checkError(p); return false; }
  return true;
}

// While a body is held, its point is given the velocity that takes it to the pointer.
function holdDrag() {
  const d = state.drag;
  if (!d) return;
  const at = points(d.p).main[d.point];
  if (!at) return;
  drag(d.p, d.point, DRAG_GAIN * (d.target[0] - at[0]), DRAG_GAIN * (d.target[1] - at[1]));
}

function setCartInput() {
  const force = (state.keys.right ? PUSH : 0) - (state.keys.left ? PUSH : 0);
  if (ex().lg_input(4, force) !== 0) checkError(4);
}

window.addEventListener('keydown', (e) => {
  if (!ready() || (e.key !== 'ArrowLeft' && e.key !== 'ArrowRight')) return;
  e.preventDefault();
  const key = e.key === 'ArrowLeft' ? 'left' : 'right';
  if (state.keys[key]) return;
  state.keys[key] = true;
  setCartInput();
});
window.addEventListener('keyup', (e) => {
  if (!ready() || (e.key !== 'ArrowLeft' && e.key !== 'ArrowRight')) return;
  state.keys[e.key === 'ArrowLeft' ? 'left' : 'right'] = false;
  setCartInput();
});

function resize(canvas) {
  const dpr = window.devicePixelRatio || 1;
  const w = Math.max(1, Math.round(canvas.clientWidth * dpr));
  const h = Math.max(1, Math.round(canvas.clientHeight * dpr));
  if (canvas.width !== w || canvas.height !== h) { canvas.width = w; canvas.height = h; }
}

function line(g, t, pts, from = 0, to = pts.length) {
  g.beginPath();
  for (let k = from; k < to; k++) {
    const [x, y] = pts[k];
    if (k === from) g.moveTo(t.x(x), t.y(y)); else g.lineTo(t.x(x), t.y(y));
  }
  g.stroke();
}

function dots(g, t, pts, r, from = 1) {
  for (let k = from; k < pts.length; k++) {
    g.beginPath();
    g.arc(t.x(pts[k][0]), t.y(pts[k][1]), r, 0, 2 * Math.PI);
    g.fill();
  }
}

function drawPanel(p) {
  const ui = state.panels[p];
  resize(ui.canvas);
  const g = ui.canvas.getContext('2d');
  const pts = points(p);
  if (ui.view.follow && pts.main.length > 0) {
    const x = pts.main[0][0];
    const edge = ui.view.hw * 0.55;
    if (x > ui.view.cx + edge) ui.view.cx = x - edge;
    if (x < ui.view.cx - edge) ui.view.cx = x + edge;
  }
  const t = transform(p);
  const px = window.devicePixelRatio || 1;
  g.clearRect(0, 0, ui.canvas.width, ui.canvas.height);
  g.lineCap = 'round';
  g.lineJoin = 'round';
  const asleep = ui.status === 1;
  const colour = asleep ? '#9aa3ad' : '#c4461a';
  const ink = asleep ? '#9aa3ad' : '#26303a';
  if (ui.view.floor !== undefined) {
    const y = t.y(ui.view.floor ?? 0);
    g.fillStyle = '#e7e2d8';
    g.fillRect(0, y, ui.canvas.width, ui.canvas.height - y);
    g.strokeStyle = '#b9b2a4';
    g.lineWidth = 1 * px;
    for (let m = Math.floor(t.wx(0)); m <= t.wx(ui.canvas.width); m++) {
      g.beginPath(); g.moveTo(t.x(m), y); g.lineTo(t.x(m) - 6 * px, y + 8 * px); g.stroke();
    }
  }
  if (pts.twin.length > 1) {
    g.globalAlpha = 0.3;
    g.strokeStyle = '#2a7ab0';
    g.fillStyle = '#2a7ab0';
    g.lineWidth = 3 * px;
    line(g, t, pts.twin);
    dots(g, t, pts.twin, 7 * px);
    g.globalAlpha = 1;
  }
  const main = pts.main;
  g.strokeStyle = ink;
  g.fillStyle = colour;
  if (asleep) g.setLineDash([6 * px, 4 * px]);
  if (p === 6) {
    // The ragdoll: ten links as (start, end) pairs; the head a disc at its top.
    g.lineWidth = 7 * px;
    g.strokeStyle = colour;
    for (let k = 0; k + 1 < main.length; k += 2) line(g, t, main, k, k + 2);
    if (main.length > 3) {
      g.beginPath();
      g.arc(t.x(main[3][0]), t.y(main[3][1]), 0.11 * t.scale, 0, 2 * Math.PI);
      g.fill();
    }
  } else if (p === 4 && main.length === 2) {
    const [cx, cy] = main[0];
    g.lineWidth = 2 * px;
    g.fillStyle = ink;
    g.fillRect(t.x(cx) - 0.25 * t.scale, t.y(cy) - 0.12 * t.scale, 0.5 * t.scale, 0.24 * t.scale);
    g.strokeStyle = colour;
    g.lineWidth = 4 * px;
    line(g, t, main);
    g.fillStyle = colour;
    dots(g, t, main, 7 * px);
  } else {
    g.lineWidth = 3 * px;
    line(g, t, main);
    if (p === 3 && main.length === 4) {
      g.fillStyle = ink;
      dots(g, t, [main[0], main[3]], 5 * px, 0);
      g.fillStyle = colour;
      dots(g, t, main.slice(1, 3), 6 * px, 0);
    } else {
      dots(g, t, main, (p === 2 ? 5 : 9) * px);
    }
  }
  g.setLineDash([]);
  if (pts.exact.length > 1) {
    // The exact solution over the integrated one: a dashed rod and a ring.
    g.strokeStyle = '#2a7ab0';
    g.lineWidth = 2 * px;
    g.setLineDash([5 * px, 4 * px]);
    line(g, t, pts.exact);
    g.setLineDash([]);
    const [x, y] = pts.exact[pts.exact.length - 1];
    g.beginPath();
    g.arc(t.x(x), t.y(y), 12 * px, 0, 2 * Math.PI);
    g.stroke();
  }
  if (state.drag && state.drag.p === p && main[state.drag.point]) {
    const [x, y] = main[state.drag.point];
    g.strokeStyle = '#2a7ab0';
    g.lineWidth = 1.5 * px;
    g.beginPath();
    g.moveTo(t.x(x), t.y(y));
    g.lineTo(t.x(state.drag.target[0]), t.y(state.drag.target[1]));
    g.stroke();
  }
  g.fillStyle = asleep ? '#6b7580' : '#26303a';
  g.font = `${11 * px}px ui-monospace, monospace`;
  const label = ['awake', 'asleep', 'set aside'][ui.status] ?? '?';
  g.fillText(`t = ${ex().lg_time(p).toFixed(2)} s  ${label}`, 6 * px, 14 * px);
}

function drawPlot(p) {
  const ui = state.panels[p];
  resize(ui.plot);
  const g = ui.plot.getContext('2d');
  const { width: w, height: h } = ui.plot;
  const px = window.devicePixelRatio || 1;
  g.clearRect(0, 0, w, h);
  const s = ui.samples;
  if (s.length < 2) return;
  let span = 1e-12;
  for (const [, e] of s) span = Math.max(span, Math.abs(e));
  const tEnd = s[s.length - 1][0];
  const x = (tt) => w - (tEnd - tt) / PLOT_SECONDS * w;
  const y = (e) => h / 2 - e / span * (h / 2 - 4 * px);
  g.strokeStyle = '#d8d2c6';
  g.lineWidth = 1;
  g.beginPath(); g.moveTo(0, h / 2); g.lineTo(w, h / 2); g.stroke();
  g.strokeStyle = '#2a7ab0';
  g.lineWidth = 1.5 * px;
  g.beginPath();
  s.forEach(([tt, e], k) => (k ? g.lineTo(x(tt), y(e)) : g.moveTo(x(tt), y(e))));
  g.stroke();
  g.fillStyle = '#555';
  g.font = `${10 * px}px ui-monospace, monospace`;
  g.fillText(`(E - E0)/E0, last ${PLOT_SECONDS} s: ${s[s.length - 1][1].toExponential(2)}`, 4 * px, 11 * px);
  g.fillText(`±${span.toExponential(1)}`, 4 * px, h - 4 * px);
}

function frame(now) {
  const elapsed = state.last === null ? 0 : (now - state.last) / 1000;
  state.last = now;
  if (!state.paused) {
    holdDrag();
    state.panels.forEach((ui, p) => {
      const before = ex().lg_time(p);
      const start = performance.now();
      ui.status = ex().lg_advance(p, elapsed);
      ui.cost.ms += performance.now() - start;
      const steps = Math.round((ex().lg_time(p) - before) / ex().lg_dt(p));
      if (steps > 0) {
        ui.cost.steps += steps;
        // The frame's time per step: the slowest step's, where a frame takes one.
        ui.slowest = Math.max(ui.slowest, (performance.now() - start) / steps);
      }
      if (now - ui.cost.since > 5000) {
        ui.cost.shown = ui.cost.steps > 0 ? `, ${(1000 * ui.cost.ms / ui.cost.steps).toFixed(1)} µs/step` : '';
        Object.assign(ui.cost, { ms: 0, steps: 0, since: now });
      }
      checkError(p);
      const e = ex().lg_energy_error(p);
      const tt = ex().lg_time(p);
      if (ui.samples.length && tt < ui.samples[ui.samples.length - 1][0]) ui.samples.length = 0;
      if (Number.isFinite(e)) ui.samples.push([tt, e]);
      while (ui.samples.length > 2 && tt - ui.samples[0][0] > PLOT_SECONDS) ui.samples.shift();
    });
  }
  if (!state.paused) stepSandbox(elapsed);
  drawSandbox();
  showSandboxInfo();
  state.panels.forEach((ui, p) => {
    drawPanel(p);
    drawPlot(p);
    ui.info.textContent = `${METHODS[Number(ui.method.value)]}, dt ${ex().lg_dt(p).toPrecision(3)} s, ` +
      `${state.double ? 'f64' : 'f32'}${ui.cost.shown}${p === 1 && !state.double ? ' (twin: the next f32, 2.4e-7 rad away)' : ''}`;
    if (ui.errorUntil && now > ui.errorUntil) { ui.error.textContent = ''; ui.errorUntil = 0; }
  });
  state.frames++;
  requestAnimationFrame(frame);
}

function init(double) {
  state.double = double;
  const n = ex().lg_init(double ? 1 : 0);
  if (n === 0) throw new Error(`the page's mechanisms did not build: ${text()}`);
  state.panels.forEach((ui, p) => { ui.view = { ...VIEWS[p] }; refreshDt(p); });
  if (ex().lg_sandbox_init(double ? 1 : 0) !== 0) throw new Error(`the sandbox did not build: ${text()}`);
  Object.assign(state.sandbox, { drag: null, slowest: 0, stepMs: 0 });
}

// --- The sandbox: one World, drawn from its shapes where they are. ---

const SANDBOX_VIEW = { left: -4.2, bottom: -0.2, width: 8.4 };
const FAILED = 4294967295; // u32::MAX: a step failed

function sandboxScale(canvas) { return canvas.width / SANDBOX_VIEW.width; }

function toScreen(canvas, x, y) {
  const k = sandboxScale(canvas);
  return [(x - SANDBOX_VIEW.left) * k, canvas.height - (y - SANDBOX_VIEW.bottom) * k];
}

function toWorld(canvas, e) {
  const r = canvas.getBoundingClientRect();
  const k = sandboxScale(canvas);
  const px = (e.clientX - r.left) * canvas.width / r.width;
  const py = (e.clientY - r.top) * canvas.height / r.height;
  return [px / k + SANDBOX_VIEW.left, (canvas.height - py) / k + SANDBOX_VIEW.bottom];
}

function drawSandbox() {
  const canvas = document.getElementById('sandbox');
  const g = canvas.getContext('2d');
  const k = sandboxScale(canvas);
  g.clearRect(0, 0, canvas.width, canvas.height);
  g.strokeStyle = '#555';
  g.lineWidth = 2;
  g.beginPath();
  const corners = [[-4, 5], [-4, 0], [4, 0], [4, 5]].map(([x, y]) => toScreen(canvas, x, y));
  corners.forEach(([x, y], i) => (i ? g.lineTo(x, y) : g.moveTo(x, y)));
  g.stroke();
  const n = ex().lg_sandbox_shapes();
  const v = new Float64Array(ex().memory.buffer, ex().lg_numbers(), n);
  g.lineCap = 'round';
  g.lineJoin = 'round';
  for (let at = 0; at < n;) {
    const [asleep, r, count] = [v[at], v[at + 1], v[at + 2]];
    const pts = [];
    for (let i = 0; i < count; i++) pts.push(toScreen(canvas, v[at + 3 + 2 * i], v[at + 4 + 2 * i]));
    at += 3 + 2 * count;
    const colour = asleep ? '#b9b9b9' : '#d9822b';
    g.fillStyle = colour;
    g.strokeStyle = colour;
    if (count === 1) {
      g.beginPath();
      g.arc(pts[0][0], pts[0][1], r * k, 0, 2 * Math.PI);
      g.fill();
    } else {
      g.beginPath();
      pts.forEach(([x, y], i) => (i ? g.lineTo(x, y) : g.moveTo(x, y)));
      if (count > 2) { g.closePath(); g.fill(); }
      if (r > 0) { g.lineWidth = 2 * r * k; g.stroke(); }
    }
  }
  const d = state.sandbox.drag;
  if (d && d.trail.length) {
    const [, x, y] = d.trail[d.trail.length - 1];
    const [sx, sy] = toScreen(canvas, d.start[0], d.start[1]);
    const [ex2, ey2] = toScreen(canvas, x, y);
    g.strokeStyle = '#26303a';
    g.lineWidth = 1.5;
    g.beginPath(); g.moveTo(sx, sy); g.lineTo(ex2, ey2); g.stroke();
  }
}

function stepSandbox(elapsed) {
  const start = performance.now();
  const steps = ex().lg_sandbox_advance(elapsed);
  const ms = performance.now() - start;
  const error = document.getElementById('sandbox-error');
  if (steps === FAILED) {
    error.textContent = `a step failed and the sandbox was rebuilt: ${text()}`;
    return;
  }
  if (steps > 0) {
    state.sandbox.stepMs = ms / steps;
    state.sandbox.slowest = Math.max(state.sandbox.slowest, ms / steps);
  }
}

function showSandboxInfo() {
  const info = (which) => ex().lg_sandbox_info(0, which);
  const s = state.sandbox;
  const script = s.script ? `; the scripted pile: digest ${s.script.digest}, slowest step ` +
    `${s.script.slowestMs.toFixed(2)} ms` : '';
  document.getElementById('sandbox-info').textContent =
    `${info(0)} bodies, ${info(1)} awake, ${info(2)} contact points (at most ${info(3)} in a ` +
    `step, cap ${info(4)}); a step ${s.stepMs.toFixed(2)} ms, the slowest ${s.slowest.toFixed(2)} ms` +
    `, ${state.double ? 'f64' : 'f32'}${script}`;
}

function startSandboxDrag(e) {
  if (!ready()) return;
  const canvas = document.getElementById('sandbox');
  const [x, y] = toWorld(canvas, e);
  const key = ex().lg_sandbox_grab(x, y);
  if (key === 0) return;
  state.sandbox.drag = { key: key - 1, start: [x, y], trail: [[performance.now(), x, y]] };
  e.preventDefault();
}

window.addEventListener('pointermove', (e) => {
  const d = state.sandbox.drag;
  if (!d) return;
  const [x, y] = toWorld(document.getElementById('sandbox'), e);
  d.trail.push([performance.now(), x, y]);
  while (d.trail.length > 2 && performance.now() - d.trail[0][0] > 100) d.trail.shift();
});

window.addEventListener('pointerup', () => {
  const d = state.sandbox.drag;
  if (!d) return;
  state.sandbox.drag = null;
  // The throw: the pointer's velocity over its last 100 ms, at most 15 m/s.
  const [t0, x0, y0] = d.trail[0];
  const [t1, x1, y1] = d.trail[d.trail.length - 1];
  const dt = Math.max((t1 - t0) / 1000, 1 / 60);
  let [vx, vy] = [(x1 - x0) / dt, (y1 - y0) / dt];
  const speed = Math.hypot(vx, vy);
  if (speed > 15) [vx, vy] = [15 * vx / speed, 15 * vy / speed];
  if (ex().lg_sandbox_throw(d.key, vx, vy) !== 0) {
    document.getElementById('sandbox-error').textContent = text();
  }
});

// The scripted pile, step by step, each step timed: its digest (the host computes the same),
// the slowest step, and the most contact points of a step against the cap.
function runSandboxScript() {
  let slowestMs = 0;
  let failed = null;
  const steps = ex().lg_script_steps();
  for (let i = 0; i < steps && failed === null; i++) {
    const start = performance.now();
    if (ex().lg_script_step(i) !== 0) failed = text();
    slowestMs = Math.max(slowestMs, performance.now() - start);
  }
  const digest = text(ex().lg_script_digest());
  state.sandbox.script = {
    precision: state.double ? 'f64' : 'f32', steps, digest, slowestMs,
    worst: ex().lg_sandbox_info(1, 3), cap: ex().lg_sandbox_info(1, 4), failed,
  };
}

function runScenario() {
  const out = [];
  for (const double of [0, 1]) {
    const len = ex().lg_scenario(double);
    const line = text(len);
    state.scenario[double ? 'f64' : 'f32'] = line;
    out.push(line);
  }
  const world = text(ex().lg_world_scenario());
  state.scenario.world = world;
  out.push(world);
  document.getElementById('scenario').textContent = out.join('\n');
}

// Bad input, as a user would give it: a dt of 0, a dt of NaN, a throw at an absurd speed.
// What the page showed for each, and whether every panel still steps and draws finite points.
window.lagrangeBadInput = function badInput() {
  if (!ready()) return NOT_READY;
  const before = state.shownErrors.length;
  const results = {
    dtZero: setDt(0, 0),
    dtNaN: setDt(1, NaN),
    absurdThrow: drag(6, 3, 1e300, -1e300),
    hugeThrow: drag(2, 8, 3e8, 0),
  };
  for (let k = 0; k < 50; k++) {
    state.panels.forEach((_, p) => { ex().lg_advance(p, 1 / 60); checkError(p); });
  }
  results.shown = state.shownErrors.slice(before).map((e) => `${e.panel}: ${e.message}`);
  results.finite = state.panels.every((_, p) => {
    const pts = points(p);
    return pts.main.length > 0 && Number.isFinite(ex().lg_energy_error(p));
  });
  results.nonFinite = state.nonFinite;
  return JSON.stringify(results);
};

// Where point `k` of panel `p`'s main instance is on the screen (CSS pixels), for the test's
// mouse.
window.lagrangeScreenPoint = function screenPoint(p, k) {
  if (!ready()) return NOT_READY;
  const ui = state.panels[p];
  const at = points(p).main[k];
  const t = transform(p);
  const r = ui.canvas.getBoundingClientRect();
  return JSON.stringify([r.left + t.x(at[0]) * r.width / ui.canvas.width,
    r.top + t.y(at[1]) * r.height / ui.canvas.height]);
};

// Back to the start (a mechanism thrown again), as the reset button does.
window.lagrangeReset = function reset(p) {
  if (!ready()) return NOT_READY;
  ex().lg_reset(p);
  refreshDt(p);
  return 'ok';
};

// Chooses as a user would: `select` (an id, or panel p's integrator picker) set to `value`.
window.lagrangeChoose = function choose(p, value) {
  if (!ready()) return NOT_READY;
  const select = p < 0 ? document.getElementById('precision') : state.panels[p].method;
  select.value = String(value);
  select.dispatchEvent(new Event('change'));
  return 'ok';
};

// The page's state for the test. Statuses are read from the library, not from the last
// frame's, so that a wake shows before the next frame is drawn.
window.lagrangeProbe = function probe() {
  if (!ready()) return NOT_READY;
  return JSON.stringify({
    ready: true,
    frames: state.frames,
    times: state.panels.map((_, p) => ex().lg_time(p)),
    statuses: state.panels.map((_, p) => ex().lg_status(p)),
    cartX: points(4).main[0]?.[0] ?? null,
    double: state.double,
    methods: state.panels.map((ui) => Number(ui.method.value)),
    slowest: state.panels.map((ui) => ui.slowest),
    work: state.panels.map((_, p) => [ex().lg_work(p, 0), ex().lg_work(p, 1)]),
    roundsCap: ex().lg_rounds_cap(),
    scenario: state.scenario,
    sandbox: state.sandbox.script,
    sandboxSlowest: state.sandbox.slowest,
    build: state.build,
    nonFinite: state.nonFinite,
  });
};

async function main() {
  const status = document.getElementById('status');
  const response = await fetch(MODULE);
  if (!response.ok) throw new Error(`${MODULE}: ${response.status} ${response.statusText}`);
  const bytes = await response.arrayBuffer();
  const { instance } = await WebAssembly.instantiate(bytes, {});
  state.wasm = instance;
  const names = ['origin\'s pendulum (orange) beside its exact solution (blue, dashed)',
    'chaotic double pendulum, a faint twin 1e-9 rad away', 'chain of 8 links', 'four-bar linkage',
    'cart-pole: balance it with ← →', 'double pendulum falling onto a floor (ImpulseStepper)',
    'ragdoll thrown onto the floor (ImpulseStepper)'];
  buildPanels(names.slice(0, ex().lg_panels()));
  const precision = document.getElementById('precision');
  precision.addEventListener('change', () => init(precision.value === '1'));
  document.getElementById('pause').addEventListener('click', (e) => {
    state.paused = !state.paused;
    e.target.textContent = state.paused ? 'resume' : 'pause';
  });
  init(true);
  runScenario();
  runSandboxScript();
  document.getElementById('sandbox').addEventListener('pointerdown', startSandboxDrag);
  status.textContent = `${(bytes.byteLength / 1024).toFixed(0)} KiB of WebAssembly ` +
    `(${SIMD ? 'with SIMD: banks in lanes' : 'scalar'}); ` +
    'each mechanism steps in a lagrange Scene with a fixed-timestep clock, drawn interpolated.';
  state.ready = true;
  requestAnimationFrame(frame);
}

main().catch((e) => {
  document.getElementById('status').textContent = `failed: ${e}`;
  throw e;
});
