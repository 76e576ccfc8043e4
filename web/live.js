// The live page of `pspslam run --viewer`: Server-Sent Events say when a new snapshot of the
// frame, the map or the run's state exists; the images and the map are fetched only then, and
// only the newest (a slow page skips snapshots, the run never waits for it). Counts the test
// reads are mirrored in data- attributes of <body>.
import * as THREE from 'three';
import { frustumPoints, lineThrough, makeView, poseMatrix } from '/scene.js';

const FATE_COLOURS = ['#00d200', '#ffd700', '#a03cff', '#00ffff'];
// Keyframe frusta by the atlas map they belong to (map id modulo the palette): map 0 keeps the
// single-map colour, the others stay clear of the other layers' colours.
const MAP_COLOURS = [0x8ab4ff, 0xd67cff, 0xf2e35c, 0xff8fc4, 0x7be3c3, 0xb0b0ff];
const mapColour = (id) => MAP_COLOURS[id % MAP_COLOURS.length];
const $ = (id) => document.getElementById(id);
const body = document.body;

// ---- the frame view -------------------------------------------------------------------------
let lastFrame = null;
let frameVersion = 0;
let imageBusy = false;

function loadImages(frame, version) {
  if (imageBusy) return;  // the newest is loaded when this one is done
  imageBusy = true;
  const done = () => {
    imageBusy = false;
    if (frameVersion !== version) loadImages(lastFrame, frameVersion);
  };
  const image = new Image();
  image.onload = () => {
    $('frame').src = image.src;
    // An empty src would fetch the page itself: no overlay, no attribute.
    for (const [id, present] of [['labels', frame.labels], ['regions', frame.regions]]) {
      if (present) $(id).src = `/api/live/${id}.png?v=${version}`;
      else $(id).removeAttribute('src');
    }
    drawMarks(frame);
    done();
  };
  image.onerror = done;
  image.src = `/api/live/frame.jpg?v=${version}`;
}

function drawMarks(frame) {
  const canvas = $('marks');
  const width = $('frame-view').clientWidth;
  const height = Math.round(width * frame.height / frame.width);
  canvas.width = width;
  canvas.height = height;
  const g = canvas.getContext('2d');
  g.clearRect(0, 0, width, height);
  const s = width / frame.width;
  $('labels').style.display = $('show-labels').checked && frame.labels ? 'block' : 'none';
  $('regions').style.display = $('show-regions').checked && frame.regions ? 'block' : 'none';
  if ($('show-search').checked) {
    g.strokeStyle = 'rgba(111,168,255,0.55)';
    g.lineWidth = 1;
    g.beginPath();
    frame.path.forEach(([x, y], i) => (i ? g.lineTo(x * s, y * s) : g.moveTo(x * s, y * s)));
    g.stroke();
    for (const [x, y, dynamic] of frame.tested) {
      if (dynamic) {
        g.fillStyle = '#ff3c28';
        g.fillRect(x * s - 2.5, y * s - 2.5, 5, 5);
      } else {
        g.strokeStyle = '#ffffff';
        g.strokeRect(x * s - 2.5, y * s - 2.5, 5, 5);
      }
    }
  }
  if ($('show-keypoints').checked) {
    g.lineWidth = 1.5;
    for (const [x, y, fate] of frame.keypoints) {
      g.strokeStyle = FATE_COLOURS[fate];
      g.beginPath();
      if (fate < 2) {
        g.arc(x * s, y * s, 2.5, 0, 2 * Math.PI);
      } else {  // dropped: a cross, so the picture reads without colour too
        g.moveTo(x * s - 3, y * s - 3); g.lineTo(x * s + 3, y * s + 3);
        g.moveTo(x * s + 3, y * s - 3); g.lineTo(x * s - 3, y * s + 3);
      }
      g.stroke();
    }
  }
}

