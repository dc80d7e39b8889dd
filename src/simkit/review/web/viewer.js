// The live viewer of `simkit view` and of the kit pages of `simkit publish`: MuJoCo's
// WebAssembly build steps the kit's MJCF in real time, three.js draws every geom at its
// simulated pose. Position servos (the MJCF's actuators) hold the joints: named-pose buttons
// and the joint sliders set their targets (ctrl). Frames: MuJoCo's world, z up, metres.
//
// Where the kit comes from: a kit page holds `<script type="application/json"
// id="simkit-kit">` ({"base": URL of the kit folder, "files": [kit paths]}); without it (the
// `simkit view` server) the kit is at `kit/` and its file list at `kit-files.json`. Every
// request stays on this site. The test interface `window.simkitViewer` is documented in
// docs/publish.md.
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import loadMujoco from './vendor/mujoco/mujoco.js';
import { geomMesh } from './geoms.js';
import { frameCamera, screenBox } from './camera.js';

const MAX_STEPS_PER_FRAME = 200;  // a slow machine runs behind real time, never freezes
const MAX_CONTACTS = 64;
let settle;
const api = { error: null, firstFrame: null, ready: new Promise((ok, no) => { settle = { ok, no }; }) };
api.ready.catch(() => {});  // the error is shown on the page and in api.error
window.simkitViewer = api;

function element(tag, attrs = {}, text = '') {
  const node = document.createElement(tag);
  for (const [key, value] of Object.entries(attrs)) node.setAttribute(key, value);
  if (text) node.textContent = text;
  return node;
}

async function fetchOk(url) {
  const response = await fetch(url);
  if (!response.ok) throw new Error(`${url}: HTTP ${response.status}`);
  return response;
}

async function kitSource() {
  const inline = document.getElementById('simkit-kit');
  if (inline) return JSON.parse(inline.textContent);
  return { base: 'kit/', files: await (await fetchOk('kit-files.json')).json() };
}

// The MJCF and every file beside it that it may name (meshes, included XML) into MuJoCo's
// in-memory file system under /kit; the URDF, USD, STEP... stay on the server.
async function loadModel(mujoco, source, robot) {
  const wanted = source.files.filter((p) => p.startsWith('mjcf/') || p.startsWith('meshes/'));
  const bodies = await Promise.all(wanted.map(async (p) => new Uint8Array(
    await (await fetchOk(source.base + p)).arrayBuffer())));
  wanted.forEach((path, i) => {
    const folder = `/kit/${path.split('/').slice(0, -1).join('/')}`;
    mujoco.FS.mkdirTree(folder);
    mujoco.FS.writeFile(`/kit/${path}`, bodies[i]);
  });
  const main = robot.files?.mjcf_scene ?? robot.files?.mjcf ?? `mjcf/${robot.name}.xml`;
  return { model: mujoco.MjModel.from_xml_path(`/kit/${main}`), main };
}

function setupScene(container) {
  const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
  renderer.setPixelRatio(window.devicePixelRatio);
  container.appendChild(renderer.domElement);
  const scene = new THREE.Scene();
  scene.background = new THREE.Color(0x2a3240);
  scene.add(new THREE.HemisphereLight(0xffffff, 0x8d8f94, 1.6));
  const key = new THREE.DirectionalLight(0xffffff, 1.6);
  key.position.set(2, -2, 4);
  scene.add(key);
  const camera = new THREE.PerspectiveCamera(45, 1, 0.01, 100);
  camera.up.set(0, 0, 1);  // MuJoCo's z up
  const controls = new OrbitControls(camera, renderer.domElement);
  const resize = () => {
    const { clientWidth: w, clientHeight: h } = container;
    renderer.setSize(w, h, false);
    camera.aspect = w / Math.max(h, 1);
    camera.updateProjectionMatrix();
  };
  new ResizeObserver(resize).observe(container);
  resize();
  return { scene, camera, controls, resize, render: () => renderer.render(scene, camera) };
}

// Name lookups and the joint <-> qpos / actuator maps of the compiled model.
function indexModel(mujoco, model) {
  const id = (kind, name) => mujoco.mj_name2id(model, mujoco.mjtObj[kind].value, name);
  const joints = new Map();
  for (let j = 0; j < model.njnt; j++) {
    const name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT.value, j);
    const type = model.jnt_type[j];  // 0 free, 1 ball, 2 slide, 3 hinge
    joints.set(name, { id: j, type, adr: model.jnt_qposadr[j], actuator: -1 });
  }
  for (let a = 0; a < model.nu; a++) {
    const j = model.actuator_trnid[2 * a];
    for (const joint of joints.values()) if (joint.id === j) joint.actuator = a;
  }
  return { id, joints };
}

