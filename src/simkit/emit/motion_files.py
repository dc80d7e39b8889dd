"""Motion-data files of an arm kit: ik_cases.json, the 1 kg benchmark cycle (CSV and JSON)
and examples/fk_ik.py. They format what the motion derive step (`motion.derive_motion`)
put in `robot.products`; a robot without those products gets none of these files.

Source: 000_5f76ade803e16979.txt, "What a kit contains", "Benchmark cycle" and "IK reference
cases".
"""

from __future__ import annotations

from simkit.emit.templating import environment
from simkit.kitio import layout
from simkit.kitio.fmt import num
from simkit.kitio.jsonout import dumps
from simkit.model.robot import Robot

FK_IK = "fk_ik.py"


def columns(joints: list[str]) -> list[str]:
    """CSV header: time, q, qd and qdd per joint, then the TCP in base_link."""
    return (
        ["t"]
        + [f"q_{j}" for j in joints]
        + [f"qd_{j}" for j in joints]
        + [f"qdd_{j}" for j in joints]
        + ["tcp_x", "tcp_y", "tcp_z"]
    )


def trajectory_csv(traj: dict) -> bytes:
    """One row per sample; units s, rad, rad/s, rad/s^2 and m."""
    lines = [",".join(columns(traj["joints"]))]
    for t, q, qd, qdd, tcp in zip(
        traj["t"], traj["q"], traj["qd"], traj["qdd"], traj["tcp"], strict=True
    ):
        values = [t, *q, *qd, *qdd, *tcp]
        lines.append(",".join(num(v) for v in values))
    return ("\n".join(lines) + "\n").encode("utf-8")


def trajectory_json(traj: dict) -> bytes:
    """The same samples as the CSV, as arrays, with the segment table."""
    return dumps(
        {
            "robot": traj["robot"],
            "cycle": traj["cycle"],
            "payload_kg": traj["payload_kg"],
            "dt": traj["dt"],
            "units": {"t": "s", "q": "rad", "qd": "rad/s", "qdd": "rad/s^2", "tcp": "m, base_link"},
            "joints": traj["joints"],
            "segments": traj["segments"],
            "t": traj["t"],
            "q": traj["q"],
            "qd": traj["qd"],
            "qdd": traj["qdd"],
            "tcp": traj["tcp"],
        }
    )


def fk_ik_script(robot: Robot, base: str) -> bytes:
    ctx = {
        "title": robot.title,
        "spec": robot.spec_file,
        "tool": robot.tool_frame,
        "base": base,
        "robot_json": layout.ROBOT_JSON,
        "ik_cases": layout.IK_CASES,
    }
    return environment().get_template(f"examples/{FK_IK}.j2").render(ctx).encode("utf-8")


def emit(robot: Robot) -> dict[str, bytes]:
    """`ik_cases.json`, `benchmark/NAME_cycle_1kg.{csv,json}` and `examples/fk_ik.py`."""
    out: dict[str, bytes] = {}
    cases = robot.products.ik_cases
    if cases is not None:
        out[layout.IK_CASES] = dumps(cases)
        out[layout.example(FK_IK)] = fk_ik_script(robot, cases["chain"]["base"])
    traj = robot.products.benchmark_trajectory
    if traj is not None:
        out[layout.benchmark(robot.name, "csv")] = trajectory_csv(traj)
        out[layout.benchmark(robot.name, "json")] = trajectory_json(traj)
    return out
