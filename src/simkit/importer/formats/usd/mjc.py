"""MuJoCo's compiler settings that a USD keeps in the MjcPhysics schema (mujoco-usd-converter
writes them on the PhysicsScene) and that change the robot's mass properties.

`mjc:compiler:setTotalMass` (MJCF `<compiler settotalmass>`): MuJoCo scales every body's
mass and inertia by one factor so that the model's total mass is that value (kg). The
converter writes the bodies' UsdPhysics masses unscaled (from the geoms' density) and the
setting beside them, so the robot the USD describes to MuJoCo, its author's robot, is the
scaled one: the import applies the factor to every link's inertial. The total is the whole
model's, so with a rigid body on the stage that is not the robot's (its mass unknown here)
the factor is not known: left unapplied and listed.
"""

from __future__ import annotations

from dataclasses import replace

from simkit.importer.read.model import Link

#: the MjcSceneAPI attribute: the model's total mass (kg; <= 0: not set)
TOTAL_MASS = "mjc:compiler:setTotalMass"


def total_mass(stage) -> float:
    """The stage's MjcPhysics total mass in kg (0: none), read from its PhysicsScene."""
    from pxr import UsdPhysics

    for prim in stage.Traverse():
        if prim.IsA(UsdPhysics.Scene):
            attr = prim.GetAttribute(TOTAL_MASS)
            if attr and attr.HasAuthoredValue() and float(attr.Get()) > 0:
                return float(attr.Get())
    return 0.0


def scale_to_total(links: list[Link], art, kilograms: float, listed: list) -> list[Link]:
    """The `links` with each inertial's mass and inertia scaled so the masses sum to the total
    mass of the stage of `art` (stage.Articulation; `kilograms`: kg per stage mass unit);
    list what was done or why not."""
    total = total_mass(art.stage) * kilograms
    if total <= 0:
        return links
    masses = [link.inertial.mass for link in links if link.inertial is not None]
    if not _robot_only(art) or sum(masses) <= 0:
        why = "not applied: the stage has rigid bodies that are not the robot's"
        listed.append(("links.mass", f"MjcPhysics {TOTAL_MASS} {total:g} kg {why}"))
        return links
    factor = total / sum(masses)
    out = []
    for link in links:
        inertial = link.inertial
        if inertial is not None:
            inertia = inertial.inertia
            if inertia is not None:
                inertia = tuple(float(v * factor) for v in inertia)
            inertial = replace(inertial, mass=float(inertial.mass * factor), inertia=inertia)
            why = f"scaled by {factor:.9g}: MjcPhysics {TOTAL_MASS} {total:g} kg (MuJoCo's rule)"
            listed.extend([(f"links.{link.name}.mass", why), (f"links.{link.name}.inertia", why)])
        out.append(replace(link, inertial=inertial))
    return out


def _robot_only(art) -> bool:
    """Whether every rigid body on the stage is one of the robot's."""
    from pxr import Usd, UsdPhysics

    mine = set(art.bodies)
    every = Usd.PrimRange(art.stage.GetPseudoRoot(), Usd.TraverseInstanceProxies())
    return all(str(p.GetPath()) in mine for p in every if p.HasAPI(UsdPhysics.RigidBodyAPI))
