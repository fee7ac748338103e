// mechlab studio: the page. Plain script, no framework, no network beyond
// the studio's own API. `window.studio` holds the state (read by the
// browser test).
"use strict";

const studio = {
  ready: false,
  models: [],
  model: null,
  params: {},
  axes: [0, 1],
  through: [],
  view: { x: [-Math.PI, Math.PI], y: [-3, 3] },
  orbits: [],
  overlay: null,
  chaos: null,
  basins: null,
  manifolds: null,
  branches: null,
  section: false,
  megno: null,
  nextId: 1,
  pointsReceived: 0,
};
window.studio = studio;

const $ = (id) => document.getElementById(id);
const canvas = $("plane");
const ctx = canvas.getContext("2d");

// ---------- talking to the server ----------

async function errorOf(response) {
  try {
    const body = await response.json();
    return body.error || response.statusText;
  } catch (_) {
    return `${response.status} ${response.statusText}`;
  }
}

async function getJson(url) {
  const response = await fetch(url);
  if (!response.ok) throw new Error(await errorOf(response));
  return response.json();
}

async function postJson(url, body, signal) {
  const response = await fetch(url, { method: "POST", body: JSON.stringify(body), signal,
    headers: { "content-type": "application/json" } });
  if (!response.ok) throw new Error(await errorOf(response));
  return response.json();
}

// Posts `body` and calls `onLine` with every NDJSON line as it arrives.
async function postStream(url, body, signal, onLine) {
  const response = await fetch(url, { method: "POST", body: JSON.stringify(body), signal,
    headers: { "content-type": "application/json" } });
  if (!response.ok) throw new Error(await errorOf(response));
  const reader = response.body.getReader();
  const decoder = new TextDecoder();
  let pending = "";
  for (;;) {
    const { value, done } = await reader.read();
    if (done) break;
    pending += decoder.decode(value, { stream: true });
    let newline;
    while ((newline = pending.indexOf("\n")) >= 0) {
      const line = pending.slice(0, newline);
      pending = pending.slice(newline + 1);
      if (line.trim()) onLine(JSON.parse(line));
    }
  }
}

function setup() {
  return {
    model: studio.model.name,
    params: { ...studio.params },
    method: $("method").value,
    tol: Number($("tol").value),
    axes: studio.axes,
    through: studio.through,
  };
}

function say(text) { $("message").textContent = text || ""; }
const aborted = (e) => e && e.name === "AbortError";

// ---------- coordinates ----------

function toWorld(px, py) {
  const { x, y } = studio.view;
  return [x[0] + (px / canvas.width) * (x[1] - x[0]), y[1] - (py / canvas.height) * (y[1] - y[0])];
}
function toPixel(wx, wy) {
  const { x, y } = studio.view;
  return [((wx - x[0]) / (x[1] - x[0])) * canvas.width, ((y[1] - wy) / (y[1] - y[0])) * canvas.height];
}
const stateName = (k) => studio.model.state[k];
// The page's axis i: on a section, the plane's chart as the server names it.
const axisName = (i) => (studio.section && studio.sectionAxes ? studio.sectionAxes[i] : stateName(studio.axes[i]));
// For the browser test: where a point is drawn, and the colour there.
studio.pixelOf = (x, y) => toPixel(x, y);
studio.colorAt = (px, py) => Array.from(ctx.getImageData(Math.round(px), Math.round(py), 1, 1).data);
studio.attractorAt = (x, y) => attractorAt(x, y);
studio.attractorColor = (label) => attractorColor(label);

// ---------- drawing ----------

let dirty = true;
function redraw() { dirty = true; }
function frame() {
  if (dirty) { dirty = false; draw(ctx, canvas.width, canvas.height); saveAddress(); }
  drawMechanism(performance.now());
  requestAnimationFrame(frame);
}

function orbitColor(id) { return `hsl(${(id * 137.508) % 360}, 75%, 42%)`; }

function draw(g, width, height) {
  g.fillStyle = "#fff";
  g.fillRect(0, 0, width, height);
  if (!studio.model) return;
  if (studio.section && studio.megno && $("show-megno").checked) drawImage(g, studio.megno);
  if (!studio.section && $("show-chaos").checked && studio.chaos) drawChaos(g);
  if (!studio.section && $("show-basins").checked && studio.basins) drawBasins(g);
  drawGrid(g, width, height);
  if (!studio.section && studio.overlay && $("show-levels").checked) drawLevels(g);
  for (const orbit of studio.orbits) {
    g.fillStyle = orbit.color;
    for (const [x, y] of orbit.points) {
      const [px, py] = toPixel(x, y);
      g.fillRect(px - 0.8, py - 0.8, 1.6, 1.6);
    }
  }
  if (studio.section) return;
  if (studio.manifolds && $("show-manifolds").checked) drawManifolds(g);
  if (studio.overlay && $("show-equilibria").checked) drawEquilibria(g);
  if (studio.branches) drawBranches(g);
}

const BIFURCATION_NAMES = { fold: "fold", branch_point: "branch point", period_doubling: "period doubling", neimark_sacker: "Neimark–Sacker", hopf: "Hopf" };

// The branches of "continue this orbit": the fixed point's path in the
// plane as the parameter moves, stable solid, unstable dashed.
function drawBranches(g) {
  g.lineWidth = 1.8;
  studio.branches.branches.forEach((branch, b) => {
    g.strokeStyle = `hsl(${(b * 97 + 140) % 360}, 70%, 35%)`;
    for (let i = 1; i < branch.points.length; i++) {
      const [x0, y0] = branch.points[i - 1];
      const [x1, y1] = branch.points[i];
      if (Math.abs(x1 - x0) > Math.PI) continue;
      g.setLineDash(branch.stable[i] ? [] : [5, 4]);
      const [a, c] = toPixel(x0, y0);
      const [d, e] = toPixel(x1, y1);
      g.beginPath();
      g.moveTo(a, c);
      g.lineTo(d, e);
      g.stroke();
    }
  });
  g.setLineDash([]);
  g.font = "11px sans-serif";
  for (const mark of studio.branches.bifurcations) {
    const [px, py] = toPixel(mark.at[0], mark.at[1]);
    g.fillStyle = "#000";
    g.fillRect(px - 3.5, py - 3.5, 7, 7);
    g.fillText(`${BIFURCATION_NAMES[mark.kind]} ${mark.parameter.toPrecision(6)}`, px + 6, py - 6);
  }
}

let continuationController = null;

// Shift-click: continue the periodic orbit nearest (x, y).
async function continueAt(x, y) {
  const seed = studio.through.slice();
  seed[studio.axes[0]] = x;
  seed[studio.axes[1]] = y;
  const parameter = $("cont-parameter").value;
  // An empty `to` is the declaration's auto (resolved by the library).
  const to = $("cont-to").value.trim() === "" ? "auto" : Number($("cont-to").value);
  if (to !== "auto" && !Number.isFinite(to)) { say("continuation: `to` is not a number"); return; }
  if (continuationController) continuationController.abort();
  continuationController = new AbortController();
  say(`continuing in ${parameter} …`);
  try {
    const { model, params, method, tol, axes } = setup();
    const request = { model, params, method, tol, axes, start: seed, parameter, to };
    const answer = await postJson("/api/continuation", request, continuationController.signal);
    studio.branches = answer;
    const items = answer.bifurcations.map((m) =>
      `<li>${BIFURCATION_NAMES[m.kind]} at ${parameter} = ${m.parameter.toPrecision(10)}${m.located ? "" : " (bracketed)"}</li>`);
    const points = answer.branches.reduce((n, b) => n + b.points.length, 0);
    $("cont-list").innerHTML = items.join("") || "<li>no bifurcation on the way</li>";
    say(`${answer.branches.length} branch(es), ${points} points in ${answer.seconds.toFixed(2)} s`);
    redraw();
  } catch (e) {
    if (!aborted(e)) say(`continuation: ${e.message}`);
  }
}

