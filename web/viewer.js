// taiga's web viewer (docs/viewer.md). Two sources of data:
// - a finished run (`taiga view`): /api/info (trajectory, keyframes, loops, scan times, health)
//   and the map as a level-of-detail octree (/api/nodes, /api/node/N), of which the page loads
//   only the nodes in view that are large on screen, within a point budget;
// - a live run (`taiga run --view`): the Foxglove WebSocket channels on the same port
//   (/taiga/pose, /taiga/scan, /taiga/keyframes, /taiga/health, /taiga/keyframe_poses,
//   /taiga/loops, /taiga/georef, /taiga/trees; docs/live.md): keyframes move where the mapping
//   graph puts them.
// The map frame is z-up, in metres; everything is drawn relative to the server's origin.
// window.taigaView holds counters for tests (tools/viewer-check).
import * as THREE from "three";
import { OrbitControls } from "/three/OrbitControls.js";

const state = (window.taigaView = {
  mode: null, ready: false, pointsShown: 0, nodesLoaded: 0, nodesShown: 0, loading: 0,
  poses: 0, keyframes: 0, scans: 0, messages: 0, frames: 0, graphUpdates: 0, loops: 0, georef: 0,
  trees: 0,
});

// ---- scene ----------------------------------------------------------------------------------
const canvas = document.getElementById("view");
const renderer = new THREE.WebGLRenderer({ canvas, preserveDrawingBuffer: true });
renderer.setPixelRatio(window.devicePixelRatio);
const scene = new THREE.Scene();
scene.background = new THREE.Color(0x10161c);
const camera = new THREE.PerspectiveCamera(60, 1, 0.1, 50000);
camera.up.set(0, 0, 1);
const controls = new OrbitControls(camera, canvas);
const mapGroup = new THREE.Group();
scene.add(mapGroup);
const pointMaterial = new THREE.PointsMaterial({ size: 2, vertexColors: true, sizeAttenuation: false });

let dirty = true;
function requestRender() { dirty = true; }
controls.addEventListener("change", () => { requestRender(); scheduleLod(); });

function resize() {
  const w = canvas.clientWidth, h = canvas.clientHeight;
  renderer.setSize(w, h, false);
  camera.aspect = w / Math.max(h, 1);
  camera.updateProjectionMatrix();
  requestRender();
  scheduleLod();
}
window.addEventListener("resize", resize);

function frame() {
  if (dirty) {
    dirty = false;
    renderer.render(scene, camera);
    ++state.frames;
  }
  requestAnimationFrame(frame);
}

function lookAt(center, radius) {
  controls.target.copy(center);
  camera.position.copy(center).add(new THREE.Vector3(-0.45, -0.65, 0.9).multiplyScalar(radius));
  controls.update();
  requestRender();
}

// ---- colours --------------------------------------------------------------------------------
const colourSelect = document.getElementById("colour");
// A perceptually ordered ramp (dark blue, teal, green, yellow), sampled at 5 stops.
const ramp = [[0.18, 0.2, 0.55], [0.12, 0.5, 0.6], [0.2, 0.7, 0.45], [0.65, 0.82, 0.25], [0.99, 0.9, 0.2]];
function rampColour(u, out, i) {
  const x = Math.min(Math.max(u, 0), 1) * (ramp.length - 1);
  const k = Math.min(Math.floor(x), ramp.length - 2), f = x - k;
  for (let c = 0; c < 3; ++c) out[3 * i + c] = ramp[k][c] * (1 - f) + ramp[k + 1][c] * f;
}
const colourRange = { height: [0, 20], intensity: [0, 100] };
/// Colours for interleaved x, y, z, intensity; z_offset moves z into the map frame.
function colours(xyzi, z_offset = 0) {
  const n = xyzi.length / 4, out = new Float32Array(3 * n);
  const mode = colourSelect.value, [lo, hi] = colourRange[mode], span = Math.max(hi - lo, 1e-6);
  for (let i = 0; i < n; ++i) {
    const v = mode === "height" ? xyzi[4 * i + 2] + z_offset : xyzi[4 * i + 3];
    rampColour((v - lo) / span, out, i);
  }
  return out;
}
/// The 2nd and 98th percentile of a channel: a colour range that outliers do not squeeze.
function robustRange(xyzi, channel) {
  const values = [];
  for (let i = channel; i < xyzi.length; i += 4 * Math.max(1, Math.floor(xyzi.length / 40000))) values.push(xyzi[i]);
  values.sort((a, b) => a - b);
  if (values.length === 0) return [0, 1];
  return [values[Math.floor(0.02 * (values.length - 1))], values[Math.floor(0.98 * (values.length - 1))]];
}
function pointsObject(xyzi, z_offset = 0) {
  const geometry = new THREE.BufferGeometry();
  const buffer = new THREE.InterleavedBuffer(xyzi, 4);
  geometry.setAttribute("position", new THREE.InterleavedBufferAttribute(buffer, 3, 0));
  geometry.setAttribute("color", new THREE.BufferAttribute(colours(xyzi, z_offset), 3));
  geometry.computeBoundingSphere();
  const points = new THREE.Points(geometry, pointMaterial);
  points.userData = { xyzi, z_offset };
  return points;
}
function recolour() {
  mapGroup.traverse((o) => {
    if (o.isPoints && o.userData.xyzi) {
      o.geometry.setAttribute("color", new THREE.BufferAttribute(colours(o.userData.xyzi, o.userData.z_offset), 3));
    }
  });
  requestRender();
}
colourSelect.addEventListener("change", recolour);
document.getElementById("size").addEventListener("input", (e) => { pointMaterial.size = Number(e.target.value); requestRender(); });

