// simkit view: a kit's GLB with joint sliders, named poses, frames and collision pieces.
//
// Kinematics follow the GLB emitter (emit/glb.py): each link node sits on its joint origin,
// so a joint value q turns the child link node about the joint axis (node frame) by q, or
// moves it along the axis by q for a prismatic joint. The scene's first node turns the kit's
// Z-up frames into glTF's Y-up; positions reported by `simkitViewer.framePosition` are in the
// kit's frame (m), below that node. Everything is fetched from this server: no network.
import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import { STLLoader } from 'three/addons/loaders/STLLoader.js';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';

const COLLISION_PIECE = /^meshes\/collision\/(.+)_(\d+)\.(stl|obj)$/;
const PALETTE = [0xf25a1a, 0x1a8cf2, 0x33bf4d, 0xd933b3, 0xf2bf1a];
const api = { ready: false, error: null, joints: [] };
window.simkitViewer = api;

function element(tag, attrs = {}, text = '') {
  const node = document.createElement(tag);
  for (const [key, value] of Object.entries(attrs)) node.setAttribute(key, value);
  if (text) node.textContent = text;
  return node;
}

async function fetchJson(url) {
  const response = await fetch(url);
  if (!response.ok) throw new Error(`${url}: HTTP ${response.status}`);
  return response.json();
}

function setupScene(container) {
  const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
  renderer.setPixelRatio(window.devicePixelRatio);
  container.appendChild(renderer.domElement);
  const scene = new THREE.Scene();
  scene.background = new THREE.Color(0x2a3240);  // dark: white robots stand out
  scene.add(new THREE.HemisphereLight(0xffffff, 0x8d8f94, 1.6));
  const key = new THREE.DirectionalLight(0xffffff, 1.6);
  key.position.set(2, 4, 2);
  scene.add(key);
  const fill = new THREE.DirectionalLight(0xffffff, 0.5);
  fill.position.set(-2, 3, -2);
  scene.add(fill);
  const camera = new THREE.PerspectiveCamera(45, 1, 0.01, 100);
  const controls = new OrbitControls(camera, renderer.domElement);
  const render = () => renderer.render(scene, camera);
  controls.addEventListener('change', render);
  const resize = () => {
    const { clientWidth: w, clientHeight: h } = container;
    renderer.setSize(w, h, false);
    camera.aspect = w / Math.max(h, 1);
    camera.updateProjectionMatrix();
    render();
  };
  new ResizeObserver(resize).observe(container);
  const aspect = () => container.clientWidth / Math.max(container.clientHeight, 1);
  return { scene, camera, controls, render, resize, aspect };
}

// The visible meshes' vertices in world coordinates (three's frame), after `object`'s
// current joint values; collision pieces and frame axes count only when shown.
function visibleVertices(object, visit) {
  object.updateMatrixWorld(true);
  const point = new THREE.Vector3();
  object.traverseVisible((node) => {
    if (!node.isMesh) return;
    const positions = node.geometry.attributes.position;
    for (let i = 0; i < positions.count; i++) {
      visit(point.fromBufferAttribute(positions, i).applyMatrix4(node.matrixWorld));
    }
  });
}

// The extent on the canvas, in normalised device coordinates, of the visible vertices of
// `object` in every pose of `poses` (each a list of joint values for `setPose`).
function poseBox(camera, object, poses, setPose) {
  const lo = [Infinity, Infinity];
  const hi = [-Infinity, -Infinity];
  camera.updateMatrixWorld(true);
  for (const values of poses) {
    setPose(values);
    visibleVertices(object, (p) => {
      p.project(camera);
      lo[0] = Math.min(lo[0], p.x); lo[1] = Math.min(lo[1], p.y);
      hi[0] = Math.max(hi[0], p.x); hi[1] = Math.max(hi[1], p.y);
    });
  }
  return { lo, hi };
}

