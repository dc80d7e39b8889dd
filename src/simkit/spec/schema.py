"""The spec schema: what a person writes in robots/NAME.yaml.

Every model forbids unknown keys. Angles may be given in radians (`lower`) or degrees
(`lower_deg`); the resolver turns everything into SI. Values that no source publishes are
listed by field name in the entity's `estimated` list, and that list ends up in robot.json.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Annotated, Literal, Protocol, TypeVar

from pydantic import ConfigDict, Field, field_validator, model_validator

from simkit.spec.loops import LoopSpec
from simkit.spec.mjcf import MjcfSpec
from simkit.spec.placed import Placed, Strict, Vec3
from simkit.spec.sim import FreefallSpec, InertiaDecisionSpec, Ros2ControlSpec

Rgba = tuple[float, float, float, float]
PositiveFloat = Annotated[float, Field(gt=0)]
NonNegFloat = Annotated[float, Field(ge=0)]


class Primitive(Placed):
    """One solid primitive in the link frame. Round shapes run along their local z axis,
    centred on `xyz`, unless `from`/`to` give the two end centres."""

    shape: Literal["box", "cylinder", "cone", "capsule", "sphere", "mesh"]
    size: Vec3 | None = None
    radius: PositiveFloat | None = None
    radius_top: NonNegFloat | None = None
    length: PositiveFloat | None = None
    from_: Vec3 | None = Field(default=None, alias="from")
    to: Vec3 | None = None
    file: str | None = None
    scale: PositiveFloat = 1.0
    subtract: bool = False

    model_config = ConfigDict(
        extra="forbid", frozen=True, allow_inf_nan=False, populate_by_name=True
    )

    @model_validator(mode="after")
    def _complete(self) -> Primitive:
        need = {
            "box": ("size",),
            "cylinder": ("radius",),
            "cone": ("radius", "radius_top"),
            "capsule": ("radius",),
            "sphere": ("radius",),
            "mesh": ("file",),
        }[self.shape]
        for name in need:
            if getattr(self, name) is None:
                raise ValueError(f"a {self.shape} needs '{name}'")
        if self.shape in ("cylinder", "cone", "capsule"):
            ends = (self.from_ is not None) + (self.to is not None)
            if ends == 1:
                raise ValueError("give both 'from' and 'to'")
            if ends == 0 and self.length is None:
                raise ValueError(f"a {self.shape} needs 'length' or 'from'/'to'")
            if ends == 2 and math.dist(self.from_, self.to) <= 0:  # type: ignore[arg-type]
                raise ValueError("'from' and 'to' must differ")
        if self.size is not None and min(self.size) <= 0:
            raise ValueError("box size must be positive")
        return self


class CollisionPrimitive(Placed):
    """A collision primitive that the MJCF, URDF and USD emit as a primitive."""

    shape: Literal["box", "cylinder", "capsule", "sphere"]
    size: Vec3 | None = None
    radius: PositiveFloat | None = None
    length: PositiveFloat | None = None
    from_: Vec3 | None = Field(default=None, alias="from")
    to: Vec3 | None = None
    geom_class: str | None = None

    model_config = ConfigDict(
        extra="forbid", frozen=True, allow_inf_nan=False, populate_by_name=True
    )


class InertiaSpec(Strict):
    """Inertia tensor about the CoM, in the link frame (kg m^2)."""

    ixx: float
    iyy: float
    izz: float
    ixy: float = 0.0
    ixz: float = 0.0
    iyz: float = 0.0


class LinkSpec(Strict):
    """A rigid body: its solid, mass, optional CoM/inertia, and colour."""

    name: str
    mass: float
    com: Vec3 | None = None
    inertia: InertiaSpec | None = None
    material: str | None = None
    solid: tuple[Primitive, ...] = ()
    collision: Literal["auto", "convex", "coacd", "primitives", "mesh", "given"] = "auto"
    collision_primitives: tuple[CollisionPrimitive, ...] = ()
    #: `collision: given`: shapes (e.g. an imported URDF's collision meshes), one convex piece each
    collision_shapes: tuple[Primitive, ...] = ()
    estimated: tuple[str, ...] = ()
    note: str | None = None
    #: keep a non-physical reported inertia on purpose (spec_sim.InertiaDecisionSpec)
    inertia_decision: InertiaDecisionSpec | None = None

    @field_validator("mass")
    @classmethod
    def _positive_mass(cls, value: float) -> float:
        if value <= 0:
            raise ValueError(f"mass must be > 0 kg (got {value})")
        return value


class DriveSpec(Strict):
    """Motor and gearbox; the resolver derives armature and the drive's peak joint torque."""

    motor: str | None = None
    motor_peak_torque: PositiveFloat
    rotor_inertia: NonNegFloat
    gearbox: str | None = None
    gear_ratio: PositiveFloat
    gear_inertia: NonNegFloat = 0.0
    efficiency: Annotated[float, Field(gt=0, le=1)] = 1.0
    gear_max_output_torque: PositiveFloat | None = None
    estimated: tuple[str, ...] = ()


