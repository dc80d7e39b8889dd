"""Quickstart scripts in the kit's examples/: mujoco_demo.py, pybullet_demo.py, mjx_demo.py.

They follow the kit page's "Quickstart" snippets, with paths taken relative to the script so
they run from inside the kit folder (or anywhere) with only numpy plus mujoco or pybullet.
examples/fk_ik.py comes from the motion-data emitter.
"""

from __future__ import annotations

from simkit.emit import mjcf_world
from simkit.emit.templating import environment
from simkit.kitio import layout
from simkit.kitio.fmt import num
from simkit.model.robot import Robot

#: The pose the demos drive to: the first of these the spec names, else all zeros.
DEMO_POSES = ("work", "stretched", "home")


def _context(robot: Robot) -> dict:
    poses = dict(robot.poses)
    pose = next((name for name in DEMO_POSES if name in poses), None)
    names = [j.name for j in robot.movable_joints]
    values = poses[pose] if pose else (0.0,) * len(names)
    return {
        "spec": robot.spec_file,
        "title": robot.title,
        "pose": pose or "zero",
        "tool": robot.tool_frame,
        "tool_repr": repr(robot.tool_frame),
        # the file with the position servos (a second scene file for some robots)
        "mjcf": layout.mjcf(robot.name)
        if mjcf_world.servos_in_main(robot)
        else layout.mjcf_scene(robot.name),
        "mjx": layout.mjcf_mjx(robot.name),
        "urdf": layout.urdf(robot.name),
        "target": [(name, num(v)) for name, v in zip(names, values, strict=True)],
    }


def emit(robot: Robot) -> dict[str, bytes]:
    """`examples/mujoco_demo.py`, `examples/pybullet_demo.py` and, with a GPU scene,
    `examples/mjx_demo.py`."""
    env, ctx = environment(), _context(robot)
    plan = robot.products.gpu_scene
    gpu = plan is not None and "none" not in plan  # a kit without a GPU scene says why instead
    return {
        layout.example(name): env.get_template(f"examples/{name}.j2").render(ctx).encode("utf-8")
        for name in ("mujoco_demo.py", "pybullet_demo.py", "mjx_demo.py")
        if name != "mjx_demo.py" or gpu
    }