// Frame the robot in every named pose (issue 25: with home alone, the flange left the canvas
// in "stretched"): first a bounding sphere of the vertices of all poses, seen whole by the
// narrower field of view; then a few steps that centre the poses' extent on the canvas and
// move in until it fills FILL of the canvas in its longer direction.
const FILL = 0.85;
function frameCamera(view, object, poses, setPose) {
  const { camera, controls } = view;
  const box = new THREE.Box3();
  for (const values of poses) {
    setPose(values);
    visibleVertices(object, (p) => box.expandByPoint(p));
  }
  if (box.isEmpty()) box.setFromObject(object);
  const target = box.getCenter(new THREE.Vector3());
  const radius = Math.max(box.getSize(new THREE.Vector3()).length() / 2, 0.05);
  const halfV = THREE.MathUtils.degToRad(camera.fov / 2);
  const halfH = Math.atan(Math.tan(halfV) * camera.aspect);
  let distance = (1.05 * radius) / Math.sin(Math.min(halfV, halfH));
  // from +x, -y (kit frame) and above; the kit's (x, y, z) is three's (x, z, -y)
  const direction = new THREE.Vector3(1.2, 0.8, 1.6).normalize();
  const place = () => {
    camera.position.copy(target).addScaledVector(direction, distance);
    camera.near = distance / 100;
    camera.far = distance * 100;
    camera.lookAt(target);
    camera.updateProjectionMatrix();
  };
  place();
  for (let step = 0; step < 6; step++) {
    const { lo, hi } = poseBox(camera, object, poses, setPose);
    const right = new THREE.Vector3().setFromMatrixColumn(camera.matrixWorld, 0);
    const up = new THREE.Vector3().setFromMatrixColumn(camera.matrixWorld, 1);
    target.addScaledVector(right, ((lo[0] + hi[0]) / 2) * Math.tan(halfH) * distance);
    target.addScaledVector(up, ((lo[1] + hi[1]) / 2) * Math.tan(halfV) * distance);
    const half = Math.max(hi[0] - lo[0], hi[1] - lo[1]) / 2;
    distance *= Math.min(Math.max(half / FILL, 0.5), 2);
    place();
  }
  for (let step = 0; step < 20; step++) { // never closer than the whole robot allows
    const { lo, hi } = poseBox(camera, object, poses, setPose);
    if (Math.min(...lo) >= -0.95 && Math.max(...hi) <= 0.95) break;
    distance *= 1.1;
    place();
  }
  controls.target.copy(target);
  controls.update();
  const grid = new THREE.GridHelper(radius * 4, 20, 0x5b6a7e, 0x3a4656);
  grid.position.y = Math.min(box.min.y, 0);
  view.scene.add(grid);
}

// The robot's extent on the canvas in normalised device coordinates ([-1, 1] is inside).
function screenBox(view, object) {
  const lo = [Infinity, Infinity];
  const hi = [-Infinity, -Infinity];
  view.camera.updateMatrixWorld(true);
  visibleVertices(object, (p) => {
    p.project(view.camera);
    lo[0] = Math.min(lo[0], p.x); lo[1] = Math.min(lo[1], p.y);
    hi[0] = Math.max(hi[0], p.x); hi[1] = Math.max(hi[1], p.y);
  });
  return { lo, hi };
}

function makeJoint(spec, model) {
  const node = model.getObjectByName(spec.child);
  if (!node) throw new Error(`joint ${spec.name}: no node ${spec.child} in the GLB`);
  return {
    name: spec.name,
    type: spec.type,
    lower: spec.lower ?? -Math.PI,
    upper: spec.upper ?? Math.PI,
    axis: new THREE.Vector3(...spec.axis).normalize(),
    node,
    q0: node.quaternion.clone(),
    p0: node.position.clone(),
  };
}

