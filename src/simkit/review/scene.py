"""The render scene of a kit, without OpenGL: the kit's MJCF plus a floor and two lights,
its named poses as MuJoCo `qpos`, and a camera that frames the whole robot.

Frames: the kit's world frame (Z up, metres). The camera is MuJoCo's free camera: azimuth
and elevation in degrees, distance in metres from `lookat`. Framing uses the robot's geometry
in every named pose, so all poses of a kit (and both kits of a diff) share one camera; fixtures
(links welded to the world) count only near the moving links (`framing_points`).
"""

from __future__ import annotations

import json
import math
import re
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from simkit.errors import SimkitError

#: geom groups the renderer shows: the floor, visual geometry, collision geometry.
FLOOR_GROUP, VISUAL_GROUP, COLLISION_GROUP = 0, 2, 3
#: never drawn: the kit's own ground (planes, height fields), which simkit's floor replaces
HIDDEN_GROUP = 5
FLOOR = "simkit_render_floor"
#: collision pieces when shown (`--collision`): translucent, cycling through these colours,
#: over the visual geometry made faint (VISUAL_FAINT alpha).
COLLISION_COLOURS = (
    (0.95, 0.35, 0.1),
    (0.1, 0.55, 0.95),
    (0.2, 0.75, 0.3),
    (0.85, 0.2, 0.7),
    (0.95, 0.75, 0.1),
)
COLLISION_ALPHA, VISUAL_FAINT = 0.55, 0.25
#: the fitted distance leaves this much room around the robot (all named poses).
MARGIN = 1.15
#: framing: fixtures (geometry welded to the world: a wall plate, a pedestal) count only
#: within this fraction of the moving links' extent around them, so the robot fills the frame
FIXTURE_ROOM = 0.1
POSE_NAME = re.compile(r"^[A-Za-z0-9_.-]+$")

#: a dark blue-grey floor and backdrop, so white, grey and coloured robots all stand out
#: (issue 25: a white robot on a light floor had low contrast)
SCENE_ASSETS = """
<asset>
  <texture name="simkit_render_sky" type="skybox" builtin="gradient" width="64" height="384"
    rgb1="0.26 0.3 0.36" rgb2="0.12 0.14 0.18" />
  <texture name="simkit_render_floor" type="2d" builtin="checker" width="256" height="256"
    rgb1="0.2 0.25 0.32" rgb2="0.16 0.2 0.26" mark="edge" markrgb="0.26 0.31 0.38" />
  <material name="simkit_render_floor" texture="simkit_render_floor" texrepeat="4 4"
    texuniform="true" reflectance="0" />
</asset>
"""
SCENE_BODIES = """
<worldbody>
  <geom name="simkit_render_floor" type="plane" size="0 0 0.05" material="simkit_render_floor"
    contype="0" conaffinity="0" group="0" />
  <light name="simkit_render_key" directional="true" pos="2 -2 4" dir="-0.4 0.4 -0.82"
    diffuse="0.62 0.62 0.62" specular="0.25 0.25 0.25" castshadow="true" />
  <light name="simkit_render_fill" directional="true" pos="-2 2 3" dir="0.5 -0.3 -0.81"
    diffuse="0.3 0.3 0.32" specular="0.05 0.05 0.05" castshadow="false" />
</worldbody>
"""


@dataclass(frozen=True)
class Camera:
    """Free camera: azimuth and elevation in degrees; distance (m) and lookat (world frame, m)
    fitted to the robot when None."""

    azimuth: float = 135.0
    elevation: float = -20.0
    distance: float | None = None
    lookat: tuple[float, float, float] | None = None

    def to_json(self) -> dict:
        return {
            "azimuth": self.azimuth,
            "elevation": self.elevation,
            "distance": self.distance,
            "lookat": list(self.lookat) if self.lookat is not None else None,
        }

    @classmethod
    def from_json(cls, doc: dict) -> Camera:
        look = doc.get("lookat")
        return cls(
            doc["azimuth"], doc["elevation"], doc.get("distance"), tuple(look) if look else None
        )