// ---- trajectory, keyframes, loops -----------------------------------------------------------
function lineObject(colour, capacity) {
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute("position", new THREE.BufferAttribute(new Float32Array(3 * capacity), 3));
  geometry.setDrawRange(0, 0);
  return new THREE.Line(geometry, new THREE.LineBasicMaterial({ color: colour }));
}
const path = lineObject(0xff4f4f, 1024);
const keyframeGeometry = new THREE.BufferGeometry();
const keyframeDots = new THREE.Points(keyframeGeometry, new THREE.PointsMaterial({ color: 0xff9a3c, size: 5, sizeAttenuation: false }));
const loopLines = new THREE.LineSegments(new THREE.BufferGeometry(), new THREE.LineBasicMaterial({ color: 0xe05cff }));
const poseMarker = new THREE.AxesHelper(1.5);
poseMarker.visible = false;
// The walk is drawn over the canopy that would hide it.
for (const overlay of [path, keyframeDots, loopLines, poseMarker]) {
  overlay.renderOrder = 1;
  for (const material of [overlay.material].flat()) material.depthTest = false;
}
scene.add(path, keyframeDots, loopLines, poseMarker);
for (const [id, object] of [["show-path", path], ["show-keyframes", keyframeDots], ["show-loops", loopLines]])
  document.getElementById(id).addEventListener("change", (e) => { object.visible = e.target.checked; requestRender(); });

/// New positions for a geometry; its bounds too, which frustum culling cached when it was empty.
function setPositions(geometry, xyz) {
  geometry.setAttribute("position", new THREE.Float32BufferAttribute(xyz, 3));
  geometry.computeBoundingSphere();
}

// Trees (trees.csv of `taiga trees` or `mapping.trees`): each stem a cylinder of its DBH from the
// ground to 3 m (around breast height; a full-height column would hide the map), coloured by DBH.
const trees = new THREE.Group();
scene.add(trees);
document.getElementById("show-trees").addEventListener("change", (e) => { trees.visible = e.target.checked; requestRender(); });
function showTrees(rows) {
  for (const old of [...trees.children]) {
    trees.remove(old);
    old.geometry.dispose();
  }
  state.trees = 0;
  if (rows.length === 0) return;
  const stem = new THREE.CylinderGeometry(0.5, 0.5, 1, 12);
  stem.rotateX(Math.PI / 2);  // along z
  stem.translate(0, 0, 0.5);  // from its base
  const mesh = new THREE.InstancedMesh(stem, new THREE.MeshBasicMaterial(), rows.length);
  const maxDbh = Math.max(...rows.map((t) => t[3]));
  const matrix = new THREE.Matrix4(), colour = new Float32Array(3);
  rows.forEach(([x, y, z, dbh], i) => {
    matrix.makeScale(dbh, dbh, 3).setPosition(x, y, z ?? 0);
    mesh.setMatrixAt(i, matrix);
    rampColour(dbh / maxDbh, colour, 0);
    mesh.setColorAt(i, new THREE.Color(0.55 + 0.45 * colour[0], 0.35 + 0.3 * colour[1], 0.2));
  });
  mesh.computeBoundingSphere();
  trees.add(mesh);
  state.trees = rows.length;
}