function applyJoint(joint, q) {
  if (joint.type === 'prismatic') {
    const shift = joint.axis.clone().applyQuaternion(joint.q0).multiplyScalar(q);
    joint.node.position.copy(joint.p0).add(shift);
  } else {
    const turn = new THREE.Quaternion().setFromAxisAngle(joint.axis, q);
    joint.node.quaternion.copy(joint.q0).multiply(turn);
  }
}

function jointLabel(joint, q) {
  return joint.type === 'prismatic'
    ? `${(q * 1000).toFixed(1)} mm`
    : `${THREE.MathUtils.radToDeg(q).toFixed(1)}°`;
}

function buildSliders(joints, start, render) {
  const box = document.getElementById('joints');
  const sliders = {};
  joints.forEach((joint, i) => {
    const value = element('span', { class: 'value' });
    const input = element('input', {
      type: 'range', min: joint.lower, max: joint.upper, step: 'any', 'data-joint': joint.name,
    });
    const set = (q) => {
      applyJoint(joint, q);
      value.textContent = jointLabel(joint, q);
      render();
    };
    input.addEventListener('input', () => set(Number(input.value)));
    const label = element('label', {}, joint.name);
    label.appendChild(value);
    const row = element('div', { class: 'joint' });
    row.append(label, input);
    box.appendChild(row);
    sliders[joint.name] = { input, set };
    input.value = start[i] ?? 0;
    set(Number(input.value));
  });
  return sliders;
}

function buildPoses(robot, joints, sliders) {
  const box = document.getElementById('poses');
  const poses = robot.poses ?? (robot.home ? { home: robot.home } : {});
  for (const [name, values] of Object.entries(poses)) {
    const button = element('button', { 'data-pose': name }, name);
    button.addEventListener('click', () => joints.forEach((joint, i) => {
      sliders[joint.name].input.value = values[i] ?? 0;
      sliders[joint.name].set(Number(sliders[joint.name].input.value));
    }));
    box.appendChild(button);
  }
}

function toggle(container, label, attrs, checked, onChange) {
  const input = element('input', { type: 'checkbox', ...attrs });
  input.checked = checked;
  input.addEventListener('change', () => onChange(input.checked));
  const row = element('label', { class: 'toggle' });
  row.append(input, document.createTextNode(` ${label}`));
  container.appendChild(row);
  return input;
}

function buildFrames(robot, model, size, render) {
  const box = document.getElementById('frames');
  const names = [robot.base_frame, robot.tool_frame].filter((n) => n && model.getObjectByName(n));
  for (const name of [...new Set(names)]) {
    const axes = new THREE.AxesHelper(size);
    axes.name = `${name}_axes`;
    axes.material.depthTest = false;
    axes.renderOrder = 2;
    model.getObjectByName(name).add(axes);
    toggle(box, name, { 'data-frame': name }, true, (on) => { axes.visible = on; render(); });
  }
  if (!names.length) box.textContent = 'none named in robot.json';
}

// A kit's OBJ collision piece (kitio/obj.py: `v x y z` and `f a b c` lines) as a geometry.
async function loadObj(url) {
  const text = await (await fetch(url)).text();
  const vertices = [];
  const corners = [];
  for (const line of text.split('\n')) {
    const parts = line.trim().split(/\s+/);
    if (parts[0] === 'v') vertices.push(parts.slice(1, 4).map(Number));
    if (parts[0] !== 'f') continue;
    const ring = parts.slice(1).map((t) => {
      const i = parseInt(t.split('/')[0], 10);
      return i > 0 ? i - 1 : vertices.length + i;
    });
    for (let k = 1; k + 1 < ring.length; k++) corners.push(ring[0], ring[k], ring[k + 1]);
  }
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.Float32BufferAttribute(
    corners.flatMap((i) => vertices[i]), 3));
  geometry.computeVertexNormals();
  return geometry;
}