const COUNTERS = [
  ['processed', 'frames processed'], ['lost', 'lost frames'], ['relocalisations', 'relocalisations'],
  ['dropped_by_feed', 'dropped by the feed'], ['keyframes', 'keyframes'], ['map_points', 'map points'],
  ['masked_keypoints', 'keypoints removed'], ['tested_points', 'points tested'],
  ['dynamic_points', 'geometry dynamic'], ['culled_map_points', 'map points culled'],
  ['frames_without_mask', 'frames without mask'], ['loops_closed', 'loops closed']];

function showFrame(frame, version) {
  lastFrame = frame;
  frameVersion = version;
  $('frame-index').textContent = frame.index;
  $('frame-total').textContent = frame.total ? ` / ${frame.total - 1}` : '';
  body.dataset.frame = frame.index;
  frame.fates.forEach((n, i) => { $(`fate-${i}`).textContent = frame.detail ? n : '–'; });
  // A real-time run does not pay the second extraction that finds them: the label overlay
  // shows the mask instead.
  if (frame.detail && !frame.masked_recorded) $('fate-2').textContent = 'not recorded (--realtime)';
  // Dynamic keypoints of the shown frame: dropped by the semantic mask or by geometry.
  const dynamic = frame.fates[2] + frame.fates[3];
  body.dataset.dynamicKeypoints = dynamic;
  body.dataset.dynamicSeen = Math.max(Number(body.dataset.dynamicSeen ?? 0), dynamic);
  $('fps').textContent = frame.fps ? frame.fps.toFixed(1) : '–';
  $('mask-age').textContent = frame.mask_age < 0 ? 'none' : `${frame.mask_age} fr`;
  for (const [key, ms] of Object.entries(frame.timing)) {
    const cell = $(`t-${key}`);
    if (cell) cell.textContent = `${ms.toFixed(1)} ms`;
  }
  $('counters').innerHTML = '';
  for (let i = 0; i < COUNTERS.length; i += 2) {
    const row = $('counters').insertRow();
    for (const [key, label] of COUNTERS.slice(i, i + 2)) {
      row.insertCell().outerHTML = `<th>${label}</th>`;
      row.insertCell().textContent = frame.counters[key];
    }
  }
  if (frame.pose) setCurrentCamera(frame.pose);
  loadImages(frame, version);
}

for (const id of ['show-labels', 'show-regions', 'show-keypoints', 'show-search'])
  $(id).addEventListener('change', () => lastFrame && drawMarks(lastFrame));

// ---- the map --------------------------------------------------------------------------------
const view = makeView($('scene'));
const layers = {
  points: new THREE.Points(new THREE.BufferGeometry(),
                           new THREE.PointsMaterial({ size: 0.02, color: 0xc8c8c8 })),
  keyframes: new THREE.Group(),  // one LineSegments per map of the atlas
  covisibility: new THREE.LineSegments(new THREE.BufferGeometry(),
                                       new THREE.LineBasicMaterial({ color: 0x3a9d54 })),
  trajectory: lineThrough([], 0xe8a33d),
  truth: lineThrough([], 0x3db4e8),
  camera: new THREE.LineSegments(new THREE.BufferGeometry(),
                                 new THREE.LineBasicMaterial({ color: 0xff4d4d })),
};
Object.values(layers).forEach((layer) => view.world.add(layer));
view.world.add(new THREE.AxesHelper(0.3));
let framed = false;
let currentPosition = null;

// three.js (r163+) fills an existing position buffer in place and cannot grow it, and the map
// grows: each update gets a new geometry.
function setPoints(layer, points) {
  layer.geometry.dispose();
  layer.geometry = new THREE.BufferGeometry().setFromPoints(points);
}

