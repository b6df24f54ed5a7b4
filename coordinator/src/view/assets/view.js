// Shoal's live view: applies the server's messages (see coordinator/src/view/message.rs) to one
// state object and draws it a few times a second. `window.shoalView` is that state, and its
// `summary()` reads back what is drawn (for tests and the curious).
"use strict";

const NS = "http://www.w3.org/2000/svg";
const TRACK_POINTS = 4000;   // per vehicle; past it every other point is dropped
const EVENTS = 500;          // kept, newest last
const DRAW_MS = 200;         // redraw at most this often
const COLOURS = ["#1f77b4", "#2ca02c", "#d62728", "#9467bd", "#ff7f0e", "#17becf", "#8c564b",
  "#e377c2", "#7f7f7f", "#bcbd22"];

const S = {
  mode: null,          // "live" or "replay"
  connected: false,
  connections: 0,      // WebSocket connections opened so far (a reconnect adds one)
  caughtUp: false,
  scene: null,
  t_s: null,           // mission clock: the latest time seen
  revision: null,
  plans: {},           // vehicle -> [[t, x, y, z], ...]
  vehicles: {},        // vehicle -> { fix: telemetry state, track: [[x, y, z], ...] }
  order: [],           // vehicle ids, scenario order first
  obstacles: [],       // scene obstacles, then published ones (published: true)
  status: null,
  predicted: null,
  events: [],
  end: null,
  log: [],             // replay: every message of the log
  applied: 0,          // replay: messages of the log applied so far
};
window.shoalView = S;

function reset() {
  Object.assign(S, { caughtUp: false, scene: null, t_s: null, revision: null, plans: {},
    vehicles: {}, order: [], obstacles: [], status: null, predicted: null, events: [], end: null });
  dirty.scene = dirty.live = true;
}

function vehicle(id) {
  if (!S.vehicles[id]) {
    S.vehicles[id] = { fix: null, track: [] };
    if (!S.order.includes(id)) S.order.push(id);
  }
  return S.vehicles[id];
}

function clock(t) {
  if (typeof t === "number" && isFinite(t) && (S.t_s === null || t > S.t_s)) S.t_s = t;
}

// Applies one message to the state.
function apply(m) {
  switch (m.kind) {
    case "hello": S.mode = m.mode; break;
    case "reset": reset(); break;
    case "scene": {
      const caughtUp = S.caughtUp;   // a mission starting while the page watches
      reset();
      S.caughtUp = caughtUp;
      S.scene = m;
      S.obstacles = (m.obstacles || []).map(o => Object.assign({ published: false }, o));
      m.vehicles.forEach(vehicle);
      break;
    }
    case "plan":
      S.revision = m.plan.revision;
      for (const [id, samples] of m.plan.trajectories) { S.plans[id] = samples; vehicle(id); }
      break;
    case "telemetry": {
      const t = m.telemetry;
      const v = vehicle(t.vehicle);
      v.fix = t.state;
      v.seq = t.seq;
      v.track.push(t.state.position);
      if (v.track.length > TRACK_POINTS) v.track = v.track.filter((_, i, a) => i % 2 === 0 || i === a.length - 1);
      clock(t.state.t_s);
      break;
    }
    case "event":
      S.events.push(m.event);
      if (S.events.length > EVENTS) S.events.shift();
      clock(m.event.t_s);
      dirty.events = true;
      break;
    case "obstacle":
      S.obstacles = S.obstacles.filter(o => o.id !== m.obstacle.id);
      S.obstacles.push(Object.assign({}, m.obstacle, { published: true }));
      dirty.scene = true;
      break;
    case "status":
      S.status = m.status;
      S.predicted = m.predicted;
      clock(m.status.t_s);
      break;
    case "end": S.end = m.figures; break;
    case "caught_up": S.caughtUp = true; break;
  }
  dirty.live = true;
}

// ---- Replay: the whole log, played with a slider ----