async function buildCollision(files, model, render) {
  const box = document.getElementById('collision');
  const byLink = new Map();
  for (const path of files) {
    const match = COLLISION_PIECE.exec(path);
    if (match && model.getObjectByName(match[1])) {
      if (!byLink.has(match[1])) byLink.set(match[1], []);
      byLink.get(match[1]).push(path);
    }
  }
  if (!byLink.size) {
    box.textContent = 'no collision meshes in this kit';
    return 0;
  }
  const loader = new STLLoader();
  const groups = [];
  let count = 0;
  for (const [link, paths] of byLink) {
    const group = new THREE.Group();
    group.name = `${link}_collision`;
    group.visible = false;
    const geometries = await Promise.all(paths.map((p) => (p.endsWith('.obj')
      ? loadObj(`kit/${p}`) : loader.loadAsync(`kit/${p}`))));
    geometries.forEach((geometry) => {
      const material = new THREE.MeshStandardMaterial({
        color: PALETTE[count++ % PALETTE.length], transparent: true, opacity: 0.55,
        depthWrite: false, polygonOffset: true, polygonOffsetFactor: -2, polygonOffsetUnits: -2,
      });
      group.add(new THREE.Mesh(geometry, material));
    });
    model.getObjectByName(link).add(group);
    groups.push(group);
  }
  const links = [];
  toggle(box, 'all collision pieces', { 'data-collision': '*' }, false, (on) => {
    links.forEach((input) => { input.checked = on; input.dispatchEvent(new Event('change')); });
  });
  [...byLink.keys()].forEach((link, i) => {
    links.push(toggle(box, `${link} (${byLink.get(link).length})`, { 'data-collision': link },
      false, (on) => { groups[i].visible = on; render(); }));
  });
  return count;
}

async function main() {
  const status = document.getElementById('status');
  const robot = await fetchJson('kit/robot.json');
  const files = await fetchJson('kit-files.json');
  document.title = `simkit view: ${robot.name}`;
  document.getElementById('title').textContent = robot.title ?? robot.name;
  const view = setupScene(document.getElementById('view'));
  const glb = robot.files?.glb ?? `glb/${robot.name}.glb`;
  const gltf = await new GLTFLoader().loadAsync(`kit/${glb}`);
  const model = gltf.scene;
  view.scene.add(model);
  const kitFrame = model.children[0];
  const joints = robot.joints.filter((j) => j.type !== 'fixed').map((j) => makeJoint(j, model));
  const start = robot.joints.filter((j) => j.type !== 'fixed').map((_, i) => (robot.home ?? [])[i]);
  const sliders = buildSliders(joints, start, view.render);
  buildPoses(robot, joints, sliders);
  const setPose = (values) => joints.forEach((joint, i) => {
    sliders[joint.name].input.value = values[i] ?? 0;
    sliders[joint.name].set(Number(sliders[joint.name].input.value));
  });
  const poses = Object.values(robot.poses ?? {});
  view.camera.aspect = view.aspect();
  frameCamera(view, model, [...poses, start], setPose);
  setPose(start);
  const size = new THREE.Box3().setFromObject(model).getSize(new THREE.Vector3()).length();
  buildFrames(robot, model, size / 10, view.render);
  const pieces = await buildCollision(files, model, view.render);
  api.screenBox = () => screenBox(view, model);
  api.joints = joints.map(({ name, type, lower, upper }) => ({ name, type, lower, upper }));
  api.framePosition = (name) => {
    const node = model.getObjectByName(name);
    model.updateMatrixWorld(true);
    const relative = kitFrame.matrixWorld.clone().invert().multiply(node.matrixWorld);
    return new THREE.Vector3().setFromMatrixPosition(relative).toArray();
  };
  view.resize();
  status.textContent = `${glb}: ${joints.length} joints, ${pieces} collision pieces`;
  api.ready = true;
}

main().catch((error) => {
  const status = document.getElementById('status');
  status.textContent = `error: ${error.message ?? error}`;
  status.className = 'error';
  api.error = String(error.message ?? error);
  console.error(error);
});
