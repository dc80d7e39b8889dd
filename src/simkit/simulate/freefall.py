"""Free-fall validation: the ECN report's fidelity test, automated.

Report 002_e760a3794accbbd5.txt, section 4 step 4: release the arm from rest under gravity and
superimpose the joint angles of two independent simulations. Here three are compared:

- `mjcf`: MuJoCo on the kit's MJCF;
- `urdf`: MuJoCo on the kit's URDF, with each joint's armature from robot.json (URDF has no
  armature element, so a URDF reader cannot know the motor's reflected inertia);
- `independent`: `rnea.py`, recursive Newton-Euler dynamics written from the model alone,
  integrated with scipy's solve_ivp (DOP853).

Both MuJoCo models step with RK4 at the MJCF's timestep (the files' own first-order
integrators drift ~2e-3 rad over 2 s on this swing; robot.json records that figure too), with
the actuators disabled (a free fall) and everything else as written.

Friction: MuJoCo's `frictionloss` is a soft constraint whose sign follows the acceleration the
joint would have, not only its velocity, so it turns earlier than ideal Coulomb friction around
each velocity reversal. So two runs are compared, each with friction handled the same way on
all three sides: `rigid` (friction off everywhere: the rigid-body model, mounting and armature)
and `friction` (the spec's friction on every side: MuJoCo's frictionloss against regularised
Coulomb friction). Both must stay under the spec's RMS bound.

The simulate stage runs all this on the staged kit's MJCF and URDF; `check/freefall.py` runs
the MuJoCo side again on the written kit and holds it to the recorded independent trajectory.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np

from simkit.errors import SpecError
from simkit.kitio import layout
from simkit.kitio.cache import library_versions
from simkit.kitio.fmt import rounded
from simkit.model import rnea
from simkit.model.robot import Robot
from simkit.simulate.loaders import load_mjcf_file, load_urdf_file

SAMPLE_DT = 0.01  # s: trajectories are compared, stored and plotted every 10 ms
RUNS = ("rigid", "friction")
SIDES = ("independent", "mjcf", "urdf")
PAIRS = (("mjcf", "independent"), ("urdf", "independent"), ("mjcf", "urdf"))
#: dynamics evaluations per independent run: ecn_2r's 2 s swing takes about 3,900 (0.5 ms
#: each); joint friction of 10 N m makes the regularised Coulomb term stiff and takes 690,000
#: (250 s), so the budget refuses such a setup within about 20 s
MAX_EVALS = 40_000
#: MuJoCo RK4 steps per run (duration / timestep): 2 s at ecn_2r's 1 ms is 2,000
MAX_MUJOCO_STEPS = 200_000


def sample_times(duration: float) -> np.ndarray:
    """0, 10 ms, ... duration (s)."""
    return np.arange(round(duration / SAMPLE_DT) + 1) * SAMPLE_DT


Joints = list[tuple[str, float]]  # (name, armature in kg m^2) of every movable joint


def load_models(mjcf: Path, urdf: Path, joints: Joints) -> dict:
    """MuJoCo models of the kit's MJCF and URDF; the URDF one gets each joint's armature
    (as robot.json publishes it: URDF has no armature element)."""
    models = {"mjcf": load_mjcf_file(mjcf), "urdf": load_urdf_file(urdf)}
    urdf_model = models["urdf"]
    for name, armature in joints:
        urdf_model.dof_armature[urdf_model.jnt_dofadr[urdf_model.joint(name).id]] = armature
    return models


def simulate(
    model, names: list[str], q0, duration: float, timestep: float, friction: bool
) -> np.ndarray:
    """Joint angles (rad) every SAMPLE_DT after release from rest at q0: RK4 at `timestep`,
    actuators off, frictionloss as in the file or zero. Shape (samples, joints)."""
    import mujoco

    model.opt.integrator = mujoco.mjtIntegrator.mjINT_RK4
    model.opt.timestep = timestep
    model.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_ACTUATION)
    if not friction:
        model.dof_frictionloss[:] = 0.0
    return _step(model, names, q0, duration)


def _step(model, names: list[str], q0, duration: float) -> np.ndarray:
    import mujoco

    data = mujoco.MjData(model)
    qpos = [int(model.jnt_qposadr[model.joint(n).id]) for n in names]
    data.qpos[qpos] = q0
    mujoco.mj_forward(model, data)
    per_sample = round(SAMPLE_DT / model.opt.timestep)
    out = [data.qpos[qpos].copy()]
    for _ in range(len(sample_times(duration)) - 1):
        for _ in range(per_sample):
            mujoco.mj_step(model, data)
        out.append(data.qpos[qpos].copy())
    return np.array(out)


def rms(a: np.ndarray, b: np.ndarray) -> float:
    """Joint-angle RMS difference over all samples and joints (rad)."""
    return float(np.sqrt(np.mean((np.asarray(a) - np.asarray(b)) ** 2)))


def _frictionless(robot: Robot) -> Robot:
    return replace(robot, joints=tuple(replace(j, friction=0.0) for j in robot.joints))


def _budget(spec_file: str, duration: float, timestep: float) -> None:
    """Refuse, before any step, a MuJoCo run longer than MAX_MUJOCO_STEPS."""
    if duration / timestep > MAX_MUJOCO_STEPS:
        raise SpecError(
            spec_file,
            None,
            "freefall.duration",
            f"{duration:g} s at a {timestep:g} s timestep is more than the free-fall budget of "
            f"{MAX_MUJOCO_STEPS} steps per run",
        )


def _integrate(robot: Robot, q0, duration: float, times: np.ndarray, run: str) -> np.ndarray:
    try:
        return rnea.integrate(robot, q0, duration, times, max_evals=MAX_EVALS)
    except rnea.EvaluationBudget:
        friction = max((j.friction for j in robot.movable_joints), default=0.0)
        raise SpecError(
            robot.spec_file,
            None,
            "freefall",
            f"the independent free-fall integration ({run} run) needs more than its budget "
            f"of {MAX_EVALS} dynamics evaluations (a stiff setup: joint friction up to "
            f"{friction:g} N m); lower the friction or shorten freefall.duration",
        ) from None


def _independent(robot: Robot, q0, duration: float) -> dict[str, np.ndarray]:
    """Both runs of the independent integration, checked against the joint limits."""
    times = sample_times(duration)
    out = {
        "rigid": _integrate(_frictionless(robot), q0, duration, times, "rigid"),
        "friction": _integrate(robot, q0, duration, times, "friction"),
    }
    for run, traj in out.items():
        for k, joint in enumerate(robot.movable_joints):
            if joint.lower is None or joint.type == "continuous":
                continue
            outside = (traj[:, k] < joint.lower) | (traj[:, k] > joint.upper)
            if outside.any():
                t = float(times[int(np.argmax(outside))])
                raise SpecError(
                    robot.spec_file,
                    None,
                    "freefall.pose",
                    (
                        f"released at '{robot.freefall.pose}', {joint.name} leaves its limits at "
                        f"t = {t:.2f} s ({run} run); choose a pose that swings inside the limits"
                    ),
                )
    return out


def mujoco_runs(
    mjcf: Path, urdf: Path, joints: Joints, q0, duration: float, spec_file: str = ""
) -> tuple[dict, float, dict]:
    """MuJoCo trajectories {run: {"mjcf": Q, "urdf": Q}}, the timestep used (the MJCF's), and
    the MJCF's own integrator name and rigid-run trajectory (informational)."""
    import mujoco

    names = [name for name, _ in joints]
    timestep = float(load_mjcf_file(mjcf).opt.timestep)
    _budget(spec_file or str(mjcf), duration, timestep)
    runs: dict = {}
    for run in RUNS:
        models = load_models(mjcf, urdf, joints)
        runs[run] = {
            side: simulate(models[side], names, q0, duration, timestep, friction=run == "friction")
            for side in ("mjcf", "urdf")
        }
    own = load_mjcf_file(mjcf)
    own.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_ACTUATION)
    own.dof_frictionloss[:] = 0.0
    integrator = mujoco.mjtIntegrator(int(own.opt.integrator)).name.removeprefix("mjINT_")
    return runs, timestep, {"integrator": integrator, "rigid": _step(own, names, q0, duration)}