studio.continueAt = (x, y) => continueAt(x, y);

function buildContinuation(model) {
  const select = $("cont-parameter");
  select.innerHTML = model.parameters.map((p) => `<option value="${p.name}">${p.symbol}</option>`).join("");
  const chosen = model.parameters.find((p) => p.name === model.amplitude) || model.parameters[0];
  if (chosen) select.value = chosen.name;
  // Empty: the library's end (the declaration's `to = auto`).
  $("cont-to").value = "";
  $("cont-to").placeholder = "auto";
  studio.branches = null;
  $("cont-list").innerHTML = "";
}

// ---------- steady motion (constrained models) ----------

let steadyController = null;

function buildSteady(model) {
  const applies = model.kind === "constrained" || (model.kind === "hamiltonian" && !model.fast_phase);
  $("steady-controls").style.display = applies ? "" : "none";
  $("steady-speed").innerHTML = `<option value="auto">auto</option>` +
    model.coordinates.map((c) => `<option value="${c}">${c}</option>`).join("");
  $("steady-at").value = "";
  $("steady-rates").value = "";
  $("steady-start").value = "";
  studio.steady = null;
  drawSteady();
}

async function runSteady() {
  const speed = $("steady-speed").value;
  const atText = $("steady-at").value.trim();
  const at = atText === "" ? "auto" : Number(atText);
  if (at !== "auto" && !Number.isFinite(at)) { say("steady motion: `at` is not a number"); return; }
  if (steadyController) steadyController.abort();
  steadyController = new AbortController();
  say("linearising the steady motion …");
  try {
    // Empty lists are the declaration's auto; the library checks the rest.
    const list = (id) => {
      const text = $(id).value.trim();
      return text === "" ? "auto" : text.split(",").map(Number);
    };
    const request = { model: studio.model.name, params: studio.params, speed, at,
      rates: list("steady-rates"), start: list("steady-start"), sweep: 81 };
    const answer = await postJson("/api/steady_motion", request, steadyController.signal);
    studio.steady = answer;
    drawSteady();
    const m = answer.motion;
    const values = m.eigenvalues.map(([re, im], k) => `${re.toPrecision(8)}${im >= 0 ? "+" : "−"}${Math.abs(im).toPrecision(8)}i ± ${m.errors[k].toExponential(0)}`);
    const shape = answer.shape.length ? `shape ${answer.shape.join(", ")}` : "no shape coordinate";
    const verdict = typeof m.verdict === "string" ? m.verdict.replaceAll("_", " ") : Object.keys(m.verdict)[0].replaceAll("_", " ");
    const bounds = (answer.sweep?.boundaries ?? []).map((b) => `${b.speed.toPrecision(10)} ± ${b.error.toExponential(0)}`);
    $("steady-note").textContent = `${answer.speed}' = ${answer.at} (${shape}): ${verdict}; eigenvalues ${values.join(", ")}` +
      (bounds.length ? `; boundaries at ${answer.speed}' = ${bounds.join(", ")}` : "");
    say("");
    startMechanism(m.state, "the steady motion");
  } catch (e) {
    if (!aborted(e)) { studio.steady = null; drawSteady(); say(`steady motion: ${e.message}`); }
  }
}

studio.runSteady = () => runSteady();

// The sweep's eigenvalues against the speed: Re blue, |Im| grey, zero
// black, boundaries red, the speed linearised dashed.
function drawSteady() {
  const c = $("steady"), g = c.getContext("2d");
  g.clearRect(0, 0, c.width, c.height);
  const sweep = studio.steady?.sweep;
  if (!sweep) return;
  const speeds = sweep.speeds;
  const points = sweep.eigenvalues.flatMap((values, k) => values.map(([re, im]) => [speeds[k], re, Math.abs(im)]));
  const x0 = Math.min(...speeds), x1 = Math.max(...speeds);
  const top = Math.max(0, ...points.map((p) => Math.max(p[1], p[2])));
  const bottom = Math.max(-10, Math.min(0, ...points.map((p) => p[1])));
  const pad = 0.05 * Math.max(top - bottom, 1e-3);
  const px = (x) => 4 + (x - x0) / (x1 - x0 || 1) * (c.width - 8);
  const py = (y) => c.height - 4 - (y - bottom + pad) / (top - bottom + 2 * pad) * (c.height - 8);
  g.strokeStyle = "#000"; g.beginPath(); g.moveTo(px(x0), py(0)); g.lineTo(px(x1), py(0)); g.stroke();
  for (const [x, re, im] of points) {
    g.fillStyle = "#999"; g.fillRect(px(x) - 1, py(im) - 1, 2, 2);
    g.fillStyle = "#1f5fbf"; g.fillRect(px(x) - 1, py(re) - 1, 2, 2);
  }
  g.strokeStyle = "#c62828";
  for (const b of sweep.boundaries) { g.beginPath(); g.moveTo(px(b.speed), 0); g.lineTo(px(b.speed), c.height); g.stroke(); }
  g.setLineDash([3, 3]); g.strokeStyle = "#555";
  g.beginPath(); g.moveTo(px(studio.steady.at), 0); g.lineTo(px(studio.steady.at), c.height); g.stroke();
  g.setLineDash([]);
  g.fillStyle = "#333"; g.font = "11px sans-serif";
  g.fillText(`${x0.toPrecision(3)} … ${x1.toPrecision(3)}: rate of ${studio.steady.speed}`, 6, c.height - 6);
}

function drawManifolds(g) {
  g.lineWidth = 1.2;
  for (const [curve, color] of [["unstable", "rgba(200, 30, 30, 0.9)"], ["stable", "rgba(30, 60, 200, 0.9)"]]) {
    g.strokeStyle = color;
    g.beginPath();
    for (const [x0, y0, x1, y1] of studio.manifolds[curve]) {
      const [a, b] = toPixel(x0, y0);
      const [c, d] = toPixel(x1, y1);
      g.moveTo(a, b);
      g.lineTo(c, d);
    }
    g.stroke();
  }
  g.fillStyle = "#000";
  for (const [x, y] of studio.manifolds.homoclinic) {
    const [px, py] = toPixel(x, y);
    g.fillRect(px - 3, py - 3, 6, 6);
  }
}

function drawGrid(g, width, height) {
  g.strokeStyle = "#e4e4e4";
  g.lineWidth = 1;
  g.fillStyle = "#666";
  g.font = "11px sans-serif";
  const { x, y } = studio.view;
  for (const [axis, range] of [[0, x], [1, y]]) {
    const step = niceStep((range[1] - range[0]) / 8);
    for (let v = Math.ceil(range[0] / step) * step; v <= range[1]; v += step) {
      const [px, py] = toPixel(axis === 0 ? v : x[0], axis === 0 ? y[0] : v);
      g.beginPath();
      if (axis === 0) { g.moveTo(px, 0); g.lineTo(px, height); } else { g.moveTo(0, py); g.lineTo(width, py); }
      g.stroke();
      const label = Math.abs(v) < step * 1e-9 ? "0" : v.toPrecision(3).replace(/\.?0+$/, "");
      if (axis === 0) g.fillText(label, px + 2, height - 4); else g.fillText(label, 3, py - 2);
    }
  }
  g.fillStyle = "#222";
  const [xName, yName] = [axisName(0), axisName(1)];
  drawName(g, xName, width - 12 - nameWidth(g, xName), height - 18);
  drawName(g, yName, 30, 16);
}