def parse_camera(text: str) -> Camera:
    """`AZ,EL[,DIST[,X,Y,Z]]` (degrees, degrees, m, m) -> Camera."""
    try:
        values = [float(v) for v in text.split(",")]
    except ValueError:
        values = []
    if len(values) not in (2, 3, 6) or (len(values) > 2 and values[2] <= 0):
        raise SimkitError(
            f"--camera {text!r}: expected AZIMUTH,ELEVATION[,DISTANCE[,X,Y,Z]] "
            "(degrees, degrees, m > 0, m)"
        )
    look = (values[3], values[4], values[5]) if len(values) == 6 else None
    return Camera(values[0], values[1], values[2] if len(values) > 2 else None, look)


def parse_size(text: str) -> tuple[int, int]:
    """`WxH` in pixels -> (width, height)."""
    match = re.fullmatch(r"(\d+)[xX](\d+)", text.strip())
    if not match or not (16 <= int(match[1]) <= 4096 and 16 <= int(match[2]) <= 4096):
        raise SimkitError(f"--size {text!r}: expected WIDTHxHEIGHT in pixels, 16 to 4096 each")
    return int(match[1]), int(match[2])


def robot_json(files: dict[str, bytes]) -> dict:
    return json.loads(files["robot.json"])


def named_poses(doc: dict) -> dict[str, list[float]]:
    """robot.json's named poses (joint values in the order of `joints`, rad or m); a kit
    without any gets its `home`."""
    poses = doc.get("poses") or {"home": doc.get("home", [])}
    bad = [name for name in poses if not POSE_NAME.match(name)]
    if bad:
        raise SimkitError(f"robot.json: pose name {bad[0]!r} is not a file name")
    return {name: list(values) for name, values in poses.items()}


@dataclass
class KitScene:
    """A kit's render model: `model` (MjModel) with groups set, and its named poses."""

    name: str
    model: object
    poses: dict[str, list[float]]
    joints: list[str]
    collision: list[int] = field(default_factory=list)
    rgba0: np.ndarray | None = None  # the kit's geom colours, to restore after `--collision`
    matid0: np.ndarray | None = None


def scene_xml(mjcf: str, meshdir: Path) -> str:
    """The kit's MJCF with absolute mesh paths, its own lights removed, and simkit's floor and
    two lights added (the same for every kit, so renders compare)."""
    root = ET.fromstring(mjcf)
    compiler = root.find("compiler")
    if compiler is None:
        compiler = ET.SubElement(root, "compiler")
    compiler.set("meshdir", str(meshdir))
    for parent in root.iter():
        for light in parent.findall("light"):
            parent.remove(light)
    root.insert(list(root).index(compiler) + 1, ET.fromstring(SCENE_ASSETS))
    root.append(ET.fromstring(SCENE_BODIES))
    return ET.tostring(root, encoding="unicode")


def load_scene(files: dict[str, bytes], workdir: Path, label: str) -> KitScene:
    """Write the kit's MJCF and meshes under `workdir` and compile the render model."""
    import mujoco

    doc = robot_json(files)
    mjcf_path = doc.get("files", {}).get("mjcf") or f"mjcf/{doc['name']}.xml"
    if mjcf_path not in files:
        raise SimkitError(f"{label}: no {mjcf_path} in the kit")
    for path, data in files.items():
        if path.startswith("meshes/"):
            target = workdir / path
            target.parent.mkdir(parents=True, exist_ok=True)
            target.write_bytes(data)
    xml = scene_xml(files[mjcf_path].decode("utf-8"), (workdir / "meshes").resolve())
    try:
        model = mujoco.MjModel.from_xml_string(xml)
    except ValueError as exc:
        raise SimkitError(f"{label}: {mjcf_path} does not load in MuJoCo ({exc})") from None
    joints = [j["name"] for j in doc.get("joints", [])]
    scene = KitScene(doc["name"], model, named_poses(doc), joints)
    _set_groups(scene)
    return scene


def _set_groups(scene: KitScene) -> None:
    """Floor, visual and collision geoms into fixed groups, whatever the kit's groups are:
    a geom that collides (contype or conaffinity set) is collision geometry; the kit's own
    planes and height fields are hidden."""
    import mujoco

    model = scene.model
    floor = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, FLOOR)
    ground = (int(mujoco.mjtGeom.mjGEOM_PLANE), int(mujoco.mjtGeom.mjGEOM_HFIELD))
    for geom in range(model.ngeom):
        if geom == floor:
            model.geom_group[geom] = FLOOR_GROUP
        elif int(model.geom_type[geom]) in ground:
            model.geom_group[geom] = HIDDEN_GROUP
        elif model.geom_contype[geom] or model.geom_conaffinity[geom]:
            model.geom_group[geom] = COLLISION_GROUP
            scene.collision.append(geom)
        else:
            model.geom_group[geom] = VISUAL_GROUP
    scene.rgba0, scene.matid0 = model.geom_rgba.copy(), model.geom_matid.copy()


