// Plays the sequences of ../export/export.json side by side (LR input | GDSR | HR
// simulation): one glTF each, frame k = morph target k - 1 at weight 1 (frame 0 = the base
// shape; see docs/exports.md). One slider drives all three; orbit controls; a toggle
// between shaded cloth and normals as colour. #status reads "ready: ..." once everything is
// loaded, or "error: ..." (the headless test checks it).
import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';

const status = document.getElementById('status');
const fail = (msg) => { status.textContent = 'error: ' + msg; status.style.color = '#b00'; };
window.addEventListener('error', (e) => fail(e.message));
window.addEventListener('unhandledrejection', (e) => fail(String(e.reason)));

const titles = { lr: 'LR input', gdsr: 'GDSR', hr: 'HR simulation' };
const colours = { lr: 0xf08c28, gdsr: 0x3c78c8, hr: 0x50aa50 };

const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
renderer.setPixelRatio(window.devicePixelRatio);
renderer.setSize(window.innerWidth, window.innerHeight);
document.body.prepend(renderer.domElement);
const scene = new THREE.Scene();
scene.background = new THREE.Color(0xf4f4f4);
scene.add(new THREE.AmbientLight(0xffffff, 0.6));
const sun = new THREE.DirectionalLight(0xffffff, 2.0);
sun.position.set(1, 2, 3);
scene.add(sun);
const camera = new THREE.PerspectiveCamera(35, window.innerWidth / window.innerHeight, 0.01, 100);
const controls = new OrbitControls(camera, renderer.domElement);

const meshes = [];   // { mesh, cloth, normal }
const garments = [];  // { root, slot: x offset, centroids: [Vector3 per frame] }
let frames = 1, fps = 30, frame = 0, playing = true, last = performance.now();

function setFrame(k) {
  frame = k;
  for (const { mesh } of meshes) {
    const w = mesh.morphTargetInfluences;
    if (!w) continue;
    w.fill(0);
    if (k > 0) w[k - 1] = 1;
  }
  // Follow the garments: each one's centroid at frame k sits at its slot (the body may walk).
  for (const g of garments) g.root.position.set(g.slot, 0, 0).sub(g.centroids[Math.min(k, g.centroids.length - 1)]);
  document.getElementById('frame').value = k;
  document.getElementById('frame_label').textContent = 'frame ' + k;
}

async function main() {
  const response = await fetch('../export/export.json');
  if (!response.ok) throw new Error('../export/export.json: HTTP ' + response.status);
  const info = await response.json();
  frames = info.frames;
  fps = info.fps;
  const loader = new GLTFLoader();
  const order = ['lr', 'gdsr', 'hr'].map((n) => info.sequences.find((s) => s.name === n)).filter((s) => s && s.gltf);
  const gltfs = await Promise.all(order.map((s) => loader.loadAsync('../export/' + s.gltf)));
  // Framing from frame 0 (the base shape; a box over all morph targets would span the walk).
  const size = new THREE.Vector3();
  for (const g of gltfs)
    g.scene.traverse((o) => {
      if (o.isMesh) size.max(new THREE.Box3().setFromBufferAttribute(o.geometry.attributes.position).getSize(new THREE.Vector3()));
    });
  const step = Math.max(size.x, size.z) * 1.3;
  gltfs.forEach((g, i) => {
    const name = order[i].name;
    scene.add(g.scene);
    let centroids = [new THREE.Vector3()];
    g.scene.traverse((o) => {
      if (!o.isMesh) return;
      // flatShading: normals from the morphed positions (the files carry no normals).
      const cloth = new THREE.MeshStandardMaterial({ color: colours[name], side: THREE.DoubleSide, flatShading: true,
                                                     roughness: 0.8 });
      const normal = new THREE.MeshNormalMaterial({ side: THREE.DoubleSide, flatShading: true });
      o.material = cloth;
      o.frustumCulled = false;  // the bounding box is the base frame's
      meshes.push({ mesh: o, cloth, normal });
      centroids = frameCentroids(o.geometry);
    });
    garments.push({ root: g.scene, slot: (i - (gltfs.length - 1) / 2) * step, centroids });
    const label = document.createElement('span');
    label.textContent = titles[name];
    document.getElementById('labels').append(label);
  });
  const span = step * gltfs.length;
  // Distance that fits the row horizontally and the tallest garment vertically.
  const tanHalf = Math.tan(THREE.MathUtils.degToRad(camera.fov / 2));
  const dist = 1.1 * Math.max(span / 2 / (tanHalf * camera.aspect), size.y / 2 / tanHalf) + size.z / 2;
  camera.position.set(0, 0, dist);
  controls.target.set(0, 0, 0);
  controls.update();
  setFrame(0);
  const slider = document.getElementById('frame');
  slider.max = frames - 1;
  slider.addEventListener('input', () => { playing = false; setFrame(Number(slider.value)); updateButton(); });
  document.getElementById('play').addEventListener('click', () => { playing = !playing; updateButton(); });
  document.getElementById('normals').addEventListener('change', (e) => {
    for (const m of meshes) m.mesh.material = e.target.checked ? m.normal : m.cloth;
  });
  const params = new URLSearchParams(location.search);
  if (params.has('frame')) { playing = false; setFrame(Math.min(frames - 1, Number(params.get('frame')))); }
  if (params.has('normals')) document.getElementById('normals').click();
  updateButton();
  status.textContent = `ready: ${gltfs.length} garments, ${frames} frames at ${fps} fps`;
}

// Centroid of every frame: the base positions, plus the mean of morph target k - 1 (glTF
// targets are displacements) for frame k.
function frameCentroids(geometry) {
  const mean = (a) => {
    const m = new THREE.Vector3();
    for (let i = 0; i < a.length; i += 3) m.x += a[i], m.y += a[i + 1], m.z += a[i + 2];
    return m.multiplyScalar(3 / a.length);
  };
  const base = mean(geometry.attributes.position.array);
  const out = [base];
  for (const t of geometry.morphAttributes.position || []) out.push(mean(t.array).add(base));
  return out;
}

function updateButton() { document.getElementById('play').textContent = playing ? 'pause' : 'play'; }

function animate(now) {
  requestAnimationFrame(animate);
  if (playing && frames > 1 && now - last >= 1000 / fps) {
    last = now;
    setFrame((frame + 1) % frames);
  }
  controls.update();
  renderer.render(scene, camera);
}

window.addEventListener('resize', () => {
  camera.aspect = window.innerWidth / window.innerHeight;
  camera.updateProjectionMatrix();
  renderer.setSize(window.innerWidth, window.innerHeight);
});

main().catch((e) => fail(e.message || String(e)));
requestAnimationFrame(animate);
