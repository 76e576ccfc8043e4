// The page of `pspslam view`: fills the side panel from /api/stats, then draws the map, the
// keyframes, the trajectory and the aligned ground truth with three.js.
import * as THREE from 'three';
import { frame, frusta, lineThrough, makeView } from '/scene.js';

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

function mapPoints(map) {
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.Float32BufferAttribute(map.positions, 3));
  geometry.setAttribute('color', new THREE.Uint8BufferAttribute(map.colors, 3, true));
  return new THREE.Points(geometry, new THREE.PointsMaterial({ size: 0.03, vertexColors: true }));
}

function drawScene(trajectory, map, truth) {
  const view = makeView(document.getElementById('scene'));
  const estimate = trajectory.refined.length ? trajectory.refined : trajectory.online;
  const path = estimate.map((pose) => new THREE.Vector3(...pose.p));
  if (map.positions.length) view.world.add(mapPoints(map));
  if (path.length) view.world.add(lineThrough(path, 0xe8a33d));
  if (truth.positions.length)
    view.world.add(lineThrough(truth.positions.map((p) => new THREE.Vector3(...p)), 0x3db4e8));
  view.world.add(frusta(trajectory.keyframes, 0.05));
  view.world.add(new THREE.AxesHelper(0.3));
  // Frame the trajectory with room around it: the map's stray far points would shrink the view.
  frame(view, path);
  view.renderer.setAnimationLoop(() => {
    view.controls.update();
    view.renderer.render(view.scene, view.camera);
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