// An axis's name as a paper sets it: the part after "_" a subscript
// (p_φ₁: p with φ₁ below, smaller).
const NAME_FONT = "italic 14px serif", SUBSCRIPT_FONT = "italic 10px serif";
function nameWidth(g, name) {
  const [base, sub = ""] = name.split("_");
  g.font = NAME_FONT;
  const wide = g.measureText(base).width;
  g.font = SUBSCRIPT_FONT;
  return wide + g.measureText(sub).width;
}
// The same in HTML (the hover line): the subscript in <sub>.
function nameHtml(name) {
  const escape = (t) => t.replace(/&/g, "&amp;").replace(/</g, "&lt;");
  const [base, sub] = escape(name).split("_");
  return sub === undefined ? base : `${base}<sub>${sub}</sub>`;
}
function drawName(g, name, x, y) {
  const [base, sub = ""] = name.split("_");
  g.font = NAME_FONT;
  g.fillText(base, x, y);
  const wide = g.measureText(base).width;
  g.font = SUBSCRIPT_FONT;
  g.fillText(sub, x + wide + 1, y + 4);
}

function niceStep(raw) {
  const power = Math.pow(10, Math.floor(Math.log10(raw)));
  const mantissa = raw / power;
  return (mantissa < 1.5 ? 1 : mantissa < 3.5 ? 2 : mantissa < 7.5 ? 5 : 10) * power;
}

function drawLevels(g) {
  for (const level of studio.overlay.levels) {
    g.strokeStyle = level.separatrix ? "rgba(200, 40, 40, 0.8)" : "rgba(90, 90, 90, 0.45)";
    g.lineWidth = level.separatrix ? 1.6 : 1;
    g.beginPath();
    for (const [x0, y0, x1, y1] of level.segments) {
      const [a, b] = toPixel(x0, y0);
      const [c, d] = toPixel(x1, y1);
      g.moveTo(a, b);
      g.lineTo(c, d);
    }
    g.stroke();
  }
}

function drawEquilibria(g) {
  for (const e of studio.overlay.equilibria) {
    if (!e.on_plane) continue;
    const [px, py] = toPixel(e.point[0], e.point[1]);
    g.beginPath();
    g.arc(px, py, 6, 0, 2 * Math.PI);
    g.lineWidth = 2;
    g.strokeStyle = e.stable ? "#127a2a" : "#c02020";
    g.fillStyle = e.stable ? "#2fb34c" : "#fff";
    g.fill();
    g.stroke();
  }
}

// A colour map from dark blue (regular) to yellow (chaotic).
function shadeColor(s) {
  const stops = [[35, 23, 80], [40, 110, 150], [60, 170, 110], [250, 225, 40]];
  const t = Math.min(Math.max(s, 0), 1) * (stops.length - 1);
  const k = Math.min(Math.floor(t), stops.length - 2);
  const f = t - k;
  return stops[k].map((c, i) => Math.round(c + f * (stops[k + 1][i] - c)));
}

function chaosImage(level) {
  return pixelImage(level.pixels, (k) => shadeColor(level.shades[k]));
}

// An n × n image of the colours [r, g, b] of the pixels k (row 0 at the bottom).
function pixelImage(n, colorOf) {
  const image = document.createElement("canvas");
  image.width = n;
  image.height = n;
  const data = image.getContext("2d").createImageData(n, n);
  for (let k = 0; k < n * n; k++) {
    const i = k % n, j = Math.floor(k / n);
    data.data.set([...colorOf(k), 255], ((n - 1 - j) * n + i) * 4);
  }
  image.getContext("2d").putImageData(data, 0, 0);
  return image;
}

function drawChaos(g) { drawImage(g, studio.chaos); }

// The plots' palette (attractor k's colour), white for diverged starts.
const PALETTE = [[31, 119, 180], [255, 127, 14], [44, 160, 44], [214, 39, 40], [148, 103, 189],
  [140, 86, 75], [227, 119, 194], [80, 80, 80], [188, 189, 34], [23, 190, 207]];
function attractorColor(label) { return label < 0 ? [255, 255, 255] : PALETTE[label % PALETTE.length]; }

function basinsImage(level) {
  return pixelImage(level.pixels, (k) => attractorColor(level.labels[k]));
}

// The basins, then each attractor's recorded iterates in black.
function drawBasins(g) {
  drawImage(g, studio.basins);
  g.fillStyle = "#000";
  for (const points of studio.basins.points) {
    for (const [x, y] of points) {
      const [px, py] = toPixel(x, y);
      g.fillRect(px - 1.5, py - 1.5, 3, 3);
    }
  }
}

// The attractor the start (x, y) of the view ends on, from the basins
// shown: its index, or null outside them.
function attractorAt(x, y) {
  const b = studio.basins;
  if (!b) return null;
  const [[x0, x1], [y0, y1]] = b.ranges;
  const i = Math.floor((x - x0) / (x1 - x0) * b.pixels), j = Math.floor((y - y0) / (y1 - y0) * b.pixels);
  if (i < 0 || j < 0 || i >= b.pixels || j >= b.pixels) return null;
  return b.labels[j * b.pixels + i];
}

// The basins' class check: the share of starts that end on another
// attractor at a hundredth of the tolerance, the fractions' numerical error.
function basinsCheckText(c) {
  if (!c) return "";
  const share = c.error === 0 || c.changed > 0 ? `${c.changed} of ${c.sampled}` : `none of ${c.sampled} (under ${(100 * c.error).toFixed(1)} %)`;
  return `; ${share} starts end elsewhere at a hundredth of the tolerance`;
}

function attractorName(label) {
  if (label < 0) return "diverged";
  const a = studio.basins.attractors[label];
  return `attractor ${label + 1}: ${a.kind}, ${(100 * a.fraction).toFixed(1)} ± ${(100 * a.fraction_error).toFixed(1)} % of the starts`;
}

function drawImage(g, { image, ranges }) {
  const [x0, y1] = toPixel(ranges[0][0], ranges[1][1]);
  const [x1, y0] = toPixel(ranges[0][1], ranges[1][0]);
  g.imageSmoothingEnabled = false;
  g.globalAlpha = 0.85;
  g.drawImage(image, x0, y1, x1 - x0, y0 - y1);
  g.globalAlpha = 1;
}

// ---------- orbits ----------

function orbitRequest(orbit) {
  return { ...setup(), seed: orbit.seed, periods: orbit.periods };
}

// Cancels an orbit's run under way and empties it for a new one.
function restart(orbit) {
  if (orbit.controller) orbit.controller.abort();
  orbit.controller = new AbortController();
  orbit.points = [];
  orbit.done = false;
  orbit.error = null;
  orbit.params = { ...studio.params };
}

function startOrbit(orbit) {
  if (orbit.section) { startSectionOrbit(orbit); return; }
  restart(orbit);
  const request = orbitRequest(orbit);
  startMechanism(orbit.seed);
  postStream("/api/orbit", request, orbit.controller.signal, (line) => {
    if (line.points) {
      for (const p of line.points) orbit.points.push(p);
      studio.pointsReceived += line.points.length;
      redraw();
    } else if (line.end) {
      orbit.done = true;
      orbit.end = line.end;
    } else if (line.error) {
      orbit.error = line.error;
      orbit.done = true;
      say(`orbit ${orbit.id}: ${line.error}`);
    }
  }).catch((e) => {
    if (aborted(e)) return;
    orbit.error = e.message;
    orbit.done = true;
    say(`orbit ${orbit.id}: ${e.message}`);
  }).finally(() => { listOrbits(); redraw(); });
}

// ---------- the mechanism, moving ----------

const mechanismCanvas = $("mechanism");
const mctx = mechanismCanvas.getContext("2d");
let mechanismController = null;

