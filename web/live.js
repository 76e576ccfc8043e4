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
// People by track id: hues a golden angle apart, so neighbouring ids differ clearly.
const personHue = (id) => (id * 137.508) % 360;
const personCss = (id) => `hsl(${personHue(id)}, 85%, 62%)`;
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
  drawPeopleIds(g, frame, s);
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

// Each person's id at the pixel her centre projects to (the server projects with the frame's
// pose and intrinsics); the count drawn is mirrored for the test.
function drawPeopleIds(g, frame, s) {
  let drawn = 0;
  if ($('show-people').checked) {
    g.font = 'bold 13px sans-serif';
    g.textAlign = 'center';
    g.textBaseline = 'middle';
    for (const person of frame.people) {
      if (!person.pixel) continue;
      const [x, y] = [person.pixel[0] * s, person.pixel[1] * s];
      if (x < 0 || y < 0 || x > g.canvas.width || y > g.canvas.height) continue;
      const text = `#${person.id}`;
      g.fillStyle = 'rgba(0,0,0,0.6)';
      g.fillRect(x - 14, y - 9, 28, 18);
      g.fillStyle = personCss(person.id);
      g.fillText(text, x, y);
      ++drawn;
    }
  }
  body.dataset.peopleLabels = drawn;
  body.dataset.peopleLabelsSeen = Math.max(Number(body.dataset.peopleLabelsSeen ?? 0), drawn);
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
  showPeople(frame.people);
  if (frame.pose) setCurrentCamera(frame.pose);
  loadImages(frame, version);
}

for (const id of ['show-labels', 'show-regions', 'show-keypoints', 'show-search', 'show-people'])
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
  people: new THREE.Group(),  // per person: a box of her extent and her recent track
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

// ---- people ---------------------------------------------------------------------------------
// Recent positions per track id, as the frame snapshots brought them (the page sees every
// snapshot, not every frame: the track is sampled at the viewer's interval).
const TRACK_LENGTH = 120;
const tracks = new Map();
const idsSeen = new Set();

function personObjects(person) {
  const colour = new THREE.Color().setHSL(personHue(person.id) / 360, 0.85, 0.62);
  const material = new THREE.LineBasicMaterial({ color: colour });
  // Upright in SLAM's world (y down): as tall as her extent, half as wide and deep.
  const size = Math.max(person.extent, 0.3);
  const box = new THREE.LineSegments(
      new THREE.EdgesGeometry(new THREE.BoxGeometry(size * 0.5, size, size * 0.5)), material);
  box.position.set(...person.p);
  box.userData.personId = person.id;
  const track = new THREE.Line(new THREE.BufferGeometry().setFromPoints(tracks.get(person.id)),
                               material);
  return [box, track];
}

function showPeople(people) {
  for (const child of layers.people.children) {
    child.geometry.dispose();
    child.material.dispose();  // shared by a box and its track: a second dispose does nothing
  }
  layers.people.clear();
  const current = new Set(people.map((person) => person.id));
  for (const id of [...tracks.keys()]) if (!current.has(id)) tracks.delete(id);
  for (const person of people) {
    const track = tracks.get(person.id) ?? [];
    track.push(new THREE.Vector3(...person.p));
    tracks.set(person.id, track.slice(-TRACK_LENGTH));
    layers.people.add(...personObjects(person));
    idsSeen.add(person.id);
  }
  const boxes = layers.people.children.filter((child) => child.userData.personId !== undefined);
  $('people-count').textContent = boxes.length;
  // Read from the three.js scene itself, so a test sees what is drawn, not what was received.
  let inScene = 0;
  view.scene.traverse((object) => { inScene += object.userData.personId !== undefined; });
  window.liveScene = { ...window.liveScene, people: inScene };
  body.dataset.people = boxes.length;
  body.dataset.peopleSeen = Math.max(Number(body.dataset.peopleSeen ?? 0), boxes.length);
  body.dataset.peopleIds = [...idsSeen].sort((a, b) => a - b).join(' ');
  requestRender();
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
  layers.people.visible = $('show-people').checked;
  requestRender();
};
for (const id of ['show-covis', 'show-trajectory', 'show-truth', 'show-people'])
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

// ---- the occupancy grid ---------------------------------------------------------------------
// Offered only when the run builds the map (--occupancy); otherwise the tooltip says how. While
// shown, the grid is asked for every few seconds (the server rebuilds it at most that often)
// and drawn as a textured plane on the floor (grid frame: x, y on the floor, z up).
const GRID_REFRESH_MS = 3000;
let gridMesh = null;
let gridVersion = 0;
let gridTimer = null;

function showOccupancyToggle(available) {
  $('show-occupancy').disabled = !available;
  $('occupancy-toggle').title = available
      ? 'the 2D occupancy grid at floor height'
      : 'start the run with --occupancy to build the occupancy map';
  body.dataset.occupancy = available ? 'available' : 'off';
}

function placeGrid(grid, texture) {
  const [w, h] = [grid.width * grid.resolution, grid.height * grid.resolution];
  const geometry = new THREE.PlaneGeometry(w, h);
  // The plane's centre in the grid frame, a millimetre above the floor so points on it show.
  geometry.translate(grid.origin[0] + w / 2, grid.origin[1] + h / 2, 0.001);
  const m = grid.T_world_grid;
  geometry.applyMatrix4(new THREE.Matrix4().set(...m));
  texture.magFilter = THREE.NearestFilter;
  texture.colorSpace = THREE.SRGBColorSpace;
  const material = new THREE.MeshBasicMaterial(
      { map: texture, transparent: true, side: THREE.DoubleSide, depthWrite: false });
  if (gridMesh) {
    view.world.remove(gridMesh);
    gridMesh.geometry.dispose();
    gridMesh.material.map.dispose();
    gridMesh.material.dispose();
  }
  gridMesh = new THREE.Mesh(geometry, material);
  gridMesh.userData.occupancyGrid = true;
  gridMesh.visible = $('show-occupancy').checked;
  view.world.add(gridMesh);
  let inScene = 0;
  view.scene.traverse((object) => { inScene += object.userData.occupancyGrid === true; });
  window.liveScene = { ...window.liveScene, grid: inScene };
  body.dataset.gridCells = `${grid.cells.unknown} ${grid.cells.free} ${grid.cells.occupied}`;
  body.dataset.gridVersion = grid.version;
  requestRender();
}

async function loadGrid() {
  try {
    const response = await fetch('/api/live/grid');
    if (!response.ok) return;  // no grid yet
    const grid = await response.json();
    if (grid.version === gridVersion) return;
    gridVersion = grid.version;
    const texture = await new THREE.TextureLoader().loadAsync(`/api/live/grid.png?v=${grid.version}`);
    placeGrid(grid, texture);
  } catch {
    // The run ended and its server closed: the last grid shown stays.
  }
}

$('show-occupancy').addEventListener('change', () => {
  const on = $('show-occupancy').checked;
  if (gridMesh) gridMesh.visible = on;
  clearInterval(gridTimer);
  if (on) {
    loadGrid();
    gridTimer = setInterval(loadGrid, GRID_REFRESH_MS);
  }
  requestRender();
});

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
  showOccupancyToggle(info.occupancy);
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
