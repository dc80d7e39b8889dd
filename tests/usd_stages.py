"""Small UsdPhysics stages written with pxr for the USD import tests (issue 39)."""

from __future__ import annotations

from pathlib import Path


def arm(
    path: Path,
    meters: float = 1.0,
    y_up: bool = False,
    robots: int = 1,
    articulated: bool = True,
    variant: bool = False,
    loop: bool | None = None,
    chain: bool = False,
    rail: bool = False,
    two_roots: bool = False,
) -> Path:
    """A fixed-base two-link arm per robot: `base` (box, MassAPI 2 kg) bolted to the world,
    `upper` on a revolute joint about Z (-90..45 degrees), `slider` on a prismatic joint
    along X (0..0.2 m, stage units); with `variant`, a `Physics` variant set whose
    `heavy` variant sets `upper`'s mass to 3 kg (default `light`: 1 kg); with `loop` a
    fixed joint `loop` from `base` to `slider` closes a loop (True: marked
    excludeFromArticulation; False: not marked, so `slider` has two parent joints); with
    `chain` a second revolute joint `a_twist` (about X, at the shoulder, authored after
    `shoulder` but before it by path) joins `base` and
    `upper` too: a body with two degrees of freedom, as MJCF writes it; with `rail`, two
    joints without body0 hold `base` to the world in place of the fixed one: `rail`
    (prismatic along X), then `yaw` (revolute about Z); with `two_roots` the articulation
    root is on `base` and on a second body `post` (0.7 kg) bolted 0.3 m along X, both by
    fixed joints from the robot's own prim: two articulations of one robot."""
    from pxr import Gf, Usd, UsdGeom, UsdPhysics

    stage = Usd.Stage.CreateNew(str(path))
    UsdGeom.SetStageMetersPerUnit(stage, meters)
    UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.y if y_up else UsdGeom.Tokens.z)
    unit = 1.0 / meters
    for r in range(robots):
        top = UsdGeom.Xform.Define(stage, f"/arm{r}")
        stage.SetDefaultPrim(top.GetPrim())
        if articulated:
            UsdPhysics.ArticulationRootAPI.Apply(top.GetPrim())
        top.AddTranslateOp().Set(Gf.Vec3d(r * 2 * unit, 0, 0))
        bodies = {}
        for name, z, mass in (("base", 0.0, 2.0), ("upper", 0.5, 1.0), ("slider", 1.0, 0.5)):
            xf = UsdGeom.Xform.Define(stage, f"/arm{r}/{name}")
            xf.AddTranslateOp().Set(Gf.Vec3d(0, 0, z * unit))
            UsdPhysics.RigidBodyAPI.Apply(xf.GetPrim())
            api = UsdPhysics.MassAPI.Apply(xf.GetPrim())
            api.CreateMassAttr(mass)
            api.CreateCenterOfMassAttr(Gf.Vec3f(0, 0, 0.1 * unit))
            api.CreateDiagonalInertiaAttr(Gf.Vec3f(0.01, 0.02, 0.03) * unit * unit)
            cube = UsdGeom.Cube.Define(stage, f"/arm{r}/{name}/box")
            cube.CreateSizeAttr(0.1 * unit)
            UsdPhysics.CollisionAPI.Apply(cube.GetPrim())
            cube.CreateDisplayColorAttr([Gf.Vec3f(0.2, 0.4, 0.6)])
            bodies[name] = xf.GetPath()
        _joints(stage, f"/arm{r}", bodies, unit)
        if two_roots:
            top.GetPrim().RemoveAPI(UsdPhysics.ArticulationRootAPI)
            UsdPhysics.ArticulationRootAPI.Apply(stage.GetPrimAtPath(bodies["base"]))
            post = UsdGeom.Xform.Define(stage, f"/arm{r}/post")
            post.AddTranslateOp().Set(Gf.Vec3d(0.3 * unit, 0, 0))
            UsdPhysics.RigidBodyAPI.Apply(post.GetPrim())
            UsdPhysics.ArticulationRootAPI.Apply(post.GetPrim())
            UsdPhysics.MassAPI.Apply(post.GetPrim()).CreateMassAttr(0.7)
            for name, body in (("world_joint", bodies["base"]), ("post_joint", post.GetPath())):
                bolt = UsdPhysics.FixedJoint.Define(stage, f"/arm{r}/{name}")
                bolt.CreateBody0Rel().SetTargets([top.GetPath()])
                bolt.CreateBody1Rel().SetTargets([body])
            UsdPhysics.FixedJoint(stage.GetPrimAtPath(f"/arm{r}/post_joint")).CreateLocalPos0Attr(
                Gf.Vec3f(0.3 * unit, 0, 0)
            )
        if rail:
            stage.RemovePrim(f"/arm{r}/world_joint")
            for name, kind, axis in (("rail", UsdPhysics.PrismaticJoint, "X"),
                                     ("yaw", UsdPhysics.RevoluteJoint, "Z")):  # fmt: skip
                joint = kind.Define(stage, f"/arm{r}/{name}")
                joint.CreateBody1Rel().SetTargets([bodies["base"]])
                joint.CreateAxisAttr(axis)
        if chain:
            twist = UsdPhysics.RevoluteJoint.Define(stage, f"/arm{r}/a_twist")
            twist.CreateBody0Rel().SetTargets([bodies["base"]])
            twist.CreateBody1Rel().SetTargets([bodies["upper"]])
            twist.CreateLocalPos0Attr(Gf.Vec3f(0, 0, 0.5 * unit))
            twist.CreateAxisAttr("X")
        if loop is not None:
            closing = UsdPhysics.FixedJoint.Define(stage, f"/arm{r}/zloop")
            closing.CreateBody0Rel().SetTargets([bodies["base"]])
            closing.CreateBody1Rel().SetTargets([bodies["slider"]])
            closing.CreateLocalPos0Attr(Gf.Vec3f(0, 0, 1.0 * unit))
            closing.CreateExcludeFromArticulationAttr(loop)
        if variant:
            _variant(stage, top.GetPrim(), f"/arm{r}/upper")
    stage.GetRootLayer().Save()
    return path