function messageTime(m, last) {
  if (m.kind === "telemetry") return m.telemetry.state.t_s;
  if (m.kind === "event") return m.event.t_s;
  if (m.kind === "status") return m.status.t_s;
  return last;
}

function replayReceived(batch) {
  for (const m of batch) {
    if (m.kind === "hello" || m.kind === "reset") { apply(m); S.log = []; continue; }
    if (m.kind === "caught_up") { replayReady(); continue; }
    S.log.push(m);
  }
}

function replayReady() {
  let last = 0;
  for (const m of S.log) { last = messageTime(m, last); m.at = last; }
  const slider = document.getElementById("slider");
  slider.min = S.log.length ? Math.floor(S.log[0].at) : 0;
  slider.max = Math.ceil(last);
  slider.value = slider.max;
  document.getElementById("replay").hidden = false;
  replaySeek(Number(slider.value));
  S.caughtUp = true;
}

function replaySeek(t) {
  if (S.applied > 0 && S.log[S.applied - 1].at > t) { reset(); S.applied = 0; }
  while (S.applied < S.log.length && S.log[S.applied].at <= t) apply(S.log[S.applied++]);
  S.t_s = t;
  S.caughtUp = true;
  document.getElementById("replay-time").textContent = `t = ${t.toFixed(0)} s`;
  dirty.scene = dirty.live = dirty.events = true;
}

let playing = null;
function replayToggle() {
  const button = document.getElementById("play");
  const slider = document.getElementById("slider");
  if (playing) { clearInterval(playing); playing = null; button.textContent = "Play"; return; }
  if (Number(slider.value) >= Number(slider.max)) slider.value = slider.min;
  button.textContent = "Pause";
  const rate = S.scene ? S.scene.time_scale : 10;   // as fast as the mission ran
  let wall = performance.now();
  playing = setInterval(() => {
    const now = performance.now();
    const t = Math.min(Number(slider.max), Number(slider.value) + rate * (now - wall) / 1000);
    wall = now;
    slider.value = t;
    replaySeek(t);
    if (t >= Number(slider.max)) replayToggle();
  }, 100);
}

// ---- Connection ----

function connect() {
  const scheme = location.protocol === "https:" ? "wss:" : "ws:";
  const ws = new WebSocket(`${scheme}//${location.host}/ws`);
  S.socket = ws;
  ws.onopen = () => { S.connected = true; S.connections += 1; dirty.live = true; };
  ws.onmessage = e => {
    let batch;
    try { batch = JSON.parse(e.data); } catch (_) { return; }
    if (!Array.isArray(batch)) return;
    if (S.mode === "replay" || (batch[0] && batch[0].kind === "hello" && batch[0].mode === "replay")) {
      S.mode = "replay";
      replayReceived(batch);
    } else {
      batch.forEach(apply);
    }
  };
  ws.onclose = () => {
    S.connected = false;
    dirty.live = true;
    setTimeout(connect, 1000);
  };
}

// ---- Drawing ----

const dirty = { scene: true, live: true, events: true };

function el(name, attrs, parent) {
  const e = document.createElementNS(NS, name);
  for (const k in attrs) e.setAttribute(k, attrs[k]);
  if (parent) parent.appendChild(e);
  return e;
}

function colour(id) {
  const i = S.order.indexOf(id);
  return COLOURS[(i < 0 ? 0 : i) % COLOURS.length];
}

// The box drawn: the scene's bounds, else what is known so far.
function frame() {
  if (S.scene && S.scene.bounds) return S.scene.bounds;
  const pts = [];
  for (const id in S.plans) S.plans[id].forEach(s => pts.push([s[1], s[2], s[3]]));
  for (const id in S.vehicles) if (S.vehicles[id].fix) pts.push(S.vehicles[id].fix.position);
  if (!pts.length) return { min: [0, 0, 0], max: [1000, 1000, 1000] };
  const min = [0, 1, 2].map(k => Math.min(...pts.map(p => p[k])) - 50);
  const max = [0, 1, 2].map(k => Math.max(...pts.map(p => p[k])) + 50);
  return { min, max };
}