class Edge(Protocol):
    """A joint seen as a tree edge: any object with `parent` and `child` link names."""

    parent: str
    child: str


E = TypeVar("E", bound=Edge)


def depth_first(joints: Sequence[E], root: str) -> list[E]:
    """Joints in depth-first order from `root` (each chain contiguous, as a reader of URDF or
    MJCF expects); siblings keep spec order. The model's joint order (`Robot.joints`)."""
    by_parent: dict[str, list[E]] = {}
    for joint in joints:
        by_parent.setdefault(joint.parent, []).append(joint)
    out: list[E] = []
    stack = list(reversed(by_parent.get(root, [])))
    while stack:  # iterative: a deep chain must not hit Python's recursion limit
        joint = stack.pop()
        out.append(joint)
        stack.extend(reversed(by_parent.get(joint.child, [])))
    return out


def angle(rad: float | None, deg: float | None) -> float | None:
    """A value given in rad (or m) or in degrees, in SI; None when neither is given."""
    if rad is not None:
        return float(rad)
    return math.radians(deg) if deg is not None else None


class MimicSpec(Strict):
    """URDF `<mimic>`: this joint's value = multiplier * `joint`'s value + offset (rad or m)."""

    joint: str
    multiplier: float = 1.0
    offset: float = 0.0


class JointSpec(Placed):
    """A joint between two links. `xyz`/`rpy` place the child frame in the parent frame."""

    name: str
    type: Literal["revolute", "continuous", "prismatic", "fixed", "floating"] = "revolute"
    parent: str
    child: str
    axis: Vec3 = (0.0, 0.0, 1.0)
    lower: float | None = None
    upper: float | None = None
    lower_deg: float | None = None
    upper_deg: float | None = None
    max_velocity: PositiveFloat | None = None
    max_velocity_deg_s: PositiveFloat | None = None
    effort_peak: PositiveFloat | None = None
    effort_continuous: PositiveFloat | None = None
    drive_peak_torque_at_joint: PositiveFloat | None = None
    armature: NonNegFloat | None = None
    drive: DriveSpec | None = None
    damping: NonNegFloat = 0.0
    friction: NonNegFloat = 0.0
    stiffness: NonNegFloat = 0.0
    springref: float = 0.0
    actuated: bool = True
    # Joint-limit contact (MuJoCo solreflimit, solimplimit, margin in rad or m), servo gains
    # (N m/rad, N m s/rad; derived from effort_peak when absent) and the MJCF default class.
    solreflimit: tuple[float, float] | None = None
    solimplimit: tuple[float, float, float] | None = None
    margin: NonNegFloat = 0.0
    kp: PositiveFloat | None = None
    kv: NonNegFloat | None = None
    mjcf_class: str | None = None
    #: coupled to another joint (URDF <mimic>, MJCF <equality><joint>)
    mimic: MimicSpec | None = None
    estimated: tuple[str, ...] = ()

    @model_validator(mode="after")
    def _units_once(self) -> JointSpec:
        for rad, deg in (
            ("lower", "lower_deg"),
            ("upper", "upper_deg"),
            ("max_velocity", "max_velocity_deg_s"),
        ):
            if getattr(self, rad) is not None and getattr(self, deg) is not None:
                raise ValueError(f"give {rad} or {deg}, not both")
        return self

    @property
    def movable(self) -> bool:
        """One degree of freedom: has a value in every named pose."""
        return self.type not in ("fixed", "floating")

    def limits(self) -> tuple[float | None, float | None]:
        """(lower, upper) in rad (m for prismatic joints)."""
        return angle(self.lower, self.lower_deg), angle(self.upper, self.upper_deg)

    @field_validator("axis")
    @classmethod
    def _nonzero_axis(cls, axis: Vec3) -> Vec3:
        if math.sqrt(sum(a * a for a in axis)) < 1e-9:
            raise ValueError("axis must not be zero")
        return axis