def _joints(stage, at: str, bodies: dict, unit: float) -> None:
    from pxr import Gf, UsdPhysics

    fixed = UsdPhysics.FixedJoint.Define(stage, f"{at}/world_joint")
    fixed.CreateBody1Rel().SetTargets([bodies["base"]])
    hinge = UsdPhysics.RevoluteJoint.Define(stage, f"{at}/shoulder")
    hinge.CreateBody0Rel().SetTargets([bodies["base"]])
    hinge.CreateBody1Rel().SetTargets([bodies["upper"]])
    hinge.CreateLocalPos0Attr(Gf.Vec3f(0, 0, 0.5 * unit))
    hinge.CreateAxisAttr("Z")
    hinge.CreateLowerLimitAttr(-90.0)
    hinge.CreateUpperLimitAttr(45.0)
    drive = UsdPhysics.DriveAPI.Apply(hinge.GetPrim(), "angular")
    drive.CreateMaxForceAttr(20.0)
    slide = UsdPhysics.PrismaticJoint.Define(stage, f"{at}/slide")
    slide.CreateBody0Rel().SetTargets([bodies["upper"]])
    slide.CreateBody1Rel().SetTargets([bodies["slider"]])
    slide.CreateLocalPos0Attr(Gf.Vec3f(0, 0, 0.5 * unit))
    slide.CreateAxisAttr("X")
    slide.CreateLowerLimitAttr(0.0)
    slide.CreateUpperLimitAttr(0.2 * unit)


def _variant(stage, prim, upper: str) -> None:
    from pxr import UsdPhysics

    UsdPhysics.MassAPI(stage.GetPrimAtPath(upper)).GetMassAttr().Clear()  # the variants say
    variants = prim.GetVariantSets().AddVariantSet("Physics")
    for name, mass in (("heavy", 3.0), ("light", 1.0)):
        variants.AddVariant(name)
        variants.SetVariantSelection(name)
        with variants.GetVariantEditContext():
            UsdPhysics.MassAPI(stage.GetPrimAtPath(upper)).GetMassAttr().Set(mass)
    variants.SetVariantSelection("light")


def stage_text(inside: str, meters: float = 1.0, root_metadata: str = "") -> str:
    """A small stage as usda text (for schemas usd-core does not register, written by name):
    Z-up, `metersPerUnit` `meters`, and the articulation root `bot` holding `inside` (prims
    indented four spaces); `root_metadata` adds lines to `bot`'s metadata (a variant
    selection)."""
    meta = f"\n    {root_metadata}\n" if root_metadata else ""
    return (
        f'#usda 1.0\n(\n    defaultPrim = "bot"\n    metersPerUnit = {meters}\n'
        f'    kilogramsPerUnit = 1\n    upAxis = "Z"\n)\n\n'
        f'def Xform "bot" (prepend apiSchemas = ["PhysicsArticulationRootAPI"]{meta})\n'
        f"{{\n{inside}}}\n"
    )


def body_text(name: str, mass: float, at=None, inertia=None, box: bool = True) -> str:
    """A rigid body prim `name` (MassAPI `mass` kg, at `at` (m) and with `inertia` (kg m^2)
    where given), with a 0.1 m collision cube when `box`."""
    lines = [
        f'    def Xform "{name}" (prepend apiSchemas = ["PhysicsRigidBodyAPI", "PhysicsMassAPI"])'
    ]
    lines.append("    {")
    if at is not None:
        lines.append(f"        double3 xformOp:translate = ({', '.join(f'{v:g}' for v in at)})")
        lines.append('        uniform token[] xformOpOrder = ["xformOp:translate"]')
    lines.append(f"        float physics:mass = {mass:g}")
    if inertia is not None:
        lines.append(
            f"        float3 physics:diagonalInertia = ({', '.join(f'{v:g}' for v in inertia)})"
        )
    if box:
        lines += [
            '        def Cube "box" (prepend apiSchemas = ["PhysicsCollisionAPI"])',
            "        {",
            "            double size = 0.1",
            "        }",
        ]
    return "\n".join([*lines, "    }", ""])


def bolted_text(body: str) -> str:
    """A fixed joint `world_joint` holding `body` to the world."""
    joint = '    def PhysicsFixedJoint "world_joint"\n    {\n'
    return f"{joint}        rel physics:body1 = </bot/{body}>\n    }}\n"


#: the base bolted to the world and the arm 0.5 m above it, for a hinge between them
BASE_AND_ARM = (
    body_text("base", 2)
    + body_text("arm", 1, at=(0, 0, 0.5), inertia=(0.01, 0.01, 0.01))
    + bolted_text("base")
)