/// Appends a point to a growing line, doubling its buffer when full.
function appendToLine(line, x, y, z) {
  let attribute = line.geometry.getAttribute("position");
  const n = line.geometry.drawRange.count;
  if (n === attribute.count) {
    const grown = new Float32Array(attribute.array.length * 2);
    grown.set(attribute.array);
    attribute = new THREE.BufferAttribute(grown, 3);
    line.geometry.setAttribute("position", attribute);
  }
  attribute.setXYZ(n, x, y, z);
  attribute.needsUpdate = true;
  line.geometry.setDrawRange(0, n + 1);
  line.geometry.computeBoundingSphere();
}

// ---- the panel ------------------------------------------------------------------------------
const chart = document.getElementById("chart");
const statusColours = { ok: "#6fd08c", degraded: "#f0c05a", lost: "#ff7a6b", "": "#9aa8b4" };
/// Time per scan as bars, coloured by status; the dashed line is the 100 ms scan period.
function drawChart(ms, status) {
  const g = chart.getContext("2d"), w = chart.width, h = chart.height;
  g.clearRect(0, 0, w, h);
  if (ms.length === 0) return;
  const top = Math.max(120, ...ms.slice(-2000));
  const step = Math.max(1, Math.ceil(ms.length / w));
  for (let x = 0; x * step < ms.length; ++x) {
    let worst = 0, worstStatus = "ok";
    for (let i = x * step; i < Math.min(ms.length, (x + 1) * step); ++i) {
      if (ms[i] > worst) worst = ms[i];
      if (status[i] && status[i] !== "ok") worstStatus = status[i];
    }
    g.fillStyle = statusColours[worstStatus] ?? statusColours[""];
    const bar = (worst / top) * (h - 4);
    g.fillRect(x * (w / Math.ceil(ms.length / step)), h - bar, Math.max(1, w / Math.ceil(ms.length / step)), bar);
  }
  g.strokeStyle = "#9aa8b4";
  g.setLineDash([4, 3]);
  const y = h - (100 / top) * (h - 4);
  g.beginPath(); g.moveTo(0, y); g.lineTo(w, y); g.stroke();
}
function median(values) {
  if (values.length === 0) return NaN;
  const sorted = [...values].sort((a, b) => a - b);
  return sorted[Math.floor((sorted.length - 1) / 2)];
}
function setText(id, html) { document.getElementById(id).innerHTML = html; }
function showPoints() {
  setText("points", `${state.pointsShown.toLocaleString("en")} points shown` +
    (state.mode === "run" ? ` (${state.nodesShown} of ${lod.nodes.length} nodes)` : ` (${state.keyframes} keyframes)`));
}

// ---- a finished run: levels of detail -------------------------------------------------------
const budgetSelect = document.getElementById("budget");
const lod = { nodes: [], loaded: new Map(), wanted: [], timer: null };
/// A node's subsample is one point per 1/64 of its edge: its children are loaded while that
/// spacing covers more than 1.5 pixels, i.e. while a child's edge is over 48 pixels on screen.
const kRefinePixels = 48;
const kMaxFetches = 4;

function scheduleLod() {
  if (state.mode !== "run" || lod.timer) return;
  lod.timer = setTimeout(() => { lod.timer = null; updateLod(); }, 60);
}

/// The nodes to show: from the root, children in view whose projected edge is large, the
/// largest first, until the point budget is spent.
function chooseNodes() {
  camera.updateMatrixWorld();
  const frustum = new THREE.Frustum().setFromProjectionMatrix(
    new THREE.Matrix4().multiplyMatrices(camera.projectionMatrix, camera.matrixWorldInverse));
  const pixelsPerRadian = canvas.clientHeight / (2 * Math.tan((camera.fov * Math.PI) / 360));
  const budget = Number(budgetSelect.value);
  const chosen = [], queue = [{ id: 0, size: Infinity }];
  let total = 0;
  while (queue.length > 0) {
    queue.sort((a, b) => a.size - b.size);
    const { id } = queue.pop();
    const node = lod.nodes[id];
    if (total + node.points > budget && chosen.length > 0) continue;
    chosen.push(id);
    total += node.points;
    for (const c of node.children) {
      const child = lod.nodes[c];
      if (!frustum.intersectsBox(child.box)) continue;
      const distance = Math.max(child.center.distanceTo(camera.position) - child.radius, camera.near);
      const size = (child.edge / distance) * pixelsPerRadian;
      if (size > kRefinePixels) queue.push({ id: c, size });
    }
  }
  return chosen;
}