// The mechanism from `seed` (the orbit's), over the time asked for, in
// the declared number of frames, played over 20 seconds whatever the
// model's time scale.
const MECHANISM_SECONDS = 20;
async function startMechanism(seed, from = `orbit ${studio.orbits.length}'s seed`) {
  if (mechanismController) mechanismController.abort();
  studio.mechanism = null;
  if (!studio.model.points.length) return;
  mechanismController = new AbortController();
  const duration = Number($("mechanism-time").value);
  try {
    const m = await postJson("/api/mechanism", { ...setup(), seed, duration }, mechanismController.signal);
    const all = m.frames.flat(), span = (k) => [Math.min(...all.map((p) => p[k])), Math.max(...all.map((p) => p[k]))];
    const [[x0, x1], [y0, y1], [z0, z1]] = [span(0), span(1), span(2)];
    m.box = [x0, x1, y0, y1];
    // In space: the sphere about the box's middle that holds every frame,
    // so that turning the view never moves the mechanism out of it.
    m.middle = [(x0 + x1) / 2, (y0 + y1) / 2, (z0 + z1) / 2];
    m.radius = Math.max(1e-9, ...all.map((p) => Math.hypot(p[0] - m.middle[0], p[1] - m.middle[1], p[2] - m.middle[2])));
    m.tips = new Set(m.body_frames.flatMap(([, ...tips]) => tips));
    m.started = performance.now();
    studio.mechanism = m;
    const turn = m.in_space ? "; drag it to turn the view" : "";
    $("mechanism-note").textContent = `the mechanism from ${from} (${m.points.filter((_, p) => !m.tips.has(p)).join(", ")})${turn}`;
  } catch (e) {
    if (!aborted(e)) $("mechanism-note").textContent = `mechanism: ${e.message}`;
  }
}

// The view of a mechanism in space, orthographic: from the azimuth about
// the way up and the elevation above the horizontal (radians), turned by
// dragging the canvas.
studio.mechanismView = { azimuth: 0.6, elevation: 0.35 };
const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
const unit = (a) => { const n = Math.hypot(...a); return a.map((c) => c / n); };

// The screen's right and up in space for the view: the horizontal h1 is
// the fixed axis least along `up`, levelled; h2 = up × h1; the eye looks
// from cos(e)(cos(a) h1 + sin(a) h2) + sin(e) up.
function viewAxes(up, { azimuth, elevation }) {
  const axes = [[1, 0, 0], [0, 1, 0], [0, 0, 1]];
  const level = axes.reduce((a, b) => (Math.abs(dot(b, up)) < Math.abs(dot(a, up)) ? b : a));
  const h1 = unit(level.map((c, k) => c - dot(level, up) * up[k]));
  const h2 = cross(up, h1);
  const eye = [0, 1, 2].map((k) => Math.cos(elevation) * (Math.cos(azimuth) * h1[k] + Math.sin(azimuth) * h2[k]) + Math.sin(elevation) * up[k]);
  const right = unit(cross(up, eye));
  return { right, up: cross(eye, right) };
}

// Where a point (x, y, z) of `m` falls on a canvas w × h: the plane (x, y)
// fitted to its box, or space seen from `studio.view`.
function mechanismProjection(m, w, h) {
  if (!m.in_space) {
    const [x0, x1, y0, y1] = m.box;
    const scale = 0.85 * Math.min(w / Math.max(x1 - x0, 1e-9), h / Math.max(y1 - y0, 1e-9));
    return ([x, y]) => [w / 2 + (x - (x0 + x1) / 2) * scale, h / 2 - (y - (y0 + y1) / 2) * scale];
  }
  const { right, up } = viewAxes(m.up, studio.mechanismView);
  const scale = (0.85 * Math.min(w, h)) / (2 * m.radius);
  return (p) => {
    const d = p.map((c, k) => c - m.middle[k]);
    return [w / 2 + dot(d, right) * scale, h / 2 - dot(d, up) * scale];
  };
}
studio.mechanismProjection = mechanismProjection;

const AXIS_COLOURS = ["#c0392b", "#27ae60", "#2e6fbd"];

function drawMechanism(now) {
  const g = mctx, w = mechanismCanvas.width, h = mechanismCanvas.height;
  g.fillStyle = "#fff";
  g.fillRect(0, 0, w, h);
  const m = studio.mechanism;
  if (!m) return;
  const perSecond = (m.frames.length - 1) / MECHANISM_SECONDS;
  const f = Math.min(m.frames.length - 1, Math.floor(((now - m.started) / 1000) * perSecond));
  studio.mechanismFrame = f;
  const at = mechanismProjection(m, w, h);
  if (m.in_space) {
    // The fixed axes at the origin, faint, for the way the view is turned.
    const o = at([0, 0, 0]);
    g.lineWidth = 1;
    g.font = "11px system-ui";
    [[1, 0, 0], [0, 1, 0], [0, 0, 1]].forEach((e, k) => {
      const tip = at(e.map((c) => 0.3 * m.radius * c));
      g.strokeStyle = g.fillStyle = "rgba(90, 90, 90, 0.5)";
      g.beginPath();
      g.moveTo(...o);
      g.lineTo(...tip);
      g.stroke();
      g.fillText("xyz"[k], tip[0] + 2, tip[1] - 2);
    });
  }
  // The last second's path of each point, faint.
  const trail = Math.round(perSecond);
  g.strokeStyle = "rgba(35, 57, 91, 0.25)";
  g.lineWidth = 1;
  for (let p = 0; p < m.points.length; p++) {
    if (m.tips.has(p)) continue;
    g.beginPath();
    for (let k = Math.max(0, f - trail); k <= f; k++) {
      const [px, py] = at(m.frames[k][p]);
      if (k === Math.max(0, f - trail)) g.moveTo(px, py); else g.lineTo(px, py);
    }
    g.stroke();
  }
  const points = m.frames[f].map(at);
  g.strokeStyle = "#23395b";
  g.lineWidth = 3;
  for (const [a, b] of m.bars) {
    g.beginPath();
    g.moveTo(...points[a]);
    g.lineTo(...points[b]);
    g.stroke();
  }
  // Each body as its frame: x, y, z axes red, green, blue.
  g.lineWidth = 2.5;
  for (const [centre, ...tips] of m.body_frames) {
    tips.forEach((tip, k) => {
      g.strokeStyle = AXIS_COLOURS[k];
      g.beginPath();
      g.moveTo(...points[centre]);
      g.lineTo(...points[tip]);
      g.stroke();
    });
  }
  g.fillStyle = "#b5462f";
  g.font = "12px system-ui";
  points.forEach(([px, py], p) => {
    if (m.tips.has(p)) return;
    g.beginPath();
    g.arc(px, py, 4.5, 0, 2 * Math.PI);
    g.fill();
    g.fillText(m.points[p], px + 6, py - 6);
  });
  const end = m.times[m.times.length - 1];
  $("mechanism-clock").textContent = `t = ${m.times[f].toPrecision(4)} of ${end} (played over ${MECHANISM_SECONDS} s)`;
}

// Turns the view of a mechanism in space by (azimuth, elevation) radians,
// the elevation kept short of the poles.
studio.turnView = (azimuth, elevation) => {
  const v = studio.mechanismView;
  v.azimuth += azimuth;
  v.elevation = Math.max(-1.5, Math.min(1.5, v.elevation + elevation));
};

