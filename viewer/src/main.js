// The Tumble web viewer: plays a recorded run embedded in the page (a <script
// id="tumble-data" type="application/json"> written by `tumble export-html`), with an
// orbit camera, play/pause, speed, a time scrubber, body inspection by click, and live
// plots of the energies and of |L|. Everything is bundled into one file: no network.
import * as THREE from 'three';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';
import { energyPlot } from './plot.js';

const data = JSON.parse(document.getElementById('tumble-data').textContent);
const nFrames = data.times.length;
const nBodies = data.bodies.length;
const endTime = data.times[nFrames - 1];

const el = (tag, attrs = {}, parent = document.body) => {
  const e = document.createElement(tag);
  Object.assign(e, attrs);
  parent.appendChild(e);
  return e;
};

// --- the 3D view ---
const view = el('div', { id: 'view' });
const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
renderer.setPixelRatio(window.devicePixelRatio || 1);
view.appendChild(renderer.domElement);
const scene = new THREE.Scene();
scene.background = new THREE.Color(data.background);
const camera = new THREE.PerspectiveCamera(data.camera.fov_degrees, 1, data.scale / 1000, data.scale * 200);
camera.position.fromArray(data.camera.eye);
const controls = new OrbitControls(camera, renderer.domElement);
controls.target.fromArray(data.camera.target);
controls.update();
scene.add(new THREE.HemisphereLight(0xffffff, 0x8899aa, 1.4));
const sun = new THREE.DirectionalLight(0xffffff, 1.6);
sun.position.set(0.35, 1.0, 0.55);
scene.add(sun);

const meshes = data.bodies.map((body, i) => {
  if (body.plane) {
    const n = new THREE.Vector3().fromArray(body.plane.normal).normalize();
    const size = data.scale * 6;
    const group = new THREE.Group();
    const floor = new THREE.Mesh(
      new THREE.PlaneGeometry(size, size),
      new THREE.MeshLambertMaterial({ color: 0xd6dade, side: THREE.DoubleSide }),
    );
    const grid = new THREE.GridHelper(size, 24, 0xaab0b8, 0xaab0b8);
    grid.rotation.x = Math.PI / 2;
    grid.position.z = 1e-3 * data.scale;
    group.add(floor, grid);
    group.quaternion.setFromUnitVectors(new THREE.Vector3(0, 0, 1), n);
    group.position.copy(n.clone().multiplyScalar(body.plane.offset));
    const holder = new THREE.Group();
    holder.add(group);
    holder.userData.body = i;
    scene.add(holder);
    return holder;
  }
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.Float32BufferAttribute(body.mesh, 3));
  geometry.computeVertexNormals();
  const material = new THREE.MeshLambertMaterial({ color: body.color, side: THREE.DoubleSide });
  const mesh = new THREE.Mesh(geometry, material);
  mesh.userData.body = i;
  scene.add(mesh);
  return mesh;
});

// --- controls ---
const bar = el('div', { id: 'bar' });
const play = el('button', { id: 'play', textContent: 'Pause' }, bar);
const speed = el('select', { id: 'speed', title: 'playback speed' }, bar);
for (const s of [0.1, 0.25, 0.5, 1, 2, 4]) el('option', { value: s, textContent: `${s}×`, selected: s === 1 }, speed);
const scrub = el('input', { id: 'scrubber', type: 'range', min: 0, max: nFrames - 1, step: 1, value: 0 }, bar);
const clock = el('span', { id: 'clock' }, bar);
const title = el('div', { id: 'title', textContent: data.name || 'Tumble' });
title.title = data.description || '';
const info = el('pre', { id: 'info', textContent: 'Click a body to inspect it.' });
const plot = energyPlot(el('div', { id: 'plots' }), data);

let frame = 0;
let playing = true;
let time = 0;
let selected = -1;

const vec = (a, k) => a.slice(3 * k, 3 * k + 3);
const fmt = (v) => v.map((x) => (Math.abs(x) < 5e-5 ? 0 : x).toFixed(4).padStart(9)).join(' ');