function updateLod() {
  lod.wanted = chooseNodes();
  const wanted = new Set(lod.wanted);
  let shown = 0, nodesShown = 0;
  for (const [id, entry] of lod.loaded) {
    entry.object.visible = wanted.has(id);
    if (entry.object.visible) { shown += entry.points; ++nodesShown; entry.used = performance.now(); }
  }
  state.pointsShown = shown;
  state.nodesShown = nodesShown;
  // Least recently shown nodes go when twice the budget is held.
  let held = [...lod.loaded.values()].reduce((sum, e) => sum + e.points, 0);
  const evictable = [...lod.loaded.entries()].filter(([id]) => !wanted.has(id)).sort((a, b) => a[1].used - b[1].used);
  for (const [id, entry] of evictable) {
    if (held <= 2 * Number(budgetSelect.value)) break;
    mapGroup.remove(entry.object);
    entry.object.geometry.dispose();
    lod.loaded.delete(id);
    held -= entry.points;
  }
  state.nodesLoaded = lod.loaded.size;
  for (const id of lod.wanted) {
    if (state.loading >= kMaxFetches) break;
    if (!lod.loaded.has(id) && !lod.nodes[id].fetching) fetchNode(id);
  }
  showPoints();
  requestRender();
}

async function fetchNode(id) {
  const node = lod.nodes[id];
  node.fetching = true;
  ++state.loading;
  try {
    const response = await fetch(`/api/node/${id}`);
    if (!response.ok) throw new Error(`node ${id}: HTTP ${response.status}`);
    const xyzi = new Float32Array(await response.arrayBuffer());
    if (id === 0) {
      colourRange.height = robustRange(xyzi, 2);
      colourRange.intensity = [0, robustRange(xyzi, 3)[1]];
    }
    const object = pointsObject(xyzi);
    object.visible = false;
    mapGroup.add(object);
    lod.loaded.set(id, { object, points: xyzi.length / 4, used: performance.now() });
  } finally {
    node.fetching = false;
    --state.loading;
  }
  updateLod();
  if (id === 0) state.ready = true;
}

async function showRun(info) {
  setText("name", info.name);
  const summary = info.summary ?? {};
  if (summary.health) {
    const h = summary.health;
    setText("health", `verdict <b class="${h.verdict}">${h.verdict}</b>: ${h.scans_ok} ok, ` +
      `${h.scans_degraded} degraded, ${h.scans_lost} lost scans`);
  }
  const g = summary.georef;
  if (g?.sigma) {
    setText("georef", `georeferenced in EPSG:${g.epsg} (${g.method}, ${g.inliers} of ${g.fixes} GNSS fixes), ` +
      `1-sigma ${g.sigma.east_m.toFixed(2)} / ${g.sigma.north_m.toFixed(2)} m, ${g.sigma.yaw_deg.toFixed(1)} deg yaw`);
  }
  const ms = info.scans.ms, status = info.scans.status;
  state.scans = ms.length;
  chart.style.display = ms.length > 0 ? "" : "none";  // a cloud file has no scans
  if (ms.length > 0) {
    const sorted = [...ms].sort((a, b) => a - b);
    setText("timing", `time per scan: median ${median(ms).toFixed(1)} ms, ` +
      `p95 ${sorted[Math.floor(0.95 * (sorted.length - 1))].toFixed(1)} ms, max ${sorted[sorted.length - 1].toFixed(1)} ms` +
      (summary.realtime_factor ? `; ${Number(summary.realtime_factor).toFixed(1)}x real time` : ""));
    drawChart(ms, status);
  }
  for (const [, x, y, z] of info.trajectory) appendToLine(path, x, y, z);
  showTrees(info.trees ?? []);
  state.poses = info.trajectory.length;
  setPositions(keyframeGeometry, info.keyframes.flat());
  state.keyframes = info.keyframes.length;
  setPositions(loopLines.geometry, info.loops.flat(2));

  lod.nodes = await (await fetch("/api/nodes")).json();
  for (const node of lod.nodes) {
    node.box = new THREE.Box3(new THREE.Vector3(...node.min), new THREE.Vector3(...node.max));
    node.center = node.box.getCenter(new THREE.Vector3());
    node.edge = node.max[0] - node.min[0];
    node.radius = 0.5 * Math.sqrt(3) * node.edge;
  }
  // The camera looks at the walk (the map reaches far beyond it), or at the whole cloud.
  const view = lod.nodes[0].box.clone();
  if (info.trajectory.length > 1)
    view.setFromPoints(info.trajectory.map(([, x, y, z]) => new THREE.Vector3(x, y, z)));
  const sphere = view.getBoundingSphere(new THREE.Sphere());
  lookAt(sphere.center, Math.max(2.5 * sphere.radius, 30));
  updateLod();
}