def figures(trajectories: dict) -> dict:
    """RMS and worst absolute joint-angle difference (rad) for every pair in every run."""
    out: dict = {}
    for run in RUNS:
        sides = trajectories[run]
        out[run] = {
            f"{a}_vs_{b}": {
                "rms": rms(sides[a], sides[b]),
                "max_abs": float(np.max(np.abs(sides[a] - sides[b]))),
            }
            for a, b in PAIRS
        }
    return out


def run(kit_dir: Path, robot: Robot) -> dict | None:
    """The three simulations for a spec with a `freefall:` section, on the staged kit:
    {"record": robot.json `validation.freefall`, "data": what emit/freefall_files.py writes}.
    None without the section. A run over the bound is not an error here: the check fails."""
    setup = robot.freefall
    if setup is None:
        return None
    q0 = np.asarray(robot.pose(setup.pose), float)
    independent = _independent(robot, q0, setup.duration)
    # armature as robot.json publishes it (10 significant digits), as a URDF user reads it
    joints = [(j.name, rounded(j.armature)) for j in robot.movable_joints]
    runs, timestep, own = mujoco_runs(
        kit_dir / layout.mjcf(robot.name),
        kit_dir / layout.urdf(robot.name),
        joints,
        q0,
        setup.duration,
        robot.spec_file,
    )
    trajectories = {run: {"independent": independent[run], **runs[run]} for run in RUNS}
    numbers = figures(trajectories)
    worst = max(v["rms"] for run in numbers.values() for v in run.values())
    names = [j.name for j in robot.movable_joints]
    record = {
        "test": "release from rest under gravity (report 002_e760a3794accbbd5.txt, section 4 "
        "step 4); joint angles of three simulations compared every sample_dt",
        "pose": setup.pose,
        "q0": [float(v) for v in q0],
        "joints": names,
        "duration": setup.duration,
        "sample_dt": SAMPLE_DT,
        "tolerance_rms": setup.tolerance_rms,
        "unit": "rad",
        "sides": {
            "independent": f"rnea.py: recursive Newton-Euler from the spec's model, scipy "
            f"solve_ivp DOP853 (rtol {rnea.RTOL:g}, atol {rnea.ATOL:g}); Coulomb friction "
            f"regularised as f tanh(qd / {rnea.FRICTION_SPEED:g} rad/s)",
            "mjcf": f"MuJoCo on the MJCF, RK4 at {timestep:g} s, actuators disabled",
            "urdf": f"MuJoCo on the URDF, RK4 at {timestep:g} s, armature from robot.json "
            "(URDF has no armature element)",
        },
        "runs": {
            "rigid": {"friction": "off on every side", **numbers["rigid"]},
            "friction": {
                "friction": "the spec's joint friction on every side (MuJoCo "
                "frictionloss; Coulomb in the independent integration)",
                **numbers["friction"],
            },
        },
        "mjcf_own_integrator": {
            "integrator": own["integrator"],
            "timestep": timestep,
            "rigid_rms_vs_independent": rms(own["rigid"], independent["rigid"]),
            "note": "informational: the MJCF's own integrator at its own timestep",
        },
        "libraries": library_versions(("scipy", "mujoco", "matplotlib")),
        "worst_rms": worst,
        "passed": worst < setup.tolerance_rms,
        "files": {"csv": layout.freefall_csv(), "plot": layout.freefall_plot()},
    }
    data = {
        "t": sample_times(setup.duration),
        "joints": names,
        "trajectories": trajectories,
        "figures": numbers,
        "tolerance_rms": setup.tolerance_rms,
    }
    return {"record": record, "data": data}