class FrameSpec(Placed):
    """A massless frame fixed to a link (tool0, sensor sites, ...)."""

    name: str
    parent: str
    site_size: PositiveFloat | None = None  # m, radius of the MJCF site (default 0.005)
    estimated: tuple[str, ...] = ()
    #: the fixed joint holding it in the kit's URDF (default NAME_joint): an imported URDF's
    #: own joint name, kept so that anything keyed on joint names still finds it
    joint: str | None = None


class MaterialSpec(Strict):
    name: str
    rgba: Rgba


class MaintainerSpec(Strict):
    """The package's maintainer (package.xml `<maintainer email>`), as rosdep and bloom want."""

    name: Annotated[str, Field(min_length=1, pattern=r"^[^\n]+$")]
    email: Annotated[str, Field(pattern=r"^[^@\s]+@[^@\s]+\.[^@\s]+$")]


class PublishedSpec(Strict):
    """Published ratings and reference figures; the checks compare the outputs to these."""

    mass: PositiveFloat | None = None
    base_link_height: float | None = None
    tool0_home: Vec3 | None = None
    wrist_centre_reach: PositiveFloat | None = None
    reach_wrist: PositiveFloat | None = None
    reach_flange: PositiveFloat | None = None
    payload: PositiveFloat | None = None
    repeatability_mm: PositiveFloat | None = None
    #: m above base_link of the benchmark cycle's low points (kit page, "Benchmark cycle")
    benchmark_low_height: float | None = None
    estimated: tuple[str, ...] = ()


class PlanningGroupSpec(Strict):
    """A MoveIt planning group: the kinematic chain from link `base` to link or frame `tip`
    (SRDF `<chain>`). Without any, the SRDF has `manipulator`: base_link -> tool frame."""

    name: str
    base: str
    tip: str


class SourceSpec(Strict):
    """The file a spec was imported from, kept beside it (`simkit import` writes
    NAME.source.urdf, the expanded URDF, or NAME.source.xml, the MJCF), and its SHA-256:
    the source check compares the kit with it (check/source). The kit never carries
    the file, only the digest."""

    #: a file name in the spec's folder (no folders, so it cannot point elsewhere)
    file: Annotated[str, Field(pattern=r"^[A-Za-z0-9_][A-Za-z0-9_.-]*$")]
    #: the importer's format (importer/formats: urdf, xacro, mjcf), which picks the source
    #: check's comparison; absent in specs imported before it was recorded
    format: Annotated[str, Field(pattern=r"^[a-z][a-z0-9]{0,15}$")] | None = None
    sha256: Annotated[str, Field(pattern=r"^[0-9a-f]{64}$")]
    #: SHA-256 of the file the user imported, where the kept file is not it byte for byte
    #: (a URDF re-serialised, a xacro expanded): `simkit check --source` takes either
    original: Annotated[str, Field(pattern=r"^[0-9a-f]{64}$")] | None = None
    #: the `--xacro-arg` values the import expanded a xacro with, to expand it again
    args: dict[
        Annotated[str, Field(pattern=r"^[A-Za-z_][A-Za-z0-9_]{0,99}$")],
        Annotated[str, Field(max_length=1000)],
    ] = Field(default_factory=dict)
    #: an MJCF's other files (includes, meshes, textures): path relative to the source's
    #: folder -> SHA-256; kept beside the spec as NAME.source.assets/SHA256.EXT
    assets: dict[
        Annotated[str, Field(pattern=r"^[A-Za-z0-9_][A-Za-z0-9_./ +-]{0,299}$")],
        Annotated[str, Field(pattern=r"^[0-9a-f]{64}$")],
    ] = Field(default_factory=dict)

    @field_validator("assets")
    @classmethod
    def _inside(cls, assets: dict[str, str]) -> dict[str, str]:
        """Each asset path stays inside the source's folder (no `..` part)."""
        for path in assets:
            if ".." in path.split("/"):
                raise ValueError(f"asset path '{path}' leaves the source's folder")
        return assets