function seedAt(x, y) {
  if (studio.section) { seedSection(x, y); return; }
  const seed = studio.through.slice();
  seed[studio.axes[0]] = x;
  seed[studio.axes[1]] = y;
  if (!studio.model.fast_phase) {
    // No period map; the mechanism still moves from the state clicked.
    say(`model '${studio.model.name}' has no fast phase: there is no period map to draw${studio.model.points.length ? "; the mechanism moves from the state clicked" : ""}`);
    startMechanism(seed, "the state clicked");
    return;
  }
  const id = studio.nextId++;
  const orbit = { id, seed, color: orbitColor(id), periods: Math.max(1, Math.round(Number($("periods").value))), points: [] };
  studio.orbits.push(orbit);
  say("");
  startOrbit(orbit);
  listOrbits();
}

// ---------- the Poincaré section (a slice of the period map with a fast phase) ----------

// The section's settings as the page sets them (the `section`
// declaration's names): the plane is the typed function, else the chosen
// coordinate.
function sectionSettings() {
  const { model, params, tol } = setup();
  const coordinate = studio.model.coordinates[Number($("section-coordinate").value)];
  return {
    model, params, tol,
    energy: Number($("energy").value),
    plane: $("section-plane").value.trim() || coordinate,
    value: Number($("section-value").value),
    rising: $("section-direction").value === "rising",
  };
}

function seedSection(x, y) {
  const id = studio.nextId++;
  const orbit = { id, seed: [x, y], section: true, color: orbitColor(id),
    periods: Math.max(1, Math.round(Number($("periods").value))), points: [] };
  studio.orbits.push(orbit);
  say("");
  startSectionOrbit(orbit);
  listOrbits();
}

async function startSectionOrbit(orbit) {
  restart(orbit);
  const request = { ...sectionSettings(), seeds: [orbit.seed], crossings: orbit.periods };
  try {
    const answer = await postJson("/api/section", request, orbit.controller.signal);
    orbit.points = answer.points;
    orbit.drift = answer.energy_drift;
    if (answer.end.kind !== "complete") say(`section orbit ${answer.points.length} points: ${answer.end_text}`);
    studio.sectionAxes = answer.axes;
    studio.pointsReceived += answer.points.length;
  } catch (e) {
    if (aborted(e)) return;
    orbit.error = e.message;
    say(`section: ${e.message}`);
  }
  orbit.done = true;
  // No map has placed the view, and the orbit is outside it: show the orbit.
  const visible = ([x, y]) => x >= studio.view.x[0] && x <= studio.view.x[1] && y >= studio.view.y[0] && y <= studio.view.y[1];
  if (!studio.megnoViewSet && orbit.points.length && !orbit.points.some(visible)) fitView(orbit.points);
  listOrbits();
  redraw();
}

// The view around `points`, padded by a tenth of each side.
function fitView(points) {
  const side = (values) => {
    const lo = Math.min(...values), hi = Math.max(...values), pad = 0.1 * Math.max(hi - lo, 1e-3);
    return [lo - pad, hi + pad];
  };
  studio.view = { x: side(points.map((p) => p[0])), y: side(points.map((p) => p[1])) };
}

let megnoController = null;

// A map's class check after its chaotic fraction: ± the share of pixels a
// run at a hundredth of the tolerance reclassifies; where none is, the rule
// of three's bound.
function classCheckText(c) {
  if (!c) return "";
  if (c.error === 0) return ` (${c.changed} of all ${c.sampled} pixels reclassified at a hundredth of the tolerance)`;
  return c.changed === 0
    ? ` (none of ${c.sampled} pixels reclassified at a hundredth of the tolerance: under ${(100 * c.error).toFixed(1)} % would be)`
    : ` ± ${(100 * Math.max(c.fraction, c.error)).toFixed(1)} % (${c.changed} of ${c.sampled} pixels reclassified at a hundredth of the tolerance)`;
}

// The MEGNO map of the section, refined 32² → 64² → 128².
async function refreshMegno() {
  if (megnoController) megnoController.abort();
  megnoController = null;
  if (!studio.section || !$("show-megno").checked) { studio.megno = null; $("megno-note").textContent = ""; redraw(); return; }
  if (studio.model.kind === "constrained") { studio.megno = null; $("megno-note").textContent = "(not computed on constraints)"; redraw(); return; }
  megnoController = new AbortController();
  const signal = megnoController.signal;
  const t_max = Number($("megno-time").value);
  for (const pixels of [32, 64, 128]) {
    try {
      const map = await postJson("/api/section_map", { ...sectionSettings(), map: pixels, map_time: t_max }, signal);
      studio.megno = { ranges: map.window, image: megnoImage(map) };
      studio.sectionAxes = map.axes;
      $("megno-note").textContent = `(${pixels}², chaotic ${(100 * map.chaotic_fraction).toFixed(1)} %${classCheckText(map.class_check)})`;
      if (pixels === 32 && !studio.megnoViewSet) {
        studio.view = { x: map.window[0].slice(), y: map.window[1].slice() };
        studio.megnoViewSet = true;
      }
      redraw();
    } catch (e) {
      if (!aborted(e)) { say(`MEGNO map: ${e.message}`); studio.megno = null; redraw(); }
      return;
    }
  }
}

// ⟨Y⟩ ≈ 2 on tori (light), growing in the chaotic sea (dark); white where
// the energy is not accessible.
function megnoImage(map) {
  return pixelImage(map.pixels, (k) => {
    const y = map.megno[k];
    if (y === null) return [255, 255, 255];
    const shade = Math.round(255 - 200 * Math.min(1, Math.max(0, (y - 2) / 4)));
    return [shade, shade, Math.min(255, shade + 20)];
  });
}

// Section mode: the page's plane becomes (other coordinate, its momentum).
function setSectionMode(on) {
  const model = studio.model;
  studio.section = on;
  studio.sectionAxes = null;
  removeOrbits(0);
  if (on) {
    // A constrained model's chart is the server's (the first coordinate
    // that, held with the plane's, fixes the others): its names come back
    // with the first orbit.
    const n = model.state.length / 2;
    const other = model.kind === "constrained" ? 0 : 1 - Number($("section-coordinate").value);
    studio.axes = [other, n + other];
    studio.view = { x: [-1, 1], y: [-1, 1] };
    studio.megnoViewSet = false;
  } else {
    studio.axes = model.default_axes.slice();
    defaultView(model);
  }
  buildAxes(model);
  refreshMegno();
  redraw();
}

function buildSection(model) {
  const applies = model.section;
  $("section-energy-of").textContent = model.fast_phase ? "H̄" : "H";
  $("section-controls").style.display = applies ? "" : "none";
  $("show-section").checked = false;
  $("section-plane").value = "";
  studio.section = false;
  studio.megno = null;
  $("section-coordinate").innerHTML = model.state.slice(0, model.state.length / 2).map((name, i) => `<option value="${i}">${name}</option>`).join("");
}

studio.sectionSeed = (x, y) => seedSection(x, y);

// Scripting from the browser's console: studio.seed(q, p) seeds an orbit.
studio.seed = (x, y) => seedAt(x, y);

function listOrbits() {
  const list = $("orbit-list");
  list.innerHTML = "";
  for (const orbit of studio.orbits) {
    const item = document.createElement("li");
    item.style.color = orbit.color;
    const seed = orbit.seed.map((v) => v.toFixed(3)).join(", ");
    const tunes = orbit.end && orbit.end.tunes ? ` ν ${orbit.end.tunes.map((t) => t.toFixed(5)).join(", ")}` : "";
    item.textContent = `(${seed}) ${orbit.points.length} pts${orbit.error ? " stopped" : orbit.done ? "" : " …"}${tunes}`;
    if (tunes) item.title = "the orbit's tunes: turns per period of each degree of freedom (NAFF of q + i p over the iterates)";
    const label = studio.basins && $("show-basins").checked ? attractorAt(orbit.seed[studio.axes[0]], orbit.seed[studio.axes[1]]) : null;
    if (label !== null) {
      const mark = document.createElement("span");
      mark.className = "attractor";
      mark.style.background = `rgb(${attractorColor(label).join(",")})`;
      mark.title = "the attractor its start ends on, from the basins shown";
      item.append(" → ", mark, ` ${attractorName(label)}`);
    }
    if (orbit.error) { item.className = "error"; item.title = orbit.error; }
    list.appendChild(item);
  }
}