function buildGeoms(mujoco, model, scene) {
  const geoms = [];
  for (let g = 0; g < model.ngeom; g++) {
    const mesh = geomMesh(model, g);
    if (!mesh) continue;
    const collides = model.geom_contype[g] !== 0 || model.geom_conaffinity[g] !== 0;
    const isFloor = model.geom_type[g] === 0;
    mesh.userData = { g, collision: collides && !isFloor, body: model.geom_bodyid[g] };
    mesh.visible = !mesh.userData.collision || isFloor;
    mesh.matrixAutoUpdate = false;
    scene.add(mesh);
    geoms.push(mesh);
  }
  return geoms;
}

function placeGeoms(model, data, geoms) {
  const pos = data.geom_xpos;
  const mat = data.geom_xmat;
  for (const mesh of geoms) {
    const g = mesh.userData.g;
    const m = mat.subarray(9 * g, 9 * g + 9);
    mesh.matrix.set(m[0], m[1], m[2], pos[3 * g], m[3], m[4], m[5], pos[3 * g + 1],
      m[6], m[7], m[8], pos[3 * g + 2], 0, 0, 0, 1);
  }
}

function contactMarkers(scene, size) {
  const material = new THREE.MeshBasicMaterial({ color: 0xff3050, depthTest: false });
  const geometry = new THREE.SphereGeometry(size, 8, 6);
  const markers = [];
  for (let i = 0; i < MAX_CONTACTS; i++) {
    const marker = new THREE.Mesh(geometry, material);
    marker.visible = false;
    marker.renderOrder = 3;
    scene.add(marker);
    markers.push(marker);
  }
  return markers;
}

