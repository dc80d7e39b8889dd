// Framing the robot: the camera sees every named pose whole (issue 25), and the robot's
// extent on the canvas for tests (`simkitViewer.screenBox()`). World frame: MuJoCo's, z up.
import * as THREE from 'three';

function robotMeshes(geoms) {
  return geoms.filter((m) => m.visible && !m.userData.collision
    && m.geometry.type !== 'PlaneGeometry');
}

// The visible robot's vertices in world coordinates, after the current geom matrices.
function visibleVertices(geoms, visit) {
  const point = new THREE.Vector3();
  for (const mesh of robotMeshes(geoms)) {
    mesh.updateMatrixWorld(true);
    const positions = mesh.geometry.attributes.position;
    for (let i = 0; i < positions.count; i++) {
      visit(point.fromBufferAttribute(positions, i).applyMatrix4(mesh.matrixWorld));
    }
  }
}

// The robot's extent on the canvas in normalised device coordinates ([-1, 1] is inside).
export function screenBox(camera, geoms) {
  const lo = [Infinity, Infinity];
  const hi = [-Infinity, -Infinity];
  camera.updateMatrixWorld(true);
  visibleVertices(geoms, (p) => {
    p.project(camera);
    lo[0] = Math.min(lo[0], p.x); lo[1] = Math.min(lo[1], p.y);
    hi[0] = Math.max(hi[0], p.x); hi[1] = Math.max(hi[1], p.y);
  });
  return { lo, hi };
}

// Frame the robot in every named pose (issue 25), from +x, -y and above: the poses are set
// kinematically (qpos, mj_kinematics, no stepping), a bounding sphere of all their vertices
// is seen whole, then a few steps centre their joint extent and move in until it fills FILL
// of the canvas. `showPose(values)` places the geoms at a pose; the state is restored after.
const FILL = 0.85;
export function frameCamera(view, geoms, poses, showPose) {
  const { camera, controls } = view;
  const box = new THREE.Box3();
  for (const values of poses) {
    showPose(values);
    visibleVertices(geoms, (p) => box.expandByPoint(p));
  }
  if (box.isEmpty()) box.set(new THREE.Vector3(-0.5, -0.5, 0), new THREE.Vector3(0.5, 0.5, 1));
  const target = box.getCenter(new THREE.Vector3());
  const radius = Math.max(box.getSize(new THREE.Vector3()).length() / 2, 0.05);
  const halfV = THREE.MathUtils.degToRad(camera.fov / 2);
  const halfH = Math.atan(Math.tan(halfV) * camera.aspect);
  let distance = (1.05 * radius) / Math.sin(Math.min(halfV, halfH));
  const direction = new THREE.Vector3(1.2, -1.6, 0.8).normalize();
  const place = () => {
    camera.position.copy(target).addScaledVector(direction, distance);
    camera.near = distance / 100;
    camera.far = distance * 100;
    camera.lookAt(target);
    camera.updateProjectionMatrix();
  };
  const extent = () => {
    const lo = [Infinity, Infinity];
    const hi = [-Infinity, -Infinity];
    for (const values of poses) {
      showPose(values);
      const one = screenBox(camera, geoms);
      for (const k of [0, 1]) { lo[k] = Math.min(lo[k], one.lo[k]); hi[k] = Math.max(hi[k], one.hi[k]); }
    }
    return { lo, hi };
  };
  place();
  for (let step = 0; step < 6; step++) {
    const { lo, hi } = extent();
    const right = new THREE.Vector3().setFromMatrixColumn(camera.matrixWorld, 0);
    const up = new THREE.Vector3().setFromMatrixColumn(camera.matrixWorld, 1);
    target.addScaledVector(right, ((lo[0] + hi[0]) / 2) * Math.tan(halfH) * distance);
    target.addScaledVector(up, ((lo[1] + hi[1]) / 2) * Math.tan(halfV) * distance);
    const half = Math.max(hi[0] - lo[0], hi[1] - lo[1]) / 2;
    distance *= Math.min(Math.max(half / FILL, 0.5), 2);
    place();
  }
  for (let step = 0; step < 20; step++) {  // never closer than the whole robot allows
    const { lo, hi } = extent();
    if (Math.min(...lo) >= -0.95 && Math.max(...hi) <= 0.95) break;
    distance *= 1.1;
    place();
  }
  controls.target.copy(target);
  controls.update();
  return radius;
}