def pose_qpos(scene: KitScene, pose: str) -> np.ndarray:
    """`qpos` for a named pose: the model's rest values with the pose's joints set."""
    import mujoco

    model = scene.model
    qpos = model.qpos0.copy()
    for name, value in zip(scene.joints, scene.poses[pose], strict=False):
        joint = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, name)
        if joint < 0:
            raise SimkitError(f"{scene.name}: joint {name!r} of robot.json is not in the MJCF")
        qpos[model.jnt_qposadr[joint]] = value
    return qpos


def _geom_points(model, data, geom: int) -> np.ndarray:
    """World-frame points (m) of one geom: mesh vertices exactly, other shapes by the corners
    of their bounding spheres' boxes."""
    import mujoco

    mesh = model.geom_dataid[geom]
    if model.geom_type[geom] == mujoco.mjtGeom.mjGEOM_MESH and mesh >= 0:
        start, count = model.mesh_vertadr[mesh], model.mesh_vertnum[mesh]
        local = model.mesh_vert[start : start + count]
        rot = data.geom_xmat[geom].reshape(3, 3)
        return local @ rot.T + data.geom_xpos[geom]
    r = model.geom_rbound[geom]
    corners = np.array(np.meshgrid(*[(-r, r)] * 3)).reshape(3, -1).T
    return data.geom_xpos[geom] + corners


def posed_points(
    scene: KitScene, data, poses: list[str] | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """(points, moving): world-frame points (m) of the robot's visual and collision geoms in
    `poses` (default: every named pose), and for each whether it belongs to a moving link (a
    body not welded to the world; fixtures such as a wall plate or a pedestal are welded)."""
    import mujoco

    model = scene.model
    points, moving = [], []
    for pose in scene.poses if poses is None else poses:
        data.qpos[:] = pose_qpos(scene, pose)
        mujoco.mj_kinematics(model, data)
        for geom in range(model.ngeom):
            if model.geom_group[geom] in (FLOOR_GROUP, HIDDEN_GROUP):
                continue
            found = _geom_points(model, data, geom)
            points.append(found)
            welded = model.body_weldid[model.geom_bodyid[geom]] == 0
            moving.append(np.full(len(found), not welded))
    if not points:
        return np.zeros((1, 3)), np.ones(1, dtype=bool)
    return np.concatenate(points), np.concatenate(moving)


def robot_points(scene: KitScene, data) -> np.ndarray:
    """World-frame points (m) of the robot's visual and collision geoms in every named pose."""
    return posed_points(scene, data)[0]


def framing_points(points: np.ndarray, moving: np.ndarray) -> np.ndarray:
    """The points a camera frames: the moving links, and of the fixtures only the points
    within FIXTURE_ROOM of the moving links' extent around their bounding box, so that a 1 m
    wall plate does not shrink a 0.3 m arm to a corner of the picture (issue 25). Without
    moving links (a kit of fixed links only), every point counts."""
    if not moving.any():
        return points
    lo, hi = points[moving].min(axis=0), points[moving].max(axis=0)
    room = FIXTURE_ROOM * (hi - lo).max()
    fixed = points[~moving]
    near = np.all((fixed >= lo - room) & (fixed <= hi + room), axis=1)
    return np.concatenate([points[moving], fixed[near]])


def collision_colours(scene: KitScene, on: bool) -> None:
    """Switch the model's colours between the kit's own and the collision view."""
    model = scene.model
    model.geom_rgba[:] = scene.rgba0
    model.geom_matid[:] = scene.matid0
    if not on:
        return
    for geom in range(model.ngeom):
        if model.geom_group[geom] == VISUAL_GROUP:
            model.geom_rgba[geom, 3] = VISUAL_FAINT
            if model.geom_matid[geom] >= 0:
                model.geom_rgba[geom, :3] = model.mat_rgba[model.geom_matid[geom], :3]
                model.geom_matid[geom] = -1
    for k, geom in enumerate(scene.collision):
        model.geom_matid[geom] = -1
        model.geom_rgba[geom] = (*COLLISION_COLOURS[k % len(COLLISION_COLOURS)], COLLISION_ALPHA)


def collision_signature(scene: KitScene) -> str:
    """A hash of the collision geometry in its bodies' frames (shapes, sizes, placements,
    mesh vertices and faces), to tell whether two kits' collision geometry differs."""
    import hashlib

    import mujoco

    model = scene.model
    digest = hashlib.sha256()
    for geom in scene.collision:
        body = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, model.geom_bodyid[geom])
        digest.update(f"{body}:{int(model.geom_type[geom])}".encode())
        for values in (model.geom_size[geom], model.geom_pos[geom], model.geom_quat[geom]):
            digest.update(np.round(values, 9).tobytes())
        mesh = model.geom_dataid[geom]
        if int(model.geom_type[geom]) == int(mujoco.mjtGeom.mjGEOM_MESH) and mesh >= 0:
            v0, nv = model.mesh_vertadr[mesh], model.mesh_vertnum[mesh]
            f0, nf = model.mesh_faceadr[mesh], model.mesh_facenum[mesh]
            digest.update(model.mesh_vert[v0 : v0 + nv].tobytes())
            digest.update(model.mesh_face[f0 : f0 + nf].tobytes())
    return digest.hexdigest()


