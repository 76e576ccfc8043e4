// The page of `pspslam view`: fills the side panel from /api/stats, then draws the map, the
// keyframes, the trajectory and the aligned ground truth with three.js.
import * as THREE from 'three';
import { OrbitControls } from '/vendor/three/examples/jsm/controls/OrbitControls.js';

async function getJson(path) {
  const response = await fetch(path);
  if (!response.ok) throw new Error(`${path}: HTTP ${response.status}`);
  return response.json();
}

function setText(id, text) {
  document.getElementById(id).textContent = text;
}

function fillPanel(stats) {
  const ate = stats.ate_refined ?? stats.ate;
  setText('sequence', stats.sequence ?? '');
  setText('frames', stats.frames ?? '–');
  setText('lost', stats.lost_frames ?? '–');
  setText('fps', stats.fps !== undefined ? stats.fps.toFixed(1) : '–');
  setText('ate', ate ? ate.rmse.toFixed(4) : '–');
  setText('keyframes', stats.map?.keyframes ?? '–');
  setText('points', stats.map?.map_points ?? '–');
}

function lineThrough(positions, color) {
  const geometry = new THREE.BufferGeometry().setFromPoints(positions);
  return new THREE.Line(geometry, new THREE.LineBasicMaterial({ color }));
}

function poseMatrix(pose) {
  const [x, y, z] = pose.p;
  const [qx, qy, qz, qw] = pose.q;
  return new THREE.Matrix4().compose(new THREE.Vector3(x, y, z),
                                     new THREE.Quaternion(qx, qy, qz, qw),
                                     new THREE.Vector3(1, 1, 1));
}

// One small pyramid per keyframe, all in one LineSegments (one draw call): camera centre to the
// four corners of an image plane at `depth`, in the camera's x-right, y-down, z-forward frame.
function frusta(keyframes, depth) {
  const w = depth * 0.6, h = depth * 0.45;
  const corners = [[-w, -h], [w, -h], [w, h], [-w, h]].map(([x, y]) => new THREE.Vector3(x, y, depth));
  const points = [];
  for (const pose of keyframes) {
    const m = poseMatrix(pose);
    const centre = new THREE.Vector3().applyMatrix4(m);
    const world = corners.map((c) => c.clone().applyMatrix4(m));
    for (let i = 0; i < 4; ++i) points.push(centre, world[i], world[i], world[(i + 1) % 4]);
  }
  const geometry = new THREE.BufferGeometry().setFromPoints(points);
  return new THREE.LineSegments(geometry, new THREE.LineBasicMaterial({ color: 0xd0d0d0 }));
}

function mapPoints(map) {
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.Float32BufferAttribute(map.positions, 3));
  geometry.setAttribute('color', new THREE.Uint8BufferAttribute(map.colors, 3, true));
  return new THREE.Points(geometry, new THREE.PointsMaterial({ size: 0.03, vertexColors: true }));
}

function drawScene(trajectory, map, truth) {
  const container = document.getElementById('scene');
  const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
  renderer.setPixelRatio(window.devicePixelRatio);
  renderer.setSize(container.clientWidth, container.clientHeight);
  renderer.setClearColor(0x1b1d22);
  container.appendChild(renderer.domElement);

  const scene = new THREE.Scene();
  // SLAM's world is the first camera's frame (y down, z forward); turn it so y points up.
  const world = new THREE.Group();
  world.rotation.x = Math.PI;
  scene.add(world);

  const estimate = trajectory.refined.length ? trajectory.refined : trajectory.online;
  const path = estimate.map((pose) => new THREE.Vector3(...pose.p));
  if (map.positions.length) world.add(mapPoints(map));
  if (path.length) world.add(lineThrough(path, 0xe8a33d));
  if (truth.positions.length)
    world.add(lineThrough(truth.positions.map((p) => new THREE.Vector3(...p)), 0x3db4e8));
  world.add(frusta(trajectory.keyframes, 0.05));
  world.add(new THREE.AxesHelper(0.3));

  // Frame the trajectory with room around it: the map's stray far points would shrink the view.
  const box = new THREE.Box3().setFromPoints(path.length ? path : [new THREE.Vector3()]);
  world.updateMatrixWorld();
  box.applyMatrix4(world.matrixWorld);
  const centre = box.getCenter(new THREE.Vector3());
  const size = Math.max(box.getSize(new THREE.Vector3()).length(), 1.5);
  const camera = new THREE.PerspectiveCamera(50, container.clientWidth / container.clientHeight,
                                             0.01, 1000);
  camera.position.copy(centre).add(new THREE.Vector3(size * 0.3, size * 0.45, size * 0.6));
  const controls = new OrbitControls(camera, renderer.domElement);
  controls.target.copy(centre);
  controls.update();

  window.addEventListener('resize', () => {
    camera.aspect = container.clientWidth / container.clientHeight;
    camera.updateProjectionMatrix();
    renderer.setSize(container.clientWidth, container.clientHeight);
  });
  renderer.setAnimationLoop(() => {
    controls.update();
    renderer.render(scene, camera);
  });
}

async function main() {
  const status = document.getElementById('status');
  try {
    // The panel first: it needs no WebGL, so it shows even where the 3D view cannot.
    fillPanel(await getJson('/api/stats'));
    const [trajectory, map, truth] = await Promise.all(
        [getJson('/api/trajectory'), getJson('/api/map'), getJson('/api/groundtruth')]);
    status.textContent = `${trajectory.online.length} poses, ${trajectory.keyframes.length} ` +
                         `keyframes, ${map.positions.length / 3} map points` +
                         (truth.positions.length ? `, ground truth: ${truth.file}` : '');
    drawScene(trajectory, map, truth);
    document.body.dataset.ready = 'true';
  } catch (error) {
    status.textContent = `error: ${error.message}`;
    document.body.dataset.ready = 'error';
  }
}

main();
