"""The render process: `python -m simkit.review.render_worker` reads one job (JSON) on stdin,
writes PNGs and prints one JSON line per image on stdout.

A process of its own because MuJoCo picks its OpenGL backend (`MUJOCO_GL`) when it is first
imported: the parent tries EGL, then OSMesa, each in a fresh process (`render.py`). Exit
status NO_GL means no OpenGL context could be made with the backend it was given.
"""

from __future__ import annotations

import json
import sys
import tempfile
from pathlib import Path

import numpy as np

from simkit.errors import SimkitError

NO_GL = 3


def _scenes(kits: list[str], workdir: Path) -> list:
    from simkit.diff import load_kit
    from simkit.review.scene import load_scene

    scenes = []
    for index, kit in enumerate(kits):
        sub = workdir / str(index)
        sub.mkdir()
        scenes.append(load_scene(load_kit(Path(kit)), sub, kit))
    return scenes


def _cameras(scenes: list, camera, size: tuple[int, int], poses: list[str]) -> dict:
    """One camera per pose, shared by every kit of the job (so OLD and NEW renders line up),
    fitted to the robot in that pose (issue 25: the robot fills the frame in every pose);
    the floor under the lowest point of any kit in any pose, and the key light's shadow box
    around everything seen."""
    import mujoco

    from simkit.review.scene import FLOOR, fit_camera, framing_points, posed_points

    fovy, aspect = float(scenes[0].model.vis.global_.fovy), size[0] / size[1]
    everything = np.concatenate([posed_points(s, mujoco.MjData(s.model))[0] for s in scenes])
    cameras = {}
    for pose in poses:
        found = [posed_points(s, mujoco.MjData(s.model), [pose]) for s in scenes if pose in s.poses]
        points = np.concatenate([p for p, _moving in found])
        moving = np.concatenate([m for _points, m in found])
        cameras[pose] = fit_camera(camera, framing_points(points, moving), fovy, aspect)
    lo, hi = everything.min(axis=0), everything.max(axis=0)
    floor_z = min(0.0, float(lo[2]))
    for scene in scenes:
        floor = mujoco.mj_name2id(scene.model, mujoco.mjtObj.mjOBJ_GEOM, FLOOR)
        scene.model.geom_pos[floor] = (0.0, 0.0, floor_z)
        # MuJoCo scales clip planes, shadow maps and the floor's grid by the model's extent:
        # one extent for all kits of the job, so an unchanged region renders the same pixels
        scene.model.stat.center[:] = (lo + hi) / 2
        scene.model.stat.extent = float(np.linalg.norm(hi - lo)) / 2
        for fitted in cameras.values():
            _place_shadows(scene.model, fitted, fovy, aspect, everything, floor_z)
    return cameras


#: extents: the widest shadow box (a camera looking level sees floor up to the horizon; the
#: box's 4096 texels would get too coarse for the robot's own shadows)
MAX_SHADOW_CLIP = 8.0


def _place_shadows(model, camera, fovy: float, aspect: float, points, floor_z: float) -> None:
    """The shadow-casting lights look at the model's centre from outside the robot, and their
    shadow box covers the robot and the floor in view (`scene.shadow_clip`)."""
    from simkit.review.scene import shadow_clip

    extent, centre = float(model.stat.extent), np.array(model.stat.center)
    for light in range(model.nlight):
        if not model.light_castshadow[light]:
            continue
        direction = np.array(model.light_dir[light])
        model.light_pos[light] = centre - direction * 3.0 * extent
        half = shadow_clip(camera, fovy, aspect, points, floor_z, centre, direction)
        clip = min(1.05 * half / extent, MAX_SHADOW_CLIP)
        model.vis.map.shadowclip = max(model.vis.map.shadowclip, clip)


def _renderer(scene, size: tuple[int, int]):
    """A MuJoCo Renderer, or exit NO_GL when the OpenGL backend cannot make a context."""
    import mujoco

    model = scene.model
    model.vis.global_.offwidth = max(model.vis.global_.offwidth, size[0])
    model.vis.global_.offheight = max(model.vis.global_.offheight, size[1])
    model.vis.quality.shadowsize = 4096
    model.vis.headlight.ambient[:] = 0.3
    model.vis.headlight.diffuse[:] = 0.25
    model.vis.headlight.specular[:] = 0.05
    model.vis.rgba.haze[:] = (0.3, 0.35, 0.42, 1.0)  # the horizon: between floor and sky
    try:
        return mujoco.Renderer(model, height=size[1], width=size[0])
    except Exception as exc:  # any backend failure: ImportError, RuntimeError, GL errors
        print(f"no OpenGL context: {type(exc).__name__}: {exc}", file=sys.stderr)
        sys.exit(NO_GL)