// A view: which axes it draws (x and y or x and z), screen y up.
const VIEWS = { top: [0, 1], side: [0, 2] };

function layers(svg) {
  if (!svg.statics) {
    svg.statics = el("g", { class: "static" }, svg);
    svg.dynamic = el("g", { class: "dynamic" }, svg);
  }
  return svg;
}

function drawStatic(name) {
  const [a, b] = VIEWS[name];
  const svg = layers(document.getElementById(name));
  const f = frame();
  const w = f.max[a] - f.min[a], h = f.max[b] - f.min[b];
  const pad = 0.03 * Math.max(w, h);
  svg.setAttribute("viewBox", `${f.min[a] - pad} ${-f.max[b] - pad} ${w + 2 * pad} ${h + 2 * pad}`);
  svg.unit = Math.max(w, h) / 100;
  const g = svg.statics;
  g.replaceChildren();
  const sea = S.scene && S.scene.seabed;
  if (sea && name === "top") drawSeabedTop(g, sea);
  if (sea && name === "side") {
    const pts = sea.xs.map((x, i) => `${x},${-sea.profile[i]}`);
    pts.push(`${sea.xs[sea.xs.length - 1]},${-f.min[2]}`, `${sea.xs[0]},${-f.min[2]}`);
    el("polygon", { class: "profile", points: pts.join(" ") }, g);
  }
  if (S.scene && name === "top") {
    for (const hz of S.scene.hazards || []) el("circle", { class: "hazard", cx: hz.centre[0], cy: -hz.centre[1], r: hz.radius_m }, g);
  }
  el("rect", { class: "bounds", x: f.min[a], y: -f.max[b], width: w, height: h }, g);
  for (const o of S.obstacles) {
    const cls = `obstacle ${o.kind}${o.published ? " published" : ""}`;
    const c = el("circle", { class: cls, cx: o.centre[a], cy: -o.centre[b], r: o.radius_m, "data-obstacle": o.id, "data-published": o.published }, g);
    el("title", {}, c).textContent = `${o.id} (${o.kind}${o.published ? ", published" : ""}) r ${o.radius_m} m`;
    el("circle", { class: "inflation", cx: o.centre[a], cy: -o.centre[b], r: o.radius_m + o.inflation_m }, g);
  }
}

function drawSeabedTop(g, sea) {
  let lo = Infinity, hi = -Infinity;
  sea.z.forEach(row => row.forEach(z => { lo = Math.min(lo, z); hi = Math.max(hi, z); }));
  const span = hi - lo || 1;
  const dx = (sea.xs[1] - sea.xs[0]) || 1, dy = (sea.ys[1] - sea.ys[0]) || 1;
  sea.z.forEach((row, j) => row.forEach((z, i) => {
    const k = (z - lo) / span;   // 0 deep .. 1 high
    const shade = `rgb(${Math.round(150 + 80 * k)},${Math.round(170 + 50 * k)},${Math.round(200 - 60 * k)})`;
    el("rect", { class: "seabed", x: sea.xs[i] - dx / 2, y: -sea.ys[j] - dy / 2, width: dx, height: dy, fill: shade }, g);
  }));
}

function standing(id) {
  const row = S.status && S.status.vehicles.find(r => r.vehicle === id);
  const fix = S.vehicles[id] && S.vehicles[id].fix;
  const status = fix ? fix.status : null;
  return { lost: !!(row && row.lost), held: status === "holding", fault: status === "fault" };
}