function removeOrbits(keep) {
  for (const orbit of studio.orbits.slice(keep)) if (orbit.controller) orbit.controller.abort();
  studio.orbits = studio.orbits.slice(0, keep);
  listOrbits();
  redraw();
}

// ---------- overlays ----------

let overlayController = null;
let chaosController = null;

function viewRanges() { return [studio.view.x.slice(), studio.view.y.slice()]; }

async function refreshOverlay() {
  if (overlayController) overlayController.abort();
  overlayController = new AbortController();
  const wanted = $("show-levels").checked || $("show-equilibria").checked;
  if (!wanted || studio.model.kind !== "hamiltonian") { studio.overlay = null; redraw(); return; }
  try {
    studio.overlay = await postJson("/api/overlay",
      { ...setup(), ranges: viewRanges(), order: Number($("order").value) }, overlayController.signal);
    redraw();
  } catch (e) {
    if (!aborted(e)) say(`overlay: ${e.message}`);
  }
}

async function refreshChaos() {
  if (chaosController) chaosController.abort();
  chaosController = null;
  if (!$("show-chaos").checked || !studio.model.fast_phase) { studio.chaos = null; redraw(); return; }
  chaosController = new AbortController();
  const ranges = viewRanges();
  const request = { ...setup(), ranges, levels: [24, 48, 96, 192],
    periods: Math.max(1, Math.round(Number($("chaos-periods").value))) };
  try {
    await postStream("/api/chaos", request, chaosController.signal, (line) => {
      if (line.error) { say(`chaos map: ${line.error}`); return; }
      studio.chaos = { ...line, ranges, image: chaosImage(line) };
      $("status").textContent = `FLI ${line.pixels}² in ${line.seconds.toFixed(2)} s, chaotic ${(100 * line.chaotic_fraction).toFixed(1)} %${classCheckText(line.class_check)}`;
      redraw();
    });
  } catch (e) {
    if (!aborted(e)) say(`chaos map: ${e.message}`);
  }
}

let basinsController = null;

async function refreshBasins() {
  if (basinsController) basinsController.abort();
  basinsController = null;
  if (!$("show-basins").checked || !studio.model.fast_phase) {
    studio.basins = null; $("basins-note").textContent = ""; listOrbits(); redraw(); return;
  }
  basinsController = new AbortController();
  const ranges = viewRanges();
  const request = { ...setup(), ranges, levels: [32, 64, 128, 256],
    transient: Math.max(0, Math.round(Number($("basins-transient").value))) };
  try {
    await postStream("/api/basins", request, basinsController.signal, (line) => {
      if (line.error) { say(`basins: ${line.error}`); return; }
      studio.basins = { ...line, ranges, image: basinsImage(line) };
      const d = line.boundary.dimension;
      $("basins-note").textContent = `(${line.attractors.length} attractor${line.attractors.length === 1 ? "" : "s"}${d == null ? "" : `, boundary dimension ${d.toFixed(2)}`})`;
      $("status").textContent = `basins ${line.pixels}² in ${line.seconds.toFixed(2)} s${basinsCheckText(line.class_check)}`;
      listOrbits();
      redraw();
    });
  } catch (e) {
    if (!aborted(e)) say(`basins: ${e.message}`);
  }
}

// Waits until the changes stop for `ms` before calling `work`.
function debounce(work, ms) {
  let timer = null;
  return () => { clearTimeout(timer); timer = setTimeout(work, ms); };
}
let manifoldsController = null;
let manifoldsKey = null;

// The manifolds depend on the model and its parameters, not on the view.
async function refreshManifolds() {
  const wanted = $("show-manifolds").checked && studio.model.fast_phase && studio.model.state.length === 2;
  if (!wanted) { studio.manifolds = null; manifoldsKey = null; $("manifolds-note").textContent = ""; redraw(); return; }
  const { model, params, method, tol } = setup();
  const request = { model, params, method, tol };
  const key = JSON.stringify(request);
  if (key === manifoldsKey) return;
  if (manifoldsController) manifoldsController.abort();
  manifoldsController = new AbortController();
  manifoldsKey = key;
  $("manifolds-note").textContent = "(growing …)";
  try {
    studio.manifolds = await postJson("/api/manifolds", request, manifoldsController.signal);
    const m = studio.manifolds;
    $("manifolds-note").textContent = m.resolved
      ? `(lobe area ${m.lobe_area.toPrecision(6)}, angle ${m.angle.toPrecision(3)})`
      : `(lobe area ${m.lobe_area.toExponential(2)}, not resolved)`;
    redraw();
  } catch (e) {
    if (!aborted(e)) { manifoldsKey = null; studio.manifolds = null; $("manifolds-note").textContent = ""; say(`manifolds: ${e.message}`); }
  }
}
const refreshOverlays = debounce(() => { refreshOverlay(); refreshChaos(); refreshBasins(); refreshManifolds(); }, 150);
const rerunOrbits = debounce(() => { for (const orbit of studio.orbits) startOrbit(orbit); listOrbits(); }, 40);

// ---------- the model and its controls ----------

function sliderRange(value) {
  if (value > 0) return [0, 2.5 * value];
  if (value < 0) return [2.5 * value, 0];
  return [0, 1];
}

function buildParameters(model) {
  const box = $("params");
  box.innerHTML = "";
  for (const p of model.parameters) {
    const row = document.createElement("div");
    row.className = "param";
    row.title = p.description;
    const [lo, hi] = sliderRange(p.default);
    row.innerHTML = `<span>${p.symbol}</span><input type="range" id="param-${p.name}" min="${lo}" max="${hi}" step="${(hi - lo) / 500}" value="${p.default}"><input type="number" id="value-${p.name}" step="any" value="${p.default}">`;
    box.appendChild(row);
    const slider = row.querySelector("input[type=range]");
    const number = row.querySelector("input[type=number]");
    const set = (value) => {
      if (!Number.isFinite(value)) { say(`${p.name}: not a number`); return; }
      studio.params[p.name] = value;
      rerunOrbits();
      refreshOverlays();
    };
    slider.addEventListener("input", () => { number.value = slider.value; set(Number(slider.value)); });
    number.addEventListener("change", () => { slider.value = number.value; set(Number(number.value)); });
    studio.params[p.name] = p.default;
  }
}

function buildAxes(model) {
  for (const [k, id] of [[0, "axis-x"], [1, "axis-y"]]) {
    const select = $(id);
    select.innerHTML = model.state.map((name, i) => `<option value="${i}">${name}</option>`).join("");
    select.value = String(studio.axes[k]);
  }
  $("axes-row").style.display = model.state.length > 2 ? "" : "none";
  $("through").value = studio.through.join(", ");
}

function defaultView(model) {
  studio.view = { x: model.default_ranges[0].slice(), y: model.default_ranges[1].slice() };
}

