// One three.js mesh per MuJoCo geom, in the geom's own frame (the viewer sets its world
// matrix from data.geom_xpos / geom_xmat each frame). Sizes are MuJoCo's geom_size (m):
// half-sizes for a box, radius and half-length for a capsule or cylinder (axis z).
import * as THREE from 'three';

const PLANE = 0;
const SPHERE = 2;
const CAPSULE = 3;
const ELLIPSOID = 4;
const CYLINDER = 5;
const BOX = 6;
const MESH = 7;
const FLOOR_SIZE = 20;  // m: an infinite MuJoCo plane drawn as a 20 m square

function meshGeometry(model, g) {
  const m = model.geom_dataid[g];
  const v0 = model.mesh_vertadr[m];
  const f0 = model.mesh_faceadr[m];
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.Float32BufferAttribute(
    model.mesh_vert.slice(3 * v0, 3 * (v0 + model.mesh_vertnum[m])), 3));
  geometry.setIndex(Array.from(model.mesh_face.slice(3 * f0, 3 * (f0 + model.mesh_facenum[m]))));
  const flat = geometry.toNonIndexed();  // faceted: the kits' meshes are hulls and CAD solids
  flat.computeVertexNormals();
  return flat;
}

function alongZ(geometry) {
  return geometry.rotateX(Math.PI / 2);  // three's capsules and cylinders run along y
}

function primitive(model, g) {
  const s = model.geom_size.subarray(3 * g, 3 * g + 3);
  switch (model.geom_type[g]) {
    case PLANE: return new THREE.PlaneGeometry(
      s[0] > 0 ? 2 * s[0] : FLOOR_SIZE, s[1] > 0 ? 2 * s[1] : FLOOR_SIZE);
    case SPHERE: return new THREE.SphereGeometry(s[0], 24, 16);
    case CAPSULE: return alongZ(new THREE.CapsuleGeometry(s[0], 2 * s[1], 8, 24));
    case ELLIPSOID: return new THREE.SphereGeometry(1, 24, 16).scale(s[0], s[1], s[2]);
    case CYLINDER: return alongZ(new THREE.CylinderGeometry(s[0], s[0], 2 * s[1], 32));
    case BOX: return new THREE.BoxGeometry(2 * s[0], 2 * s[1], 2 * s[2]);
    case MESH: return meshGeometry(model, g);
    default: return null;  // height fields and the like are not drawn
  }
}

function colour(model, g) {
  const mat = model.geom_matid[g];
  const rgba = mat >= 0 ? model.mat_rgba.subarray(4 * mat, 4 * mat + 4)
    : model.geom_rgba.subarray(4 * g, 4 * g + 4);
  return rgba;
}

export function geomMesh(model, g) {
  const geometry = primitive(model, g);
  if (!geometry) return null;
  const rgba = colour(model, g);
  const floor = model.geom_type[g] === PLANE;
  const material = new THREE.MeshStandardMaterial({
    color: floor ? 0x3a4656 : new THREE.Color(rgba[0], rgba[1], rgba[2]),
    transparent: rgba[3] < 1,
    opacity: rgba[3],
    side: floor ? THREE.DoubleSide : THREE.FrontSide,
    roughness: 0.7,
  });
  const collides = model.geom_contype[g] !== 0 || model.geom_conaffinity[g] !== 0;
  if (collides && !floor) {  // collision pieces: translucent, a colour per piece
    material.color.setHSL((g * 0.137) % 1, 0.75, 0.55);
    material.transparent = true;
    material.opacity = 0.55;
    material.depthWrite = false;
  }
  return new THREE.Mesh(geometry, material);
}
