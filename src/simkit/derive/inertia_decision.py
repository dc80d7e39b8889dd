"""Recorded decisions to keep a reported inertia tensor that is not physical.

The ECN 2R report's link_0 (002_e760a3794accbbd5.txt, Appendix 1) has Ixx + Iyy < Izz, which
no rigid body can have; MuJoCo refuses such a body and Gazebo's solvers misbehave. A spec may
keep it only with an explicit `inertia_decision` (spec_sim.InertiaDecisionSpec). The URDF and
MJCF then carry a balanced replacement: every principal moment set to their mean, which is what
MuJoCo's `compiler/balanceinertia` does (MuJoCo XML reference, compiler). The mean keeps the
trace, so the replacement is the isotropic tensor (trace / 3) * identity in any frame. Mass and
CoM stay as reported. robot.json records the reported tensor, the problem, the replacement and
the reason next to the link.
"""

from __future__ import annotations

from dataclasses import replace

from simkit.model.robot import InertiaDecision, Inertial, Robot
from simkit.spec.schema import InertiaSpec, LinkSpec
from simkit.spec.validate import inertia_problem

Tensor6 = tuple[float, float, float, float, float, float]


def decision_of(link: LinkSpec) -> InertiaDecision | None:
    """The model's record of a link's decision (resolve stage); None without one."""
    decision, inertia = link.inertia_decision, link.inertia
    if decision is None or inertia is None:
        return None
    reported = (inertia.ixx, inertia.iyy, inertia.izz, inertia.ixy, inertia.ixz, inertia.iyz)
    return InertiaDecision(
        action=decision.action,
        reason=decision.reason,
        reported=reported,
        problem=inertia_problem(inertia) or "",
    )


def balanced(tensor: Tensor6) -> Tensor6:
    """Every principal moment set to their mean (MuJoCo's balanceinertia): (trace/3) * I."""
    mean = (tensor[0] + tensor[1] + tensor[2]) / 3.0
    return (mean, mean, mean, 0.0, 0.0, 0.0)


def derive_inertia_decisions(robot: Robot) -> Robot:
    """Put the balanced replacement into each decided link's inertial (what the URDF and MJCF
    write) and record it in the decision."""
    links = []
    for link in robot.links:
        decision = link.inertia_decision
        if decision is None or link.inertial is None:
            links.append(link)
            continue
        emitted = balanced(decision.reported)
        if inertia_problem(
            InertiaSpec(
                **dict(zip(("ixx", "iyy", "izz", "ixy", "ixz", "iyz"), emitted, strict=True))
            )
        ):
            raise ValueError(f"balanced inertia of {link.name} is still not physical")
        inertial = Inertial(link.inertial.mass, link.inertial.com, emitted)
        links.append(
            replace(link, inertial=inertial, inertia_decision=replace(decision, emitted=emitted))
        )
    return replace(robot, links=tuple(links))


def record(decision: InertiaDecision) -> dict:
    """The decision as robot.json writes it next to the link."""
    keys = ("ixx", "iyy", "izz", "ixy", "ixz", "iyz")
    return {
        "action": decision.action,
        "reason": decision.reason,
        "problem": decision.problem,
        "reported": dict(zip(keys, decision.reported, strict=True)),
        "emitted": dict(zip(keys, decision.emitted, strict=True)) if decision.emitted else None,
        "rule": "emitted = every principal moment set to their mean (MuJoCo balanceinertia); "
        "mass and CoM as reported",
    }