async function chooseModel(name, address = new URLSearchParams()) {
  const model = studio.models.find((m) => m.name === name);
  if (!model) return;
  removeOrbits(0);
  studio.ready = false;
  studio.model = model;
  studio.params = {};
  studio.axes = model.default_axes.slice();
  studio.through = (model.through ?? new Array(model.state.length).fill(0)).slice();
  studio.overlay = null;
  studio.chaos = null;
  studio.basins = null;
  studio.manifolds = null;
  manifoldsKey = null;
  $("model").value = name;
  $("model-file").textContent = model.source_file;
  $("levels-of").textContent = model.fast_phase ? "H̄" : "H";
  $("derivations-model").textContent = name;
  buildParameters(model);
  buildAxes(model);
  buildContinuation(model);
  buildSection(model);
  buildSteady(model);
  $("order").disabled = !model.fast_phase;
  // A constrained model of more than 6 coordinates or long forms has no
  // Taylor recurrences: its orbits run with DOP853.
  if (!model.taylor && $("method").value === "taylor") $("method").value = "dop853";
  $("order").value = "1";
  studio.mechanism = null;
  $("mechanism-note").textContent = model.points.length
    ? "click the plane: the mechanism moves from the orbit's seed"
    : `model '${name}' names no points: give its model file [[points]] (name, at = [x, y] or [x, y, z], joined_to) or [[bodies]] to draw it here`;
  defaultView(model);
  const notes = {
    contacts: `model '${name}' is a contact model: no phase plane here, its derivations are below`,
    constrained: `model '${name}' is constrained: a click seeds an orbit on its constraints (the axes' components held, the others follow from the constraints), a shift-click continues it in the chart of the axes (one degree of freedom on the constraints), the mechanism moves above the parameters; the level sets and equilibria are not drawn for it`,
  };
  say(notes[model.kind] ?? (model.fast_phase ? "" : `model '${name}' has no fast phase: no period map; the level sets of H and the equilibria are shown`));
  applyAddress(address);
  redraw();
  refreshOverlays();
  try {
    const formulas = await getJson(`/api/models/${name}/derivations`);
    $("formulas").innerHTML = formulas.map((d) =>
      `<div class="formula"><div class="what">${d.description} <code>${d.key}</code></div>${d.mathml}</div>`).join("");
  } catch (e) {
    say(`derivations: ${e.message}`);
  }
  studio.ready = true;
}

// ---------- pointer: click to seed, drag to pan, wheel to zoom ----------

let press = null;
canvas.addEventListener("mousedown", (e) => {
  press = { x: e.offsetX, y: e.offsetY, view: { x: studio.view.x.slice(), y: studio.view.y.slice() }, moved: false };
});
canvas.addEventListener("mousemove", (e) => {
  if (studio.model) {
    const [x, y] = toWorld(e.offsetX, e.offsetY);
    $("hover").innerHTML = `${nameHtml(axisName(0))} = ${x.toFixed(4)}, ${nameHtml(axisName(1))} = ${y.toFixed(4)}`;
  }
  if (!press) return;
  const dx = e.offsetX - press.x, dy = e.offsetY - press.y;
  if (!press.moved && Math.hypot(dx, dy) < 4) return;
  press.moved = true;
  const sx = (press.view.x[1] - press.view.x[0]) / canvas.width;
  const sy = (press.view.y[1] - press.view.y[0]) / canvas.height;
  studio.view = { x: press.view.x.map((v) => v - dx * sx), y: press.view.y.map((v) => v + dy * sy) };
  redraw();
});
window.addEventListener("mouseup", (e) => {
  if (!press) return;
  const wasDrag = press.moved;
  press = null;
  if (wasDrag) { refreshOverlays(); return; }
  if (e.target !== canvas || !studio.model) return;
  const [x, y] = toWorld(e.offsetX, e.offsetY);
  if (e.shiftKey) continueAt(x, y);
  else seedAt(x, y);
});
canvas.addEventListener("wheel", (e) => {
  e.preventDefault();
  const [cx, cy] = toWorld(e.offsetX, e.offsetY);
  const factor = Math.exp(0.0015 * e.deltaY);
  studio.view = {
    x: studio.view.x.map((v) => cx + (v - cx) * factor),
    y: studio.view.y.map((v) => cy + (v - cy) * factor),
  };
  redraw();
  refreshOverlays();
}, { passive: false });

// ---------- export ----------

function download(name, blob) {
  const link = document.createElement("a");
  link.href = URL.createObjectURL(blob);
  link.download = name;
  link.click();
  setTimeout(() => URL.revokeObjectURL(link.href), 1000);
}

function exportSvg() {
  const w = canvas.width, h = canvas.height;
  const parts = [`<svg xmlns="http://www.w3.org/2000/svg" width="${w}" height="${h}" viewBox="0 0 ${w} ${h}"><rect width="${w}" height="${h}" fill="#fff"/>`];
  if ($("show-chaos").checked && studio.chaos) {
    const { image, ranges } = studio.chaos;
    const [x0, y1] = toPixel(ranges[0][0], ranges[1][1]);
    const [x1, y0] = toPixel(ranges[0][1], ranges[1][0]);
    parts.push(`<image href="${image.toDataURL()}" x="${x0}" y="${y1}" width="${x1 - x0}" height="${y0 - y1}" opacity="0.85" style="image-rendering:pixelated"/>`);
  }
  if ($("show-basins").checked && studio.basins) {
    const { image, ranges } = studio.basins;
    const [x0, y1] = toPixel(ranges[0][0], ranges[1][1]);
    const [x1, y0] = toPixel(ranges[0][1], ranges[1][0]);
    parts.push(`<image href="${image.toDataURL()}" x="${x0}" y="${y1}" width="${x1 - x0}" height="${y0 - y1}" opacity="0.85" style="image-rendering:pixelated"/>`);
    const d = studio.basins.points.flat().map(([x, y]) => { const [p, q] = toPixel(x, y); return `M${(p - 1.5).toFixed(1)} ${(q - 1.5).toFixed(1)}h3v3h-3z`; }).join("");
    parts.push(`<path d="${d}" fill="#000"/>`);
  }
  if (studio.overlay && $("show-levels").checked) {
    for (const level of studio.overlay.levels) {
      const d = level.segments.map(([a, b, c, e]) => {
        const [p, q] = toPixel(a, b), [r, s] = toPixel(c, e);
        return `M${p.toFixed(1)} ${q.toFixed(1)}L${r.toFixed(1)} ${s.toFixed(1)}`;
      }).join("");
      parts.push(`<path d="${d}" stroke="${level.separatrix ? "#c82828" : "#999"}" fill="none"/>`);
    }
  }
  for (const orbit of studio.orbits) {
    const d = orbit.points.map(([x, y]) => { const [p, q] = toPixel(x, y); return `M${p.toFixed(1)} ${q.toFixed(1)}h0.1`; }).join("");
    parts.push(`<path d="${d}" stroke="${orbit.color}" stroke-width="1.6" stroke-linecap="round" fill="none"/>`);
  }
  parts.push("</svg>");
  download(`studio_${studio.model.name}.svg`, new Blob(parts, { type: "image/svg+xml" }));
}

function exportCsv() {
  const names = studio.axes.map(stateName);
  const rows = [`orbit,${names[0]},${names[1]},${Object.keys(studio.params).join(",")}`];
  for (const orbit of studio.orbits) {
    const values = Object.values(orbit.params).join(",");
    for (const [x, y] of orbit.points) rows.push(`${orbit.id},${x},${y},${values}`);
  }
  download(`studio_${studio.model.name}.csv`, new Blob([rows.join("\n") + "\n"], { type: "text/csv" }));
}

// ---------- wiring ----------