// ---- a live run: the Foxglove channels ------------------------------------------------------
const live = { subscriptions: new Map(), keyframes: new Map(), keyframePoints: 0, graph: [],
               loops: [], scanObject: null, ms: [], status: [], zRange: null, t0: null };
const liveTopics = ["/taiga/pose", "/taiga/scan", "/taiga/keyframes", "/taiga/health",
                    "/taiga/keyframe_poses", "/taiga/loops", "/taiga/georef", "/taiga/trees"];
const decoder = new TextDecoder();

function decodeCloud(message) {
  const bytes = Uint8Array.from(atob(message.data), (c) => c.charCodeAt(0));
  const stride = message.point_stride / 4;
  const source = new Float32Array(bytes.buffer, 0, bytes.length / 4);
  if (stride === 4) return source;
  const n = bytes.length / message.point_stride, xyzi = new Float32Array(4 * n);
  for (let i = 0; i < n; ++i) for (let c = 0; c < 4; ++c) xyzi[4 * i + c] = source[stride * i + c];
  return xyzi;
}
function placed(object, pose) {
  const p = pose.position, q = pose.orientation;
  object.position.set(p.x, p.y, p.z);
  object.quaternion.set(q.x, q.y, q.z, q.w);
  return object;
}
/// A keyframe's pose: the mapping graph's when it has one (loop closures move it), else as
/// published.
function keyframePose(id, published) { return live.graph[id] ?? published; }

/// Keyframe dots and loop lines from the keyframes' current poses.
function drawGraph() {
  const at = [];
  for (const [id, object] of [...live.keyframes].sort((a, b) => a[0] - b[0])) {
    placed(object, keyframePose(id, object.userData.published));
    at.push(object.position.x, object.position.y, object.position.z);
  }
  setPositions(keyframeGeometry, at);
  const lines = [];
  for (const [a, b] of live.loops) {
    const pa = live.graph[a]?.position, pb = live.graph[b]?.position;
    if (pa && pb) lines.push(pa.x, pa.y, pa.z, pb.x, pb.y, pb.z);
  }
  setPositions(loopLines.geometry, lines);
}

function onKeyframe(message) {
  const xyzi = decodeCloud(message);
  if (!live.zRange) {
    colourRange.height = robustRange(xyzi, 2);
    colourRange.intensity = [0, robustRange(xyzi, 3)[1]];
    live.zRange = true;
  }
  // Heights are coloured in the map frame: the body frame's z shifted by the pose's height
  // (exact for a level body, which a forest walk nearly is).
  const object = pointsObject(xyzi, message.pose.position.z);
  object.userData.published = message.pose;
  mapGroup.add(object);
  live.keyframes.set(message.keyframe ?? live.keyframes.size, object);
  live.keyframePoints += xyzi.length / 4;
  // The oldest keyframes go when the budget is spent.
  while (live.keyframePoints > Number(budgetSelect.value) && live.keyframes.size > 1) {
    const [oldest, old] = live.keyframes.entries().next().value;
    mapGroup.remove(old);
    old.geometry.dispose();
    live.keyframes.delete(oldest);
    live.keyframePoints -= old.userData.xyzi.length / 4;
  }
  ++state.keyframes;
  drawGraph();
}