def _basis(azimuth: float, elevation: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """MuJoCo free camera axes (world frame): forward, right, up."""
    az, el = math.radians(azimuth), math.radians(elevation)
    forward = np.array([math.cos(el) * math.cos(az), math.cos(el) * math.sin(az), math.sin(el)])
    right = np.cross(forward, (0.0, 0.0, 1.0))
    right /= np.linalg.norm(right)
    return forward, right, np.cross(right, forward)


def fit_camera(camera: Camera, points: np.ndarray, fovy_deg: float, aspect: float) -> Camera:
    """Fill in what the camera leaves open: lookat centres the points' extent across the view,
    distance is the nearest at which every point lies inside the view, plus a margin."""
    forward, right, up = _basis(camera.azimuth, camera.elevation)
    if camera.lookat is not None:
        centre = np.asarray(camera.lookat, dtype=float)
    else:
        mid = (points.min(axis=0) + points.max(axis=0)) / 2
        centre = mid.copy()
        for axis in (right, up):  # centre the extent across the view on the image centre
            along = (points - mid) @ axis
            centre += axis * (along.min() + along.max()) / 2
    v = points - centre
    tan_v = math.tan(math.radians(fovy_deg) / 2)
    tan_h = tan_v * aspect
    need = np.maximum(np.abs(v @ right) / tan_h, np.abs(v @ up) / tan_v) - v @ forward
    distance = camera.distance or MARGIN * max(float(need.max()), 1e-2)
    return Camera(camera.azimuth, camera.elevation, distance, tuple(float(c) for c in centre))


def _ray_floor(origin: np.ndarray, ray: np.ndarray, floor_z: float) -> np.ndarray | None:
    if ray[2] >= -1e-9:
        return None  # parallel to the floor or upward: the ray never reaches it
    return origin + ray * (floor_z - origin[2]) / ray[2]


def shadow_clip(
    camera: Camera,
    fovy_deg: float,
    aspect: float,
    points: np.ndarray,
    floor_z: float,
    centre: np.ndarray,
    light_dir: np.ndarray,
) -> float:
    """Half-width (m) of a directional light's shadow box about `centre` that covers the robot
    and the floor in view up to the image's bottom corners. MuJoCo's shadow map (an
    orthographic box of half-width `vis.map.shadowclip` times the extent) speckles the floor
    outside it (shadow acne: rosie_1400's 780 dark pixels per image, issue 25)."""
    forward, right, up = _basis(camera.azimuth, camera.elevation)
    eye = np.asarray(camera.lookat, dtype=float) - camera.distance * forward
    tan_v = math.tan(math.radians(fovy_deg) / 2)
    tan_h = tan_v * aspect
    seen = [points]
    for sx in (-1.0, 0.0, 1.0):
        hit = _ray_floor(eye, forward + sx * tan_h * right - tan_v * up, floor_z)
        if hit is not None:
            seen.append(hit[None, :])
    d = np.concatenate(seen) - centre
    light = np.asarray(light_dir, dtype=float) / np.linalg.norm(light_dir)
    across = d - np.outer(d @ light, light)  # offsets across the light's view
    return float(np.linalg.norm(across, axis=1).max())
