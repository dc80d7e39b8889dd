"""Derive step for wrist-partitioned 6R arms (`ik.arm_chain`): IK reference cases, peak-torque
accelerations and the benchmark cycles (kit page 000_5f76ade803e16979.txt, "IK reference
cases", "Accelerations and motion profiles", "Benchmark cycle"). Any other robot is returned
unchanged. The benchmark's inverse dynamics on the kit's MJCF runs later, in the simulate
stage (`simulate/benchmark.py`), on the written file."""

from __future__ import annotations

from dataclasses import replace

from simkit.derive import benchmark, ik_cases, motion
from simkit.derive.self_contact import depth_function
from simkit.kitio import layout
from simkit.model import ik
from simkit.model.ik import ArmChain
from simkit.model.robot import Robot


def derive_motion(robot: Robot) -> Robot:
    """IK cases (ik_cases.json, robot.json `ik_reference`); with torques, speeds and the
    stretched and work poses, the accelerations (`motion`, joints[].derived_max_acceleration);
    with servos on every chain joint, the benchmark cycles (`benchmarks`, the 1 kg files)."""
    arm = ik.arm_chain(robot)
    if arm is None:
        return robot
    robot = _ik_cases(robot, arm)
    joints = [robot.joint(n) for n in arm.names]
    if any(j.effort_peak is None or j.max_velocity is None for j in joints):
        return robot
    if not {"stretched", "work"} <= dict(robot.poses).keys():
        return robot
    robot = _accelerations(robot, arm)
    if {a.joint for a in robot.actuators} >= set(arm.names):
        robot = _benchmark(robot, arm)
    return robot


def _ik_cases(robot: Robot, arm: ArmChain) -> Robot:
    # seeds and expected solutions free of self-contact (issue 12), on the model's own
    # collision geometry in memory
    depth = depth_function(robot, list(arm.names))
    cases = ik_cases.cases_document(robot, arm, depth)
    reference = {
        "file": layout.IK_CASES,
        "cases": len(cases["cases"]),
        "chain": {"base": arm.base, "tip": arm.tool, "joints": list(arm.names)},
        "solver": {k: cases["solver"][k] for k in ("name", "method", "provenance")},
        "branch_flags": ik.BRANCH_FLAGS,
        "tolerance": ik_cases.TOLERANCE,
    }
    seeds = {**robot.products.seeds, "ik_cases": robot.seed}
    products = replace(robot.products, ik_cases=cases, ik_reference=reference, seeds=seeds)
    return replace(robot, products=products)


def _accelerations(robot: Robot, arm: ArmChain) -> Robot:
    block, per_joint = motion.motion_block(robot, arm)
    joint_motion = dict(robot.products.joint_motion)
    for name, extra in per_joint.items():
        joint_motion[name] = {**joint_motion.get(name, {}), **extra}
    return replace(robot, products=replace(robot.products, motion=block, joint_motion=joint_motion))


def _benchmark(robot: Robot, arm: ArmChain) -> Robot:
    cycles = [
        benchmark.cycle(robot, arm, "cycle_1kg", motion.WORK_PAYLOAD),
        benchmark.cycle(robot, arm, "cycle_rated", motion.rated_payload(robot)),
    ]
    samples = {
        "joints": list(arm.names),
        "link": arm.children[5],
        "cycles": {
            c.name: {
                "payload": benchmark.payload_on_link(arm, c.payload),
                "q": c.q,
                "qd": c.qd,
                "qdd": c.qdd,
            }
            for c in cycles
        },
    }
    products = replace(
        robot.products,
        benchmarks=benchmark.benchmarks_block(robot, arm, cycles),
        benchmark_cycles=samples,
        benchmark_trajectory=benchmark.trajectory_data(robot, arm, cycles[0]),
    )
    return replace(robot, products=products)
