"""The USD reader gives the source model itself (importer/formats/usd/tree.py, issue 39):
`read` sets `source.robot` with its numbers as plain floats (no text round trip) and no
source lines (a stage has none), the kept document the source differences read is that
model written as a URDF (and reads back to it), and a number that is not finite is refused
in one line where the URDF reader refused it (formats/finite.py, in formats.load)."""

from __future__ import annotations

import shutil
from dataclasses import replace

import pytest

import model_numbers
from simkit.errors import SpecError
from simkit.importer import formats
from simkit.importer import read as read_shell
from simkit.importer.diagnostics import Policy, Report
from simkit.importer.formats import usd
from simkit.importer.formats.urdf.model import robot_of
from simkit.importer.read.model import Robot
from simkit.importer.read.options import ReadOptions

pytest.importorskip("pxr")

#: `base` bolted to the world (its mass from its collider's own MassAPI), `arm` on a revolute
#: hinge (limits, drive force, MjcPhysics damping: DAMPING), `tip` on a follower of it
#: (NewtonMimicAPI), a coloured sphere visual on the arm
STAGE = """#usda 1.0
(
    defaultPrim = "bot"
    metersPerUnit = 1
    kilogramsPerUnit = 1
    upAxis = "Z"
)

def Xform "bot" (prepend apiSchemas = ["PhysicsArticulationRootAPI"])
{
    def Xform "base" (prepend apiSchemas = ["PhysicsRigidBodyAPI"])
    {
        def Cube "box" (prepend apiSchemas = ["PhysicsCollisionAPI", "PhysicsMassAPI"])
        {
            double size = 0.1
            float physics:mass = 3
        }
    }
    def Xform "arm" (prepend apiSchemas = ["PhysicsRigidBodyAPI", "PhysicsMassAPI"])
    {
        double3 xformOp:translate = (0, 0, 0.5)
        uniform token[] xformOpOrder = ["xformOp:translate"]
        float physics:mass = 1
        float3 physics:diagonalInertia = (0.01, 0.02, 0.03)
        def Sphere "ball"
        {
            double radius = 0.05
            color3f[] primvars:displayColor = [(0.2, 0.4, 0.6)]
        }
    }
    def Xform "tip" (prepend apiSchemas = ["PhysicsRigidBodyAPI", "PhysicsMassAPI"])
    {
        double3 xformOp:translate = (0, 0, 0.8)
        uniform token[] xformOpOrder = ["xformOp:translate"]
        float physics:mass = 0.5
        float3 physics:diagonalInertia = (0.001, 0.001, 0.001)
    }
    def PhysicsFixedJoint "world_joint"
    {
        rel physics:body1 = </bot/base>
    }
    def PhysicsRevoluteJoint "hinge"
    {
        rel physics:body0 = </bot/base>
        rel physics:body1 = </bot/arm>
        point3f physics:localPos0 = (0, 0, 0.5)
        uniform token physics:axis = "Y"
        float physics:lowerLimit = -90
        float physics:upperLimit = 45
        float drive:angular:physics:maxForce = 20
        double mjc:damping = DAMPING
    }
    def PhysicsRevoluteJoint "follow" (prepend apiSchemas = ["NewtonMimicAPI"])
    {
        rel physics:body0 = </bot/arm>
        rel physics:body1 = </bot/tip>
        point3f physics:localPos0 = (0, 0, 0.3)
        uniform token physics:axis = "Y"
        float physics:lowerLimit = -45
        float physics:upperLimit = 22.5
        rel newton:mimicJoint = </bot/hinge>
        float newton:mimicCoef1 = 0.5
    }
}
"""


def _read(tmp_path, damping: str = "0.3", colour: str = "0.2"):
    """The USD reader alone (no `formats.load`), its scratch folder removed after."""
    path = tmp_path / "bot.usda"
    path.write_text(STAGE.replace("DAMPING", damping).replace("(0.2,", f"({colour},"))
    options = ReadOptions()
    source = usd.read(read_shell.shell(path, (), Report(Policy()), options), options)
    for scratch in source.scratch:
        shutil.rmtree(scratch, ignore_errors=True)
    return source


def test_the_reader_gives_the_model_numbers_as_floats(tmp_path):
    """The reader's own `Robot`: each number a plain float, no source line anywhere."""
    robot = _read(tmp_path).robot
    assert isinstance(robot, Robot) and [j.name for j in robot.joints][-2:] == ["hinge", "follow"]
    found = list(model_numbers.values(robot))
    lines = [(p, v) for p, v in found if p.endswith("sourceline")]
    numbers = [(p, v) for p, v in found if not p.endswith("sourceline")]
    assert lines and all(v is None for _, v in lines), lines[:3]
    assert numbers and all(type(v) is float for _, v in numbers), numbers[:3]


def test_the_model_holds_what_the_stage_says(tmp_path):
    """Limits in rad, the drive force as the effort, the damping, the mimic, the collider's own
    MassAPI mass and the visual's colour, in the model itself."""
    robot = _read(tmp_path).robot
    hinge, follow = robot.joint("hinge"), robot.joint("follow")
    assert hinge.limit.lower == pytest.approx(-1.5707963, abs=1e-6)
    assert hinge.limit.effort == 20.0 and hinge.dynamics.damping == 0.3
    assert follow.mimic.joint == "hinge" and follow.mimic.multiplier == 0.5
    assert robot.link("base").inertial.mass == 3.0
    (ball,) = robot.link("arm").visuals
    assert ball.shape.kind == "sphere" and ball.material.rgba[3] == 1.0
    assert robot.materials == (ball.material,)


def test_the_kept_document_is_the_model_written(tmp_path):
    """The kept copy's document (what provenance reads) reads back to the reader's model,
    places included, with no attribute a step of the reader left on it."""
    source = _read(tmp_path)
    assert robot_of(replace(source.kept, closures=[])) == source.robot
    keys = {key for element in source.kept.root.iter() for key in element.attrib}
    assert not {key for key in keys if key.startswith(("usd-", "simkit-"))}


@pytest.mark.parametrize(
    ("change", "words"),
    [({"damping": "inf"}, "dynamics: 'damping'"), ({"colour": "nan"}, "color: 'rgba'")],
)
def test_a_number_that_is_not_finite_is_refused_in_one_line(tmp_path, change, words):
    """An infinite MjcPhysics damping, a NaN colour: refused in one line naming the file and
    the field as the URDF reader named it (a colour's `<color>`)."""
    path = tmp_path / "bot.usda"
    damping, colour = change.get("damping", "0.3"), change.get("colour", "0.2")
    path.write_text(STAGE.replace("DAMPING", damping).replace("(0.2,", f"({colour},"))
    with pytest.raises(SpecError) as caught:  # formats.load: formats/finite.py
        formats.load(path, report=Report(Policy()))
    text = str(caught.value)
    assert "bot.usda: " in text and words in text and "finite" in text and "\n" not in text