function placeContacts(data, markers, on) {
  const n = on ? Math.min(data.ncon, markers.length) : 0;
  if (n) {
    const contacts = data.contact;
    for (let i = 0; i < n; i++) {
      const c = contacts.get(i);
      markers[i].position.set(c.pos[0], c.pos[1], c.pos[2]);
      c.delete?.();
    }
    contacts.delete();
  }
  markers.forEach((m, i) => { m.visible = i < n; });
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

function jointLabel(joint, q) {
  return joint.type === 'prismatic'
    ? `${(q * 1000).toFixed(1)} mm`
    : `${THREE.MathUtils.radToDeg(q).toFixed(1)}°`;
}

function panel(id) {
  return document.getElementById(id) ?? element('div');
}

class Sim {
  constructor(mujoco, model, robot) {
    this.mujoco = mujoco;
    this.model = model;
    this.data = new mujoco.MjData(model);
    this.robot = robot;
    this.index = indexModel(mujoco, model);
    this.movable = robot.joints.filter((j) => j.type !== 'fixed');
    this.poses = robot.poses ?? (robot.home ? { home: robot.home } : {});
    this.paused = false;
    this.sliders = {};
  }

  jointValues(values) {
    return Object.fromEntries(this.movable.map((j, i) => [j.name, values[i] ?? 0]));
  }

  setTarget(name, value) {
    const joint = this.index.joints.get(name);
    if (!joint) throw new Error(`no joint ${name} in the MJCF`);
    if (joint.actuator >= 0) this.data.ctrl[joint.actuator] = value;
    const slider = this.sliders[name];
    if (slider) slider.show(value);
  }

  // Drive the servos to a named pose (the joints move there under physics).
  pose(name) {
    const values = this.poses[name];
    if (!values) throw new Error(`no named pose ${name}`);
    for (const [joint, q] of Object.entries(this.jointValues(values))) this.setTarget(joint, q);
  }

  // Start over at a named pose (default: home): the model's initial state (a floating base
  // where the MJCF puts it, above the floor), the joints at the pose, servos holding it.
  reset(name) {
    const values = this.poses[name ?? 'home'] ?? this.robot.home ?? [];
    this.mujoco.mj_resetData(this.model, this.data);
    for (const [joint, q] of Object.entries(this.jointValues(values))) {
      const found = this.index.joints.get(joint);
      if (found) this.data.qpos[found.adr] = q;
      this.setTarget(joint, q);
    }
    this.mujoco.mj_forward(this.model, this.data);
  }

  // Place the bodies at joint values without stepping (for framing the camera).
  showPose(values) {
    for (const [joint, q] of Object.entries(this.jointValues(values))) {
      const found = this.index.joints.get(joint);
      if (found) this.data.qpos[found.adr] = q;
    }
    this.mujoco.mj_kinematics(this.model, this.data);
  }

  step(n) {
    for (let i = 0; i < n; i++) this.mujoco.mj_step(this.model, this.data);
  }

  qpos() {
    const out = {};
    for (const [name, joint] of this.index.joints) {
      const width = joint.type === 0 ? 7 : joint.type === 1 ? 4 : 1;
      const values = Array.from(this.data.qpos.subarray(joint.adr, joint.adr + width));
      out[name] = width === 1 ? values[0] : values;
    }
    return out;
  }

  position(kind, name) {
    const id = this.index.id(kind, name);
    if (id < 0) return null;
    const xyz = kind === 'mjOBJ_SITE' ? this.data.site_xpos : this.data.xpos;
    return Array.from(xyz.subarray(3 * id, 3 * id + 3));
  }
}

function buildControls(sim) {
  const poses = panel('poses');
  for (const name of Object.keys(sim.poses)) {
    const button = element('button', { 'data-pose': name }, name);
    button.addEventListener('click', () => sim.pose(name));
    poses.appendChild(button);
  }
  const joints = panel('joints');
  for (const joint of sim.movable) {
    const value = element('span', { class: 'value' });
    const input = element('input', {
      type: 'range', min: joint.lower ?? -Math.PI, max: joint.upper ?? Math.PI, step: 'any',
      'data-joint': joint.name,
    });
    const label = element('label', {}, joint.name);
    label.appendChild(value);
    const row = element('div', { class: 'joint' });
    row.append(label, input);
    joints.appendChild(row);
    sim.sliders[joint.name] = {
      show: (q) => { input.value = q; value.textContent = jointLabel(joint, q); },
    };
    input.addEventListener('input', () => sim.setTarget(joint.name, Number(input.value)));
  }
}

function buildToggles(sim, geoms, markers, state) {
  const box = panel('collision');
  const pieces = geoms.filter((m) => m.userData.collision);
  toggle(box, 'collision pieces', { 'data-collision': '*' }, false, (on) => {
    pieces.forEach((m) => { m.visible = on; });
    geoms.filter((m) => !m.userData.collision && m.geometry.type !== 'PlaneGeometry')
      .forEach((m) => { m.material.transparent = on; m.material.opacity = on ? 0.35 : 1; });
  });
  toggle(box, 'contacts', { 'data-contacts': '*' }, false, (on) => { state.contacts = on; });
  const sim_ = panel('simulation');
  toggle(sim_, 'paused', { 'data-pause': '*' }, false, (on) => { sim.paused = on; });
  const reset = element('button', { 'data-reset': '*' }, 'reset');
  reset.addEventListener('click', () => sim.reset());
  sim_.appendChild(reset);
  return pieces.length;
}

async function main() {
  const status = panel('status');
  const source = await kitSource();
  const robot = await (await fetchOk(`${source.base}robot.json`)).json();
  panel('title').textContent = robot.title ?? robot.name;  // text, never markup
  const mujoco = await loadMujoco();
  const { model, main: mjcf } = await loadModel(mujoco, source, robot);
  const sim = new Sim(mujoco, model, robot);
  const view = setupScene(panel('view'));
  const geoms = buildGeoms(mujoco, model, view.scene);
  if (!geoms.some((m) => m.geometry.type === 'PlaneGeometry')) {  // no floor: a grid at z = 0
    const grid = new THREE.GridHelper(4, 20, 0x5b6a7e, 0x3a4656);
    grid.rotation.x = Math.PI / 2;
    view.scene.add(grid);
  }
  buildControls(sim);
  sim.reset();
  const poses = [...Object.values(sim.poses), robot.home ?? []];
  view.resize();
  const radius = frameCamera(view, geoms, poses, (values) => {
    sim.showPose(values);
    placeGeoms(model, sim.data, geoms);
  });
  sim.reset();
  placeGeoms(model, sim.data, geoms);
  const state = { contacts: false };
  const markers = contactMarkers(view.scene, radius / 80);
  const pieces = buildToggles(sim, geoms, markers, state);
  const draw = () => {
    placeGeoms(model, sim.data, geoms);
    placeContacts(sim.data, markers, state.contacts);
    view.render();
  };
  let wall = null;
  const frame = (now) => {
    if (wall !== null && !sim.paused) {
      const goal = sim.data.time + Math.min((now - wall) / 1000, 0.1);
      for (let i = 0; i < MAX_STEPS_PER_FRAME && sim.data.time < goal; i++) sim.step(1);
      if (api.firstFrame === null && sim.data.time > 0) api.firstFrame = performance.now();
    }
    wall = now;
    draw();
    requestAnimationFrame(frame);
  };
  Object.assign(api, {
    time: () => sim.data.time,
    qpos: () => sim.qpos(),
    setTarget: (joint, value) => sim.setTarget(joint, value),
    pose: (name) => sim.pose(name),
    reset: (name) => { sim.reset(name); draw(); },
    pause: (on = true) => { sim.paused = on; },
    step: (n = 1) => { sim.step(n); draw(); return sim.data.time; },
    bodyPosition: (name) => sim.position('mjOBJ_BODY', name),
    framePosition: (name) => sim.position('mjOBJ_SITE', name) ?? sim.position('mjOBJ_BODY', name),
    timestep: () => model.opt.timestep,
    screenBox: () => screenBox(view.camera, geoms),
  });
  status.textContent = `${mjcf}: ${sim.movable.length} joints, ${pieces} collision pieces`;
  requestAnimationFrame(frame);
  settle.ok(api);
}

main().catch((error) => {
  const status = panel('status');
  status.textContent = `error: ${error.message ?? error}`;
  status.className = 'error';
  api.error = String(error.message ?? error);
  console.error(error);
  settle.no(error);
});
