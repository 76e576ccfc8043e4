// three.js pieces shared by the page of a finished run (viewer.js) and the live page (live.js).
import * as THREE from 'three';
import { OrbitControls } from '/vendor/three/examples/jsm/controls/OrbitControls.js';

export function poseMatrix(pose) {
  const [x, y, z] = pose.p;
  const [qx, qy, qz, qw] = pose.q;
  return new THREE.Matrix4().compose(new THREE.Vector3(x, y, z),
                                     new THREE.Quaternion(qx, qy, qz, qw),
                                     new THREE.Vector3(1, 1, 1));
}

export function lineThrough(positions, color) {
  const geometry = new THREE.BufferGeometry().setFromPoints(positions);
  return new THREE.Line(geometry, new THREE.LineBasicMaterial({ color }));
}

// The segments of one small pyramid per pose: camera centre to the four corners of an image
// plane at `depth`, in the camera's x-right, y-down, z-forward frame.
export function frustumPoints(poses, depth) {
  const w = depth * 0.6, h = depth * 0.45;
  const corners = [[-w, -h], [w, -h], [w, h], [-w, h]].map(([x, y]) => new THREE.Vector3(x, y, depth));
  const points = [];
  for (const pose of poses) {
    const m = poseMatrix(pose);
    const centre = new THREE.Vector3().applyMatrix4(m);
    const world = corners.map((c) => c.clone().applyMatrix4(m));
    for (let i = 0; i < 4; ++i) points.push(centre, world[i], world[i], world[(i + 1) % 4]);
  }
  return points;
}

// All frusta in one LineSegments (one draw call).
export function frusta(poses, depth, color = 0xd0d0d0) {
  const geometry = new THREE.BufferGeometry().setFromPoints(frustumPoints(poses, depth));
  return new THREE.LineSegments(geometry, new THREE.LineBasicMaterial({ color }));
}

// Renderer, camera and orbit controls in `container`; SLAM's world is the first camera's frame
// (y down, z forward), so `world` is turned to have y up. Returns what the pages draw into.
export function makeView(container) {
  const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
  renderer.setPixelRatio(window.devicePixelRatio);
  renderer.setSize(container.clientWidth, container.clientHeight);
  renderer.setClearColor(0x1b1d22);
  container.appendChild(renderer.domElement);
  const scene = new THREE.Scene();
  const world = new THREE.Group();
  world.rotation.x = Math.PI;
  scene.add(world);
  const camera = new THREE.PerspectiveCamera(50, container.clientWidth / container.clientHeight,
                                             0.01, 1000);
  camera.position.set(1, 1.5, 2.5);
  const controls = new OrbitControls(camera, renderer.domElement);
  window.addEventListener('resize', () => {
    camera.aspect = container.clientWidth / container.clientHeight;
    camera.updateProjectionMatrix();
    renderer.setSize(container.clientWidth, container.clientHeight);
  });
  return { renderer, scene, world, camera, controls };
}

// Puts the orbit camera where it sees `points` (world positions after `world`'s turn).
export function frame(view, points) {
  const box = new THREE.Box3().setFromPoints(points.length ? points : [new THREE.Vector3()]);
  view.world.updateMatrixWorld();
  box.applyMatrix4(view.world.matrixWorld);
  const centre = box.getCenter(new THREE.Vector3());
  const size = Math.max(box.getSize(new THREE.Vector3()).length(), 1.5);
  view.camera.position.copy(centre).add(new THREE.Vector3(size * 0.3, size * 0.45, size * 0.6));
  view.controls.target.copy(centre);
  view.controls.update();
}