function onLiveMessage(topic, message) {
  ++state.messages;
  if (topic === "/taiga/pose") {
    const p = message.pose.position;
    appendToLine(path, p.x, p.y, p.z);
    placed(poseMarker, message.pose).visible = true;
    if (state.poses++ === 0) lookAt(new THREE.Vector3(p.x, p.y, p.z), 25);
  } else if (topic === "/taiga/keyframes") {
    onKeyframe(message);
  } else if (topic === "/taiga/keyframe_poses") {
    live.graph = message.poses;
    ++state.graphUpdates;
    drawGraph();
  } else if (topic === "/taiga/loops") {
    live.loops.push([message.keyframe, message.candidate]);
    state.loops = live.loops.length;
    drawGraph();
  } else if (topic === "/taiga/trees") {
    showTrees(message.trees);
  } else if (topic === "/taiga/georef") {
    ++state.georef;
    const [e, n] = message.sigma;
    setText("georef", `EPSG:${message.epsg} E ${message.easting_m.toFixed(1)} N ${message.northing_m.toFixed(1)} m, ` +
      `1-sigma ${e.toFixed(2)} / ${n.toFixed(2)} m (${message.fixes} GNSS fixes)`);
  } else if (topic === "/taiga/scan") {
    if (live.scanObject) { scene.remove(live.scanObject); live.scanObject.geometry.dispose(); }
    const xyzi = decodeCloud(message);
    const geometry = new THREE.BufferGeometry();
    geometry.setAttribute("position", new THREE.InterleavedBufferAttribute(new THREE.InterleavedBuffer(xyzi, 4), 3, 0));
    live.scanObject = placed(new THREE.Points(geometry, new THREE.PointsMaterial({ color: 0xffffff, size: 2, sizeAttenuation: false })), message.pose);
    scene.add(live.scanObject);
  } else if (topic === "/taiga/health") {
    ++state.scans;
    live.ms.push(message.processing_ms);
    live.status.push(message.status);
    if (live.ms.length > 3000) { live.ms.shift(); live.status.shift(); }
    live.t0 ??= message.t_s;
    setText("health", `scan at ${(message.t_s - live.t0).toFixed(1)} s: <b class="${message.status}">${message.status}</b>` +
      (message.reason ? ` (${message.reason})` : ""));
    setText("timing", `time per scan: ${message.processing_ms.toFixed(1)} ms, median ${median(live.ms).toFixed(1)} ms`);
    if (state.scans % 5 === 0) drawChart(live.ms, live.status);
  }
  state.pointsShown = live.keyframePoints + (live.scanObject ? live.scanObject.geometry.getAttribute("position").count : 0);
  if (state.keyframes > 0 && state.poses > 0) state.ready = true;
  showPoints();
  requestRender();
}

function connectLive() {
  const socket = new WebSocket(`ws://${location.host}/`, ["foxglove.websocket.v1"]);
  socket.binaryType = "arraybuffer";
  socket.onopen = () => setText("name", `live: ws://${location.host}`);
  socket.onmessage = (event) => {
    if (typeof event.data === "string") {
      const message = JSON.parse(event.data);
      if (message.op !== "advertise") return;
      const subscriptions = [];
      for (const channel of message.channels) {
        if (!liveTopics.includes(channel.topic)) continue;
        const id = live.subscriptions.size + 1;
        live.subscriptions.set(id, channel.topic);
        subscriptions.push({ id, channelId: channel.id });
      }
      socket.send(JSON.stringify({ op: "subscribe", subscriptions }));
      return;
    }
    // Message Data: opcode 1, u32 subscription id, u64 time (ns), the message's JSON.
    const view = new DataView(event.data);
    if (view.getUint8(0) !== 1) return;
    const topic = live.subscriptions.get(view.getUint32(1, true));
    if (topic) onLiveMessage(topic, JSON.parse(decoder.decode(new Uint8Array(event.data, 13))));
  };
  socket.onclose = () => setText("name", `live: ws://${location.host} (the run ended)`);
}

// ---- start ----------------------------------------------------------------------------------
async function start() {
  resize();
  requestAnimationFrame(frame);
  const info = await (await fetch("/api/info")).json();
  state.mode = info.mode;
  if (info.mode === "live") {
    setText("name", "live: connecting");
    connectLive();
  } else {
    await showRun(info);
  }
}
start();