function wire() {
  $("model").addEventListener("change", () => chooseModel($("model").value));
  $("steady-run").addEventListener("click", runSteady);
  $("undo").addEventListener("click", () => removeOrbits(studio.orbits.length - 1));
  $("clear").addEventListener("click", () => removeOrbits(0));
  $("reset-view").addEventListener("click", () => { defaultView(studio.model); redraw(); refreshOverlays(); });
  for (const id of ["method", "tol"]) $(id).addEventListener("change", () => { rerunOrbits(); refreshOverlays(); });
  for (const id of ["show-levels", "show-equilibria"]) $(id).addEventListener("change", () => { refreshOverlay(); redraw(); });
  $("show-manifolds").addEventListener("change", refreshManifolds);
  $("show-section").addEventListener("change", () => setSectionMode($("show-section").checked));
  const sectionChanged = debounce(() => { if (studio.section) { rerunOrbits(); refreshMegno(); } }, 150);
  $("energy").addEventListener("change", () => { $("energy-slider").value = $("energy").value; sectionChanged(); });
  $("energy-slider").addEventListener("input", () => { $("energy").value = $("energy-slider").value; sectionChanged(); });
  for (const id of ["section-value", "section-direction", "show-megno", "megno-time"]) $(id).addEventListener("change", sectionChanged);
  $("section-coordinate").addEventListener("change", () => { if (studio.section) setSectionMode(true); });
  $("section-plane").addEventListener("change", () => { if (studio.section) setSectionMode(true); });
  $("cont-clear").addEventListener("click", () => { studio.branches = null; $("cont-list").innerHTML = ""; redraw(); });
  for (const id of ["show-chaos", "chaos-periods"]) $(id).addEventListener("change", refreshChaos);
  for (const id of ["show-basins", "basins-transient"]) $(id).addEventListener("change", refreshBasins);
  for (const [k, id] of [[0, "axis-x"], [1, "axis-y"]]) {
    $(id).addEventListener("change", () => {
      const axes = studio.axes.slice();
      axes[k] = Number($(id).value);
      if (axes[0] === axes[1]) { say("the two axes must differ"); $(id).value = String(studio.axes[k]); return; }
      studio.axes = axes;
      const periodic = axes.map((a) => studio.model.periodic[a]);
      studio.view = { x: periodic[0] ? [-Math.PI, Math.PI] : [-3, 3], y: periodic[1] ? [-Math.PI, Math.PI] : [-3, 3] };
      removeOrbits(0);
      refreshOverlays();
    });
  }
  $("order").addEventListener("change", refreshOverlay);
  $("through").addEventListener("change", () => {
    const state = $("through").value.split(",").map((v) => Number(v.trim()));
    if (state.length !== studio.model.state.length || !state.every(Number.isFinite)) {
      say(`the plane passes through a state of ${studio.model.state.length} numbers, comma-separated`);
      $("through").value = studio.through.join(", ");
      return;
    }
    studio.through = state;
    say("");
    removeOrbits(0);
    refreshOverlays();
  });
  $("mechanism-replay").addEventListener("click", () => { if (studio.mechanism) studio.mechanism.started = performance.now(); });
  // Dragging the mechanism in space turns the view.
  let dragged = null;
  mechanismCanvas.addEventListener("pointerdown", (e) => {
    dragged = [e.clientX, e.clientY];
    try { mechanismCanvas.setPointerCapture(e.pointerId); } catch { /* a pointer no longer down */ }
  });
  mechanismCanvas.addEventListener("pointerup", () => { dragged = null; });
  mechanismCanvas.addEventListener("pointermove", (e) => {
    if (!dragged || !studio.mechanism || !studio.mechanism.in_space) return;
    studio.turnView(-0.01 * (e.clientX - dragged[0]), 0.01 * (e.clientY - dragged[1]));
    dragged = [e.clientX, e.clientY];
  });
  $("export-png").addEventListener("click", () => canvas.toBlob((blob) => download(`studio_${studio.model.name}.png`, blob)));
  $("export-svg").addEventListener("click", exportSvg);
  $("export-csv").addEventListener("click", exportCsv);
  // Points per second, for the status line.
  let last = 0;
  setInterval(() => {
    const rate = studio.pointsReceived - last;
    last = studio.pointsReceived;
    if (rate > 0) $("status").textContent = `${rate} points/s`;
    if (studio.orbits.some((o) => !o.done)) listOrbits();
  }, 1000);
}

// ---------- the address ----------
// The page's state lives in its address, so that a view can be shared and
// reloaded: /?model=kapitza&A=1.2&axes=0,1&x=-3.14,3.14&y=-2,2&show=levels,chaos
// (the parameters that differ from the model file's, the axes, the view's
// ranges, the overlays shown).
const shownInAddress = ["levels", "equilibria", "chaos", "basins", "manifolds"];

function addressOf() {
  const a = new URLSearchParams({ model: studio.model.name });
  for (const p of studio.model.parameters) {
    if (studio.params[p.name] !== p.default) a.set(p.name, studio.params[p.name]);
  }
  const round = (v) => Number(v.toPrecision(6));
  a.set("axes", studio.axes.join(","));
  a.set("x", studio.view.x.map(round).join(","));
  a.set("y", studio.view.y.map(round).join(","));
  a.set("show", shownInAddress.filter((id) => $(`show-${id}`).checked).join(","));
  return `?${a}`;
}

const saveAddress = debounce(() => {
  if (studio.ready && studio.model) history.replaceState(null, "", addressOf());
}, 300);

function applyAddress(a) {
  for (const p of studio.model.parameters) {
    const value = Number(a.get(p.name));
    if (!a.has(p.name) || !Number.isFinite(value)) continue;
    studio.params[p.name] = value;
    $(`param-${p.name}`).value = value;
    $(`value-${p.name}`).value = value;
  }
  const pair = (key) => {
    const v = (a.get(key) || "").split(",").map(Number);
    return v.length === 2 && v.every(Number.isFinite) ? v : null;
  };
  const axes = pair("axes"), states = studio.model.state.length;
  if (axes && axes[0] !== axes[1] && axes.every((i) => Number.isInteger(i) && i >= 0 && i < states)) {
    studio.axes = axes;
    buildAxes(studio.model);
  }
  const [x, y] = [pair("x"), pair("y")];
  if (x && y && x[0] < x[1] && y[0] < y[1]) studio.view = { x, y };
  if (a.has("show")) {
    const shown = new Set(a.get("show").split(","));
    for (const id of shownInAddress) $(`show-${id}`).checked = shown.has(id);
  }
}

// The analyses' settings as the library declares them (GET /api/schema):
// the page's inputs for them start from the declared defaults, or the
// studio's interactive values where it has lighter ones; no default is
// written in this script.
const declaredInputs = [
  ["chaos-periods", "chaos_map", "periods"], ["basins-transient", "basins", "transient"],
  ["method", "orbit", "method"], ["tol", "orbit", "tol"], ["periods", "orbit", "periods"],
  ["mechanism-time", "mechanism", "duration"],
];

function applySchema(schema) {
  studio.schema = Object.fromEntries(schema.map((s) => [s.analysis, s]));
  for (const [id, analysis, name] of declaredInputs) {
    const { settings, interactive } = studio.schema[analysis];
    const declared = settings.find((d) => d.name === name);
    $(id).value = name in interactive ? interactive[name] : declared.default;
    $(id).title = `${declared.help} (${analysis} setting ${name}: ${declared.range}; the scene's default ${declared.default})`;
  }
}

async function start() {
  wire();
  requestAnimationFrame(frame);
  try {
    applySchema(await getJson("/api/schema"));
    studio.models = await getJson("/api/models");
  } catch (e) {
    say(`cannot list the models: ${e.message}`);
    return;
  }
  $("model").innerHTML = studio.models.map((m) => `<option value="${m.name}">${m.name}</option>`).join("");
  // The view in the address (`/?model=four_bar&…`, or `#four_bar`).
  const address = new URLSearchParams(location.search);
  const wanted = address.get("model") || location.hash.slice(1);
  const first = studio.models.find((m) => m.name === wanted) || studio.models.find((m) => m.name === "kapitza") || studio.models[0];
  await chooseModel(first.name, first.name === wanted ? address : undefined);
}

start();
