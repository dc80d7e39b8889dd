"""Resolve a validated spec into the frozen `Robot` model: SI units, tree order, drives."""

from __future__ import annotations

import hashlib
import math

import numpy as np

from simkit.model.kinematics import matrix_rpy, tree_order
from simkit.model.robot import (
    Drive,
    Frame,
    InertiaDecision,
    Inertial,
    Joint,
    Link,
    Loop,
    PlanningGroup,
    Robot,
    Shape,
)
from simkit.spec.schema import (
    CollisionPrimitive,
    DriveSpec,
    JointSpec,
    LinkSpec,
    Primitive,
    RobotSpec,
    angle,
)
from simkit.spec.validate import inertia_problem


def _unit(v) -> tuple[float, float, float]:
    arr = np.asarray(v, dtype=float)
    arr = arr / np.linalg.norm(arr)
    return tuple(float(x) for x in arr)  # type: ignore[return-value]


def _along(start, end) -> tuple[tuple[float, float, float], tuple[float, float, float], float]:
    """Centre, rpy and length of a round shape that runs from `start` to `end`."""
    a, b = np.asarray(start, float), np.asarray(end, float)
    z = (b - a) / np.linalg.norm(b - a)
    helper = np.array([1.0, 0.0, 0.0]) if abs(z[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    x = np.cross(helper, z)
    x /= np.linalg.norm(x)
    y = np.cross(z, x)
    rot = np.column_stack([x, y, z])
    centre = tuple(float(c) for c in (a + b) / 2)
    return centre, matrix_rpy(rot), float(np.linalg.norm(b - a))  # type: ignore[return-value]


def shape_of(prim: Primitive | CollisionPrimitive) -> Shape:
    """A spec primitive as a model `Shape` (from/to turned into centre, rpy and length)."""
    xyz, rpy, length = prim.xyz, prim.rpy_rad(), prim.length
    if prim.from_ is not None and prim.to is not None:
        xyz, rpy, length = _along(prim.from_, prim.to)
    return Shape(
        kind=prim.shape,
        xyz=tuple(float(v) for v in xyz),  # type: ignore[arg-type]
        rpy=tuple(float(v) for v in rpy),  # type: ignore[arg-type]
        size=prim.size,
        radius=prim.radius,
        radius_top=getattr(prim, "radius_top", None),
        length=length,
        file=getattr(prim, "file", None),
        scale=getattr(prim, "scale", 1.0),
        subtract=getattr(prim, "subtract", False),
        geom_class=getattr(prim, "geom_class", None),
    )


def drive_of(spec: DriveSpec) -> Drive:
    return Drive(
        motor=spec.motor,
        motor_peak_torque=spec.motor_peak_torque,
        rotor_inertia=spec.rotor_inertia,
        gearbox=spec.gearbox,
        gear_ratio=spec.gear_ratio,
        gear_inertia=spec.gear_inertia,
        efficiency=spec.efficiency,
        gear_max_output_torque=spec.gear_max_output_torque,
    )


def drive_armature(drive: Drive) -> float:
    """Reflected inertia at the joint: (J_motor + J_gear) * ratio^2 (kg m^2)."""
    return (drive.rotor_inertia + drive.gear_inertia) * drive.gear_ratio**2


def drive_peak_torque(drive: Drive) -> float:
    """Peak torque the drive puts on the joint: motor peak x ratio x efficiency, capped by the
    gearbox's maximum output torque where one is given (N m)."""
    torque = drive.motor_peak_torque * drive.gear_ratio * drive.efficiency
    if drive.gear_max_output_torque is not None:
        torque = min(torque, drive.gear_max_output_torque)
    return torque


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


def joint_of(spec: JointSpec) -> Joint:
    drive = drive_of(spec.drive) if spec.drive is not None else None
    armature = spec.armature
    peak = spec.drive_peak_torque_at_joint
    if drive is not None:
        armature = drive_armature(drive) if armature is None else armature
        peak = drive_peak_torque(drive) if peak is None else peak
    return Joint(
        name=spec.name,
        type=spec.type,
        parent=spec.parent,
        child=spec.child,
        xyz=tuple(float(v) for v in spec.xyz),  # type: ignore[arg-type]
        rpy=spec.rpy_rad(),
        axis=_unit(spec.axis),
        lower=angle(spec.lower, spec.lower_deg),
        upper=angle(spec.upper, spec.upper_deg),
        max_velocity=angle(spec.max_velocity, spec.max_velocity_deg_s),
        effort_peak=spec.effort_peak,
        effort_continuous=spec.effort_continuous,
        drive_peak_torque_at_joint=peak if peak is not None else spec.effort_peak,
        armature=armature or 0.0,
        damping=spec.damping,
        friction=spec.friction,
        stiffness=spec.stiffness,
        springref=spec.springref,
        actuated=spec.actuated and spec.type not in ("fixed", "floating"),
        drive=drive,
        estimated=tuple(spec.estimated),
        solreflimit=spec.solreflimit,
        solimplimit=spec.solimplimit,
        margin=spec.margin,
        kp=spec.kp,
        kv=spec.kv,
        mjcf_class=spec.mjcf_class,
        mimic=(spec.mimic.joint, spec.mimic.multiplier, spec.mimic.offset)
        if spec.mimic is not None
        else None,
    )


def resolve(spec: RobotSpec, spec_bytes: bytes, spec_file: str) -> Robot:
    """Build the frozen model. Link solids and mass properties are filled in by derive steps."""
    joints = tuple(tree_order([joint_of(j) for j in spec.joints], spec.root))
    order = {j.child: i for i, j in enumerate(joints)}
    links = []
    for link in sorted(spec.links, key=lambda item: order[item.name]):
        inertial = None
        if link.inertia is not None and link.com is not None:
            i = link.inertia
            inertial = Inertial(link.mass, link.com, (i.ixx, i.iyy, i.izz, i.ixy, i.ixz, i.iyz))
        links.append(
            Link(
                name=link.name,
                mass=link.mass,
                inertial=inertial,
                material=link.material,
                shapes=tuple(shape_of(p) for p in link.solid),
                collision_method=link.collision,
                collision_primitives=tuple(shape_of(p) for p in link.collision_primitives),
                collision_shapes=tuple(shape_of(p) for p in link.collision_shapes),
                estimated=tuple(link.estimated),
                note=link.note,
                inertia_decision=decision_of(link),
            )
        )
    poses = {name: tuple(float(v) for v in values) for name, values in spec.poses.items()}
    poses.update(
        {name: tuple(math.radians(v) for v in values) for name, values in spec.poses_deg.items()}
    )
    published = spec.published.model_dump(exclude={"estimated"}, exclude_none=True)
    return Robot(
        name=spec.name,
        title=spec.title,
        description=spec.description,
        root=spec.root,
        floating_base=spec.floating_base or any(j.type == "floating" for j in spec.joints),
        links=tuple(links),
        joints=joints,
        frames=tuple(
            Frame(
                f.name,
                f.parent,
                tuple(float(v) for v in f.xyz),
                f.rpy_rad(),
                tuple(f.estimated),  # type: ignore[arg-type]
                f.site_size,
                f.joint,
            )
            for f in spec.frames
        ),
        materials=tuple((m.name, m.rgba) for m in spec.materials),
        poses=tuple(poses.items()),
        published=published,
        published_estimated=tuple(spec.published.estimated),
        sources=tuple(spec.sources),
        wrist_centre=spec.wrist_centre,
        tool_frame=spec.tool_frame,
        seed=spec.seed,
        spec_sha256=hashlib.sha256(spec_bytes).hexdigest(),
        spec_file=spec_file,
        planning_groups=tuple(PlanningGroup(g.name, g.base, g.tip) for g in spec.planning_groups),
        asset_dir=spec.asset_dir,
        step=spec.step,
        mjcf=spec.mjcf,
        ros2_control=spec.ros2_control,
        urdf_blocks=spec.urdf_blocks,
        freefall=spec.freefall,
        maintainer=(spec.maintainer.name, spec.maintainer.email) if spec.maintainer else None,
        maintainer_unnamed=spec.maintainer_unnamed,
        license=spec.license,
        source=None if spec.source is None else (spec.source.file, spec.source.sha256),
        source_assets=() if spec.source is None else tuple(sorted(spec.source.assets.items())),
        source_about=_source_about(spec),
        source_differences=tuple((d.what, d.reason, d.kit) for d in spec.source_differences),
        contact_excludes=tuple(sorted(tuple(sorted(p)) for p in spec.contact_excludes)),
        needs_active_balance=spec.needs_active_balance,
        loops=tuple(
            Loop(lp.name, lp.type, lp.link1, lp.link2, lp.xyz, lp.rpy_rad()) for lp in spec.loops
        ),
    )


def _source_about(spec: RobotSpec) -> tuple[tuple[str, object], ...]:
    """robot.json's `source` keys beyond file, digest and assets: the format, the
    original's digest and the xacro args, those the spec gives."""
    if spec.source is None:
        return ()
    about = {"format": spec.source.format, "original": spec.source.original}
    if spec.source.args:
        about["args"] = tuple(sorted(spec.source.args.items()))
    return tuple((k, v) for k, v in about.items() if v is not None)