function drawDynamic(name) {
  const [a, b] = VIEWS[name];
  const svg = layers(document.getElementById(name));
  const g = svg.dynamic;
  const u = svg.unit || 10;
  g.replaceChildren();
  for (const id of S.order) {
    const plan = S.plans[id];
    if (plan) el("polyline", { class: "plan", stroke: colour(id), points: plan.map(s => `${s[1 + a]},${-s[1 + b]}`).join(" ") }, g);
  }
  for (const id of S.order) {
    const v = S.vehicles[id];
    if (v.track.length > 1) el("polyline", { class: "track", stroke: colour(id), points: v.track.map(p => `${p[a]},${-p[b]}`).join(" ") }, g);
  }
  const p = S.predicted;
  if (p) {
    const cls = p.conflict ? " conflict" : "";
    const [pa, pb] = p.places;
    el("line", { class: "predicted" + cls, x1: pa[a], y1: -pa[b], x2: pb[a], y2: -pb[b], "data-predicted": p.vehicles.join(" "), "data-conflict": p.conflict }, g);
    for (const q of p.places) el("circle", { class: "predicted-mark" + cls, cx: q[a], cy: -q[b], r: 1.2 * u }, g);
    const t = el("text", { class: "label", x: (pa[a] + pb[a]) / 2 + u, y: -(pa[b] + pb[b]) / 2 - u, "font-size": 2.2 * u }, g);
    t.textContent = `${p.min_distance_m.toFixed(0)} m at t ${p.at_s.toFixed(0)} s`;
  }
  for (const id of S.order) {
    const v = S.vehicles[id];
    if (!v.fix) continue;
    const pos = v.fix.position;
    const st = standing(id);
    const cls = ["vehicle", st.lost ? "lost" : "", st.held ? "held" : "", st.fault ? "fault" : ""].join(" ").trim();
    const c = el("circle", { class: cls, fill: colour(id), cx: pos[a], cy: -pos[b], r: u, "data-vehicle": id,
      "data-x": pos[0], "data-y": pos[1], "data-z": pos[2], "data-t": v.fix.t_s, "data-seq": v.seq }, g);
    el("title", {}, c).textContent = `${id} ${v.fix.status}${st.lost ? " LOST" : ""}`;
    const label = el("text", { class: "label", x: pos[a] + 1.4 * u, y: -pos[b] - 1.4 * u, "font-size": 2.4 * u }, g);
    label.textContent = id + (st.lost ? " (lost)" : st.held ? " (held)" : st.fault ? " (fault)" : "");
  }
}

function fmt(x, digits, unit) {
  return typeof x === "number" && isFinite(x) ? `${x.toFixed(digits)}${unit}` : "–";
}

function drawTable() {
  const rows = document.getElementById("rows");
  rows.replaceChildren();
  for (const id of S.order) {
    const row = S.status && S.status.vehicles.find(r => r.vehicle === id);
    const fix = S.vehicles[id].fix;
    const pr = row && row.progress;
    const st = standing(id);
    const status = st.lost ? "lost" : fix ? fix.status : "not heard";
    const tr = document.createElement("tr");
    tr.className = st.lost ? "lost" : st.held ? "held" : st.fault ? "fault" : "";
    tr.dataset.vehicle = id;
    const cells = [id, status,
      pr ? `${pr.along_m.toFixed(0)} m (${(100 * pr.fraction).toFixed(0)} %)` : "–",
      fmt(pr && pr.cross_track_m, 1, " m"), fmt(pr && pr.lag_s, 0, " s"), fmt(pr && pr.eta_s, 0, " s"),
      fix ? `${(100 * fix.battery).toFixed(0)} %` : "–", row ? `rev ${row.revision}` : "–"];
    cells.forEach((text, i) => {
      const td = document.createElement("td");
      td.textContent = text;
      if (i === 1) td.className = "status";
      tr.appendChild(td);
    });
    rows.appendChild(tr);
  }
  const s = S.status;
  const sep = document.getElementById("separation");
  if (s) {
    const p = s.predicted;
    sep.textContent = `separation now ${fmt(s.current_min_separation_m, 0, " m")}` +
      (s.current_pair ? ` (${s.current_pair.join("–")})` : "") +
      `; closest predicted within ${s.horizon_s.toFixed(0)} s: ${p ? `${p.min_distance_m.toFixed(0)} m at t ${p.at_s.toFixed(0)} s` : "–"}` +
      `; d_min ${s.d_min_m.toFixed(0)} m`;
  } else sep.textContent = "separation: –";
}

