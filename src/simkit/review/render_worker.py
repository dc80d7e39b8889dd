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


def _shared_camera(scenes: list, camera, size: tuple[int, int]):
    """One camera for every kit of the job (so OLD and NEW renders line up), and the floor
    under the lowest point of any of them."""
    import mujoco

    from simkit.review.scene import FLOOR, fit_camera, robot_points

    points = np.concatenate([robot_points(s, mujoco.MjData(s.model)) for s in scenes])
    lo, hi = points.min(axis=0), points.max(axis=0)
    for scene in scenes:
        floor = mujoco.mj_name2id(scene.model, mujoco.mjtObj.mjOBJ_GEOM, FLOOR)
        scene.model.geom_pos[floor] = (0.0, 0.0, min(0.0, float(lo[2])))
        # MuJoCo scales clip planes, shadow maps and the floor's grid by the model's extent:
        # one extent for all kits of the job, so an unchanged region renders the same pixels
        scene.model.stat.center[:] = (lo + hi) / 2
        scene.model.stat.extent = float(np.linalg.norm(hi - lo)) / 2
    fovy = float(scenes[0].model.vis.global_.fovy)
    return fit_camera(camera, points, fovy, size[0] / size[1])


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
    model.vis.rgba.haze[:] = (0.9, 0.92, 0.95, 1.0)
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
    return renderer.render().copy()


def run(job: dict) -> None:
    from simkit.review.png import write_png
    from simkit.review.scene import Camera, collision_signature

    size = (int(job["size"][0]), int(job["size"][1]))
    with tempfile.TemporaryDirectory(prefix="simkit-render-") as tmp:
        scenes = _scenes(job["kits"], Path(tmp))
        camera = _shared_camera(scenes, Camera.from_json(job["camera"]), size)
        renderers = [_renderer(scene, size) for scene in scenes]
        try:
            for item in job["items"]:
                scene = scenes[item["kit"]]
                pixels = render_image(
                    scene, renderers[item["kit"]], camera, item["pose"], item["collision"]
                )
                write_png(Path(item["file"]), pixels)
                print(json.dumps({"file": item["file"]}), flush=True)
        finally:
            for renderer in renderers:
                renderer.close()
    signatures = [collision_signature(scene) for scene in scenes]
    print(json.dumps({"camera": camera.to_json(), "collision": signatures}), flush=True)


def probe() -> None:
    """Make one tiny render: exits NO_GL when this backend has no OpenGL context."""
    import mujoco

    from simkit.review.scene import KitScene

    model = mujoco.MjModel.from_xml_string("<mujoco><worldbody/></mujoco>")
    renderer = _renderer(KitScene("probe", model, {}, []), (16, 16))
    renderer.update_scene(mujoco.MjData(model))
    renderer.render()
    renderer.close()
    print(json.dumps({"camera": None, "collision": []}), flush=True)


def main() -> None:
    try:
        job = json.load(sys.stdin)
        probe() if job.get("probe") else run(job)
    except SimkitError as exc:
        print(f"simkit: error: {exc}", file=sys.stderr)
        sys.exit(exc.exit_code)


if __name__ == "__main__":
    main()