const keyframeMaterials = MAP_COLOURS.map((color) => new THREE.LineBasicMaterial({ color }));
function setKeyframes(poses, mapIds) {
  for (const child of layers.keyframes.children) child.geometry.dispose();
  layers.keyframes.clear();
  const posesByMap = {};
  poses.forEach((pose, i) => (posesByMap[mapIds[i]] ??= []).push(pose));
  for (const [id, mapPoses] of Object.entries(posesByMap)) {
    const geometry = new THREE.BufferGeometry().setFromPoints(frustumPoints(mapPoses, 0.08));
    layers.keyframes.add(
        new THREE.LineSegments(geometry, keyframeMaterials[Number(id) % MAP_COLOURS.length]));
  }
}

// The maps holding keyframes (id and keyframe count) and the merges so far. Maps are in
// different world frames until merged: the colours tell which frusta belong together.
function showAtlas(mapIds, merges) {
  const keyframesPerMap = {};
  for (const id of mapIds) keyframesPerMap[id] = (keyframesPerMap[id] ?? 0) + 1;
  const ids = Object.keys(keyframesPerMap).map(Number).sort((a, b) => a - b);
  $('maps').innerHTML = '';
  for (const id of ids) {
    const item = $('maps').appendChild(document.createElement('li'));
    const swatch = item.appendChild(document.createElement('span'));
    swatch.style.background = `#${mapColour(id).toString(16).padStart(6, '0')}`;
    item.append(`map ${id} `);
    item.appendChild(document.createElement('b')).textContent =
        `${keyframesPerMap[id]} keyframe${keyframesPerMap[id] === 1 ? '' : 's'}`;
  }
  $('merges').innerHTML = '';
  for (const merge of merges) {
    $('merges').appendChild(document.createElement('li')).textContent =
        `map ${merge.from} merged into map ${merge.into} at keyframe ${merge.current_keyframe}`;
  }
  body.dataset.maps = ids.length;
  body.dataset.merges = merges.length;
}

function setCurrentCamera(pose) {
  setPoints(layers.camera, frustumPoints([pose], 0.12));
  const position = new THREE.Vector3(...pose.p).applyMatrix4(view.world.matrixWorld);
  if ($('follow').checked && currentPosition) {
    // Keep the orbit camera's offset: the view moves with the SLAM camera.
    const delta = position.clone().sub(view.controls.target);
    view.camera.position.add(delta);
    view.controls.target.copy(position);
  }
  currentPosition = position;
  view.controls.update();
  body.dataset.orbitTarget = view.controls.target.toArray().map((v) => v.toFixed(4)).join(' ');
  requestRender();
}

let mapVersion = 0;
let mapBusy = false;
async function loadMap(version) {
  if (mapBusy) return;
  mapBusy = true;
  try {
    const response = await fetch(`/api/live/map?v=${version}`);
    if (response.ok) {
      showMap(await response.json());
      body.dataset.mapShown = version;
    }
  } catch {
    // The run ended and its server closed while this map was on its way: the last map shown
    // stays (the event stream's error handler says whether the run finished).
  } finally {
    mapBusy = false;
    if (mapVersion !== version) loadMap(mapVersion);
  }
}

