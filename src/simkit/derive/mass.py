"""Link mass properties: from the solid scaled to the link mass unless the spec gives them,
and recorded decisions to keep a reported inertia tensor that is not physical.

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

from simkit.errors import SpecError
from simkit.model import inertia
from simkit.model.robot import Inertial, Robot
from simkit.spec.schema import InertiaSpec
from simkit.spec.validate import inertia_problem

Tensor6 = tuple[float, float, float, float, float, float]


def derive_mass(robot: Robot) -> Robot:
    """CoM and inertia from the solid scaled to the link mass, unless the spec gives them."""
    links = []
    for link in robot.links:
        if link.inertial is None:
            try:
                link = replace(link, inertial=inertia.from_solid(link.solid, link.mass))
            except ValueError as exc:  # e.g. subtract removed the whole solid
                raise SpecError(link.name, None, "solid", f"link '{link.name}': {exc}") from None
        links.append(link)
    return replace(robot, links=tuple(links))


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