class SourceDifference(Strict):
    """One intended difference between the kit and its source (`what`: `links.NAME.FIELD`,
    `joints.NAME.FIELD`, `links.NAME` or `joints.NAME` for an added element), with why.
    `kit`: the kit's name for a renamed element (`what` = `links.OLD.name`)."""

    what: Annotated[str, Field(min_length=1)]
    reason: Annotated[str, Field(min_length=1)]
    kit: str | None = None


class RobotSpec(Strict):
    """The whole robot spec (one YAML file)."""

    @model_validator(mode="before")
    @classmethod
    def _unnamed_maintainer(cls, data: object) -> object:
        """`maintainer: unnamed`: no source names one (package.xml keeps the default)."""
        if isinstance(data, dict) and data.get("maintainer") == "unnamed":
            return {**data, "maintainer": None, "maintainer_unnamed": True}
        return data

    name: Annotated[str, Field(pattern=r"^[a-z][a-z0-9_]*$")]
    title: str
    description: str = ""
    sources: tuple[str, ...] = ()
    root: str = "base_footprint"
    floating_base: bool = False
    #: why a floating robot cannot stand on the kit's position servos (one line, an
    #: import's settle: `sinks 0.51 m in 2 s`): robot.json and the README say it needs
    #: active balance, and the legged check holds its base suspended instead of standing
    needs_active_balance: Annotated[str, Field(min_length=1, pattern=r"^[^\n]+$")] | None = None
    wrist_centre: str | None = None
    tool_frame: str | None = None
    materials: tuple[MaterialSpec, ...] = ()
    links: tuple[LinkSpec, ...]
    joints: tuple[JointSpec, ...]
    frames: tuple[FrameSpec, ...] = ()
    poses_deg: dict[str, tuple[float, ...]] = Field(default_factory=dict)
    poses: dict[str, tuple[float, ...]] = Field(default_factory=dict)
    published: PublishedSpec = PublishedSpec()
    #: seeds every random draw of the build (numpy wants it non-negative)
    seed: Annotated[int, Field(ge=0)] = 0
    mjcf: MjcfSpec | None = None
    planning_groups: tuple[PlanningGroupSpec, ...] = ()
    #: Folder name under the download site's /assets/sim/ (the page's `<model>`, e.g. "1000");
    #: defaults to `name`.
    asset_dir: Annotated[str, Field(pattern=r"^[A-Za-z0-9][A-Za-z0-9_.-]*$")] | None = None
    #: Write `step/NAME.step`, the STEP assembly (issue 14). `simkit import` sets it false for
    #: CAD meshes too large for a faceted STEP (importer/translate/step_budget.py); `--no-step` also
    #: leaves it out.
    step: bool = True
    #: Gazebo / ros2_control additions and the free-fall validation (spec_sim.py)
    ros2_control: Ros2ControlSpec | None = None
    freefall: FreefallSpec | None = None
    #: URDF `<gazebo>`, `<transmission>` and `<ros2_control>` elements, each as its XML text,
    #: written into the kit's URDF verbatim after the joints (spec/urdf_blocks.py)
    urdf_blocks: tuple[str, ...] = ()
    #: package.xml `<maintainer>` and `<license>` (an SPDX expression, e.g. "Apache-2.0");
    #: without them the ROS 2 package gets emit/ros2.py's defaults and the build a warning.
    #: `maintainer: unnamed` says that no source names one (the default, without the warning)
    maintainer: MaintainerSpec | None = None
    #: set by `maintainer: unnamed` (see `_unnamed_maintainer`), not written by hand
    maintainer_unnamed: bool = False
    license: Annotated[str, Field(min_length=1, pattern=r"^[^\n]+$")] | None = None
    #: the imported source file and its digest, and the kit's intended differences from it
    source: SourceSpec | None = None
    source_differences: tuple[SourceDifference, ...] = ()
    #: link pairs the source excludes from contact (an MJCF `<contact><exclude>`), each
    #: `[LINK, LINK]`: every format that can filter a pair gets them (MJCF, USD, SRDF)
    contact_excludes: tuple[tuple[str, str], ...] = ()
    #: kinematic loops the tree cannot hold, each closed by a constraint (spec/loops.py)
    loops: tuple[LoopSpec, ...] = ()
