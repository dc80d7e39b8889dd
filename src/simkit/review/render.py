"""`simkit render KIT|ZIP --out DIR`: one PNG per named pose, drawn by MuJoCo's offscreen
renderer from the kit's MJCF (floor, two lights, the kit's materials, a camera framing the
robot in each pose, its fixtures only near it; `--collision` adds the collision geometry,
translucent).

Headless: the render process (`render_worker`) runs with `MUJOCO_GL=egl`, and when EGL gives
no context, with `MUJOCO_GL=osmesa` (Debian's `libosmesa6`). A `MUJOCO_GL` of egl or osmesa in
the environment is tried first. Same kit, same machine: same pixels, same PNG bytes.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import tempfile
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

import simkit
from simkit.errors import SimkitError
from simkit.review.scene import Camera, named_poses

BACKENDS = ("egl", "osmesa")
NO_GL_HINT = (
    "no OpenGL for offscreen rendering (tried MUJOCO_GL=egl and osmesa): "
    "install Debian's libosmesa6 (apt-get install libosmesa6)"
)
DEFAULT_SIZE = (640, 480)
DEFAULT_CAMERA = Camera()
#: the backend that worked in this process, tried first next time
_working: list[str] = []

OnImage = Callable[[Path], None]


@dataclass(frozen=True)
class Item:
    """One image: kit index into the job's kits, pose name, collision shown, output file."""

    kit: int
    pose: str
    collision: bool
    file: Path


def _order() -> list[str]:
    wanted = os.environ.get("MUJOCO_GL", "").strip().lower()
    first = [*_working, wanted] if wanted in BACKENDS else list(_working)
    return list(dict.fromkeys([*first, *BACKENDS]))


def _env(backend: str) -> dict[str, str]:
    env = dict(os.environ, MUJOCO_GL=backend, PYOPENGL_PLATFORM=backend)
    src = str(Path(simkit.__file__).resolve().parents[1])  # this simkit, also from a worktree
    env["PYTHONPATH"] = os.pathsep.join(p for p in (src, env.get("PYTHONPATH")) if p)
    return env


def _attempt(backend: str, job: dict, on_image: OnImage | None) -> tuple[int, str, dict]:
    proc = subprocess.Popen(
        [sys.executable, "-m", "simkit.review.render_worker"],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=_env(backend),
    )
    assert proc.stdin is not None and proc.stdout is not None and proc.stderr is not None
    proc.stdin.write(json.dumps(job))
    proc.stdin.close()
    result: dict = {}
    for line in proc.stdout:
        msg = json.loads(line)
        if "file" in msg and on_image is not None:
            on_image(Path(msg["file"]))
        result.update(msg)
    err = proc.stderr.read()
    return proc.wait(), err, result


def _first_working(job: dict, on_image: OnImage | None = None) -> tuple[str, dict]:
    """Run `job` with the first backend that makes an OpenGL context: (backend, result)."""
    from simkit.review.render_worker import NO_GL

    for backend in _order():
        code, err, result = _attempt(backend, job, on_image)
        if code == NO_GL:
            continue
        if code != 0:
            lines = [ln for ln in err.strip().splitlines() if ln.strip()] or ["no message"]
            last = lines[-1].removeprefix("simkit: error: ")
            raise SimkitError(f"render failed (MUJOCO_GL={backend}): {last}")
        if backend not in _working:
            _working.insert(0, backend)
        return backend, result
    raise SimkitError(NO_GL_HINT)


def gl_backend() -> str | None:
    """The MUJOCO_GL backend that renders on this machine (egl or osmesa), None if neither."""
    try:
        return _first_working({"probe": True})[0]
    except SimkitError:
        return None


def run_job(
    kits: Sequence[Path],
    items: Sequence[Item],
    size: tuple[int, int] = DEFAULT_SIZE,
    camera: Camera = DEFAULT_CAMERA,
    on_image: OnImage | None = None,
) -> dict:
    """Render `items` in one process, with one camera per pose fitted to all `kits` in that
    pose. Returns the cameras (`cameras`, pose -> Camera) and each kit's collision geometry
    hash (`collision`)."""
    job = {
        "kits": [str(k) for k in kits],
        "size": list(size),
        "camera": camera.to_json(),
        "items": [
            {"kit": i.kit, "pose": i.pose, "collision": i.collision, "file": str(i.file)}
            for i in items
        ],
    }
    _backend, result = _first_working(job, on_image)
    cameras = {pose: Camera.from_json(doc) for pose, doc in result["cameras"].items()}
    return {"cameras": cameras, "collision": result["collision"]}


def kit_poses(kit: Path) -> dict[str, list[float]]:
    """Named poses of a kit folder or zip (robot.json)."""
    from simkit.diff import load_kit

    return named_poses(json.loads(load_kit(kit)["robot.json"]))


def render_kit(
    kit: Path,
    out_dir: Path,
    poses: Sequence[str] | None = None,
    size: tuple[int, int] = DEFAULT_SIZE,
    camera: Camera = DEFAULT_CAMERA,
    collision: bool = False,
    on_image: OnImage | None = None,
) -> list[Path]:
    """`out_dir/<pose>.png` for each pose (default: every named pose). Files appear only when
    every image rendered; each pose's camera frames the robot in that pose."""
    known = kit_poses(kit)
    wanted = list(poses) if poses else list(known)
    missing = [p for p in wanted if p not in known]
    if missing:
        raise SimkitError(
            f"{kit}: no pose {missing[0]!r} in robot.json (poses: {', '.join(known)})"
        )
    out_dir.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(dir=out_dir.parent, prefix=".simkit-render-") as tmp:
        items = [Item(0, p, collision, Path(tmp) / f"{p}.png") for p in dict.fromkeys(wanted)]
        run_job([kit], items, size, camera, on_image)
        out_dir.mkdir(exist_ok=True)
        paths = []
        for item in items:
            target = out_dir / item.file.name
            shutil.move(item.file, target)
            paths.append(target)
    return paths