function show(k) {
  frame = Math.max(0, Math.min(nFrames - 1, k));
  const p = data.frames.position[frame];
  const q = data.frames.orientation[frame];
  meshes.forEach((m, i) => {
    m.position.set(p[3 * i], p[3 * i + 1], p[3 * i + 2]);
    m.quaternion.set(q[4 * i], q[4 * i + 1], q[4 * i + 2], q[4 * i + 3]);
  });
  scrub.value = frame;
  clock.textContent = `t = ${data.times[frame].toFixed(2)} s / ${endTime.toFixed(2)} s`;
  plot.cursor(frame);
  if (selected >= 0) {
    const b = data.bodies[selected];
    info.textContent = [
      `${b.name} (${b.kind})`,
      `position  x  ${fmt(vec(p, selected))}  m`,
      `velocity  v  ${fmt(vec(data.frames.velocity[frame], selected))}  m/s`,
      `angular   ω  ${fmt(vec(data.frames.omega[frame], selected))}  rad/s`,
      `momentum  L  ${fmt(vec(data.frames.angular_momentum[frame], selected))}  kg·m²/s`,
    ].join('\n');
  }
}

function select(i) {
  if (selected >= 0 && meshes[selected].material) meshes[selected].material.emissive.setHex(0x000000);
  selected = i;
  if (i >= 0 && meshes[i].material) meshes[i].material.emissive.setHex(0x333333);
  if (i < 0) info.textContent = 'Click a body to inspect it.';
  show(frame);
}

play.onclick = () => {
  playing = !playing;
  if (playing && frame >= nFrames - 1) time = 0;
  play.textContent = playing ? 'Pause' : 'Play';
};
scrub.addEventListener('input', () => {
  playing = false;
  play.textContent = 'Play';
  time = data.times[+scrub.value];
  show(+scrub.value);
});

const ray = new THREE.Raycaster();
let down = null;
renderer.domElement.addEventListener('pointerdown', (e) => { down = [e.clientX, e.clientY]; });
renderer.domElement.addEventListener('pointerup', (e) => {
  // A drag turns the camera; only a click picks.
  if (!down || Math.hypot(e.clientX - down[0], e.clientY - down[1]) > 4) return;
  const r = renderer.domElement.getBoundingClientRect();
  ray.setFromCamera(new THREE.Vector2(((e.clientX - r.left) / r.width) * 2 - 1, -((e.clientY - r.top) / r.height) * 2 + 1), camera);
  const solids = meshes.filter((m) => m.isMesh);
  const hit = ray.intersectObjects(solids)[0];
  select(hit ? hit.object.userData.body : -1);
});

function resize() {
  const w = view.clientWidth;
  const h = view.clientHeight;
  renderer.setSize(w, h);
  camera.aspect = w / h;
  camera.updateProjectionMatrix();
}
window.addEventListener('resize', resize);
resize();

let last = performance.now();
function tick(now) {
  const dt = Math.min(0.1, (now - last) / 1000);
  last = now;
  if (playing) {
    time += dt * +speed.value;
    if (time > endTime) time = 0;
    show(Math.round(time * data.fps));
  }
  controls.update();
  renderer.render(scene, camera);
  requestAnimationFrame(tick);
}
show(0);
requestAnimationFrame(tick);

// For scripts and tests: the page's state and a few handles.
window.tumbleViewer = {
  ready: true,
  frames: nFrames,
  bodies: nBodies,
  frame: () => frame,
  pause: () => { playing = false; play.textContent = 'Play'; },
  select,
  info: () => info.textContent,
  render: () => renderer.render(scene, camera),
  // Where body i's origin is drawn, in CSS pixels from the canvas's top-left corner.
  screenPosition(i) {
    const v = meshes[i].position.clone().project(camera);
    const r = renderer.domElement.getBoundingClientRect();
    return { x: ((v.x + 1) / 2) * r.width, y: ((1 - v.y) / 2) * r.height };
  },
};