def render_image(scene, renderer, camera, pose: str, collision: bool) -> np.ndarray:
    """One (H, W, 3) uint8 image of a named pose."""
    import mujoco

    from simkit.review.scene import COLLISION_GROUP, collision_colours, pose_qpos

    model = scene.model
    collision_colours(scene, collision)
    data = mujoco.MjData(model)
    data.qpos[:] = pose_qpos(scene, pose)
    mujoco.mj_forward(model, data)
    cam = mujoco.MjvCamera()
    cam.type = mujoco.mjtCamera.mjCAMERA_FREE
    cam.azimuth, cam.elevation, cam.distance = camera.azimuth, camera.elevation, camera.distance
    cam.lookat[:] = camera.lookat
    option = mujoco.MjvOption()
    option.geomgroup[:] = 0
    option.geomgroup[0] = option.geomgroup[2] = 1
    option.geomgroup[COLLISION_GROUP] = int(collision)
    option.sitegroup[:] = 0
    renderer.update_scene(data, camera=cam, scene_option=option)
    shadowed = renderer.render().copy()
    renderer.scene.flags[mujoco.mjtRndFlag.mjRND_SHADOW] = 0
    plain = renderer.render().copy()
    renderer.scene.flags[mujoco.mjtRndFlag.mjRND_SHADOW] = 1
    return clean_shadows(shadowed, plain)


#: pixels: the median window that removes shadow-map speckle and keeps real shadows
SHADOW_WINDOW = 5


def clean_shadows(shadowed: np.ndarray, plain: np.ndarray) -> np.ndarray:
    """The shadowed image without shadow acne (issue 25): MuJoCo's shadow map, with the
    depth offset it uses where OpenGL lacks clip control (OSMesa), leaves isolated dark
    pixels on surfaces that face the light (rosie_1400's floor, about 780 per image). The
    shadow is taken as the per-pixel brightness ratio of the renders with and without
    shadows, median-filtered over SHADOW_WINDOW pixels (an isolated speckle goes, a shadow
    region and its edges stay), and applied to the render without shadows."""
    from scipy.ndimage import median_filter

    lum = np.array([0.299, 0.587, 0.114])
    ratio = (shadowed.astype(float) @ lum + 1.0) / (plain.astype(float) @ lum + 1.0)
    ratio = median_filter(np.clip(ratio, 0.0, 1.0), size=SHADOW_WINDOW, mode="nearest")
    return np.clip(np.rint(plain.astype(float) * ratio[..., None]), 0, 255).astype(np.uint8)


def run(job: dict) -> None:
    from simkit.review.png import write_png
    from simkit.review.scene import Camera, collision_signature

    size = (int(job["size"][0]), int(job["size"][1]))
    with tempfile.TemporaryDirectory(prefix="simkit-render-") as tmp:
        scenes = _scenes(job["kits"], Path(tmp))
        poses = list(dict.fromkeys(item["pose"] for item in job["items"]))
        cameras = _cameras(scenes, Camera.from_json(job["camera"]), size, poses)
        renderers = [_renderer(scene, size) for scene in scenes]
        try:
            for item in job["items"]:
                scene = scenes[item["kit"]]
                pixels = render_image(
                    scene,
                    renderers[item["kit"]],
                    cameras[item["pose"]],
                    item["pose"],
                    item["collision"],
                )
                write_png(Path(item["file"]), pixels)
                print(json.dumps({"file": item["file"]}), flush=True)
        finally:
            for renderer in renderers:
                renderer.close()
    signatures = [collision_signature(scene) for scene in scenes]
    views = {pose: camera.to_json() for pose, camera in cameras.items()}
    print(json.dumps({"cameras": views, "collision": signatures}), flush=True)


def probe() -> None:
    """Make one tiny render: exits NO_GL when this backend has no OpenGL context."""
    import mujoco

    from simkit.review.scene import KitScene

    model = mujoco.MjModel.from_xml_string("<mujoco><worldbody/></mujoco>")
    renderer = _renderer(KitScene("probe", model, {}, []), (16, 16))
    renderer.update_scene(mujoco.MjData(model))
    renderer.render()
    renderer.close()
    print(json.dumps({"cameras": {}, "collision": []}), flush=True)


def main() -> None:
    try:
        job = json.load(sys.stdin)
        probe() if job.get("probe") else run(job)
    except SimkitError as exc:
        print(f"simkit: error: {exc}", file=sys.stderr)
        sys.exit(exc.exit_code)


if __name__ == "__main__":
    main()