function drawEvents() {
  const log = document.getElementById("log");
  log.replaceChildren();
  const shown = S.events.slice(-200).reverse();
  for (const e of shown) {
    const li = document.createElement("li");
    li.className = e.kind;
    li.textContent = `t ${e.t_s.toFixed(1)} s  ${e.kind}: ${e.detail}`;
    log.appendChild(li);
  }
  log.start = S.events.length;
}

function drawHeader() {
  document.getElementById("mission").textContent = S.scene ? `${S.scene.name || ""} · ${S.scene.mission}` :
    (S.caughtUp ? "no mission running (yet)" : "—");
  const c = document.getElementById("clock");
  c.dataset.t = S.t_s === null ? "" : S.t_s;
  c.textContent = S.t_s === null ? "t = – s" :
    `t = ${S.t_s.toFixed(0)} s` + (S.scene ? ` of ${S.scene.common_arrival_s.toFixed(0)} s · ×${S.scene.time_scale}` : "") +
    (S.end ? " · ended" : "");
  const conn = document.getElementById("connection");
  conn.className = S.connected ? "on" : "off";
  conn.textContent = S.mode === "replay" ? "replay" : S.connected ? "live" : "reconnecting…";
}

function draw() {
  if (dirty.scene) { drawStatic("top"); drawStatic("side"); dirty.scene = false; dirty.live = true; }
  if (dirty.live) { drawDynamic("top"); drawDynamic("side"); drawTable(); drawHeader(); dirty.live = false; }
  if (dirty.events) { drawEvents(); dirty.events = false; }
}

// What is drawn, read back from the page.
S.summary = function () {
  const top = document.getElementById("top");
  const drawn = [...top.querySelectorAll("[data-vehicle]")].map(e => ({
    id: e.dataset.vehicle, x: Number(e.dataset.x), y: Number(e.dataset.y), z: Number(e.dataset.z),
    t_s: Number(e.dataset.t), seq: Number(e.dataset.seq), cx: Number(e.getAttribute("cx")), cy: Number(e.getAttribute("cy")), class: e.getAttribute("class"),
  }));
  const obstacles = [...top.querySelectorAll("[data-obstacle]")].map(e => ({
    id: e.dataset.obstacle, published: e.dataset.published === "true", cx: Number(e.getAttribute("cx")), cy: Number(e.getAttribute("cy")), r: Number(e.getAttribute("r")),
  }));
  const line = top.querySelector("[data-predicted]");
  return {
    mode: S.mode, connected: S.connected, connections: S.connections, caughtUp: S.caughtUp,
    mission: S.scene && S.scene.mission, t_s: S.t_s, revision: S.revision, ended: !!S.end,
    events: S.events.length, rows: document.querySelectorAll("#rows tr").length,
    clock: document.getElementById("clock").textContent,
    vehicles: drawn, obstacles,
    predicted: line ? { vehicles: line.dataset.predicted.split(" "), conflict: line.dataset.conflict === "true",
      x1: Number(line.getAttribute("x1")), y1: Number(line.getAttribute("y1")), x2: Number(line.getAttribute("x2")), y2: Number(line.getAttribute("y2")) } : null,
    status_predicted: S.status && S.status.predicted,
  };
};
// Draws now (a test reading the page need not wait for the next tick).
S.draw = draw;

document.getElementById("play").addEventListener("click", replayToggle);
document.getElementById("slider").addEventListener("input", e => {
  if (playing) replayToggle();
  replaySeek(Number(e.target.value));
});
setInterval(draw, DRAW_MS);
connect();