function showMap(map) {
  layers.points.geometry.dispose();
  layers.points.geometry = new THREE.BufferGeometry();
  layers.points.geometry.setAttribute('position',
                                      new THREE.Float32BufferAttribute(map.positions, 3));
  setKeyframes(map.keyframes, map.keyframe_maps);
  const centres = map.keyframes.map((pose) => new THREE.Vector3(...pose.p));
  setPoints(layers.covisibility, map.edges.flatMap(([a, b]) => [centres[a], centres[b]]));
  setPoints(layers.trajectory, map.trajectory.map((p) => new THREE.Vector3(...p)));
  setPoints(layers.truth, map.truth.map((p) => new THREE.Vector3(...p)));
  $('ate').textContent = map.ate_rmse >= 0 ? `ATE ${(map.ate_rmse * 1000).toFixed(1)} mm` : '';
  $('map-points').textContent = map.positions.length / 3;
  $('map-keyframes').textContent = map.keyframes.length;
  body.dataset.mapPoints = map.positions.length / 3;
  body.dataset.keyframes = map.keyframes.length;
  body.dataset.covisibilityEdges = map.edges.length;
  showAtlas(map.keyframe_maps, map.merges);
  if (!framed && centres.length >= 2 && map.positions.length) {
    // Look from above and behind the first keyframe (SLAM's z forward is -z here) towards the
    // map's median point: the median ignores the few far points a bounding box would chase.
    framed = true;
    const median = [0, 1, 2].map((axis) => {
      const values = map.positions.filter((_, i) => i % 3 === axis).sort((a, b) => a - b);
      return values[values.length >> 1];
    });
    // Aimed between the first keyframe and the map's median point, so the cameras stay in view.
    const start = centres[0].clone().applyMatrix4(view.world.matrixWorld);
    const target = new THREE.Vector3(...median).applyMatrix4(view.world.matrixWorld).lerp(start, 0.45);
    const distance = Math.max(start.distanceTo(target), 0.5);
    view.camera.position.copy(start).add(new THREE.Vector3(0.22, 0.65, 0.9).multiplyScalar(distance));
    view.controls.target.copy(target);
    view.controls.update();
  }
  requestRender();
}

const visibility = () => {
  layers.covisibility.visible = $('show-covis').checked;
  layers.trajectory.visible = $('show-trajectory').checked;
  layers.truth.visible = $('show-truth').checked;
  requestRender();
};
for (const id of ['show-covis', 'show-trajectory', 'show-truth'])
  $(id).addEventListener('change', visibility);
view.world.updateMatrixWorld();
// Drawn on demand, not every display frame: on a machine without a GPU the browser renders
// WebGL in software, and a continuous loop would take a core from the SLAM run it shows.
let renderQueued = false;
function requestRender() {
  if (renderQueued) return;
  renderQueued = true;
  requestAnimationFrame(() => {
    renderQueued = false;
    view.renderer.render(view.scene, view.camera);
  });
}
view.controls.addEventListener('change', requestRender);
window.addEventListener('resize', requestRender);

// ---- state, controls and the event stream ---------------------------------------------------
function showState(state) {
  const label = state.ended ? 'finished' : state.waiting ? 'paused' : state.paused ? 'pausing' : 'running';
  $('run-state').textContent = label;
  body.dataset.runState = label;
  body.dataset.heldFrame = state.held_frame;
  const off = state.realtime || state.ended;
  $('pause').disabled = off || state.paused;
  $('resume').disabled = off || !state.paused;
  $('step').disabled = off;
  if (state.realtime)
    $('control-note').textContent = 'real-time run: pause is off (the frames keep coming from ' +
                                    'the source and would be dropped, not held)';
}

async function control(action) {
  try {
    const response = await fetch(`/api/${action}`, { method: 'POST' });
    if (!response.ok) $('control-note').textContent = (await response.json()).error;
  } catch {
    $('control-note').textContent = `${action}: no connection to the run`;
  }
}
for (const action of ['pause', 'resume', 'step'])
  $(action).addEventListener('click', () => control(action));

async function main() {
  const info = await (await fetch('/api/live/info')).json();
  $('title').textContent = info.title;
  const events = new EventSource('/api/live/events');
  events.onmessage = (message) => {
    const event = JSON.parse(message.data);
    showState(event.state);
    if (event.frame && event.state.frame_version !== frameVersion)
      showFrame(event.frame, event.state.frame_version);
    if (event.state.map_version && event.state.map_version !== mapVersion) {
      mapVersion = event.state.map_version;
      body.dataset.mapVersion = mapVersion;
      loadMap(mapVersion);
    }
    body.dataset.liveReady = 'true';
  };
  events.onerror = () => {
    // The run is over and its server gone (or not yet reachable): say so, the page stays.
    if (body.dataset.runState !== 'finished') $('status').textContent = 'no connection to the run';
    if (body.dataset.runState === 'finished') events.close();
  };
}

main().catch((error) => { $('status').textContent = `error: ${error.message}`; });
