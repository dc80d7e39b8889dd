"""The frozen, format-neutral robot model every emitter and check reads. SI units throughout.

Nobody mutates a `Robot`: derive steps return a new one with `dataclasses.replace`.
Transforms follow `T_a_b` = pose of frame b in frame a.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from simkit.spec.mjcf import MjcfSpec
    from simkit.spec.sim import FreefallSpec, Ros2ControlSpec

Vec3 = tuple[float, float, float]
Rgba = tuple[float, float, float, float]


@dataclass(frozen=True)
class Inertial:
    """Mass (kg), CoM (m, link frame) and inertia about the CoM in link axes (kg m^2),
    stored as (ixx, iyy, izz, ixy, ixz, iyz)."""

    mass: float
    com: Vec3
    inertia: tuple[float, float, float, float, float, float]

    def tensor(self) -> np.ndarray:
        """The 3x3 inertia tensor about the CoM, link axes."""
        ixx, iyy, izz, ixy, ixz, iyz = self.inertia
        return np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])


@dataclass(frozen=True)
class Shape:
    """A solid primitive placed in its link frame. Round shapes run along local z;
    `length` is the cylinder length or the capsule's centre-to-centre length (m)."""

    kind: str
    xyz: Vec3
    rpy: Vec3
    size: Vec3 | None = None
    radius: float | None = None
    radius_top: float | None = None
    length: float | None = None
    file: str | None = None
    scale: float = 1.0
    subtract: bool = False
    geom_class: str | None = None


@dataclass(frozen=True, eq=False)
class Mesh:
    """A triangle mesh in a link frame (m). Arrays are read-only so the model stays frozen."""

    vertices: np.ndarray
    faces: np.ndarray

    @staticmethod
    def of(vertices: np.ndarray, faces: np.ndarray) -> Mesh:
        v = np.ascontiguousarray(vertices, dtype=np.float64)
        f = np.ascontiguousarray(faces, dtype=np.int64)
        v.setflags(write=False)
        f.setflags(write=False)
        return Mesh(v, f)


def canonical_triangles(faces: np.ndarray) -> np.ndarray:
    """The same triangles in one fixed order: each turned (never flipped, so its normal keeps
    its side) to start at its lowest vertex index, then sorted row by row. manifold3d's hull
    runs on parallel threads and lists the same triangles in a varying order from one call
    to the next; written as is, the bytes of a mesh file and every cache key after it vary."""
    faces = np.asarray(faces)
    if not len(faces):
        return faces
    start = np.argmin(faces, axis=1)
    turned = np.take_along_axis(faces, (start[:, None] + np.arange(3)) % 3, axis=1)
    return turned[np.lexsort(turned.T[::-1])]


def edge_uses(faces: np.ndarray) -> np.ndarray:
    """How many triangles use each edge (by vertex index, either direction): one count per
    distinct edge. A closed manifold has 2 everywhere; 4 is a solid touching itself."""
    edges = np.sort(np.asarray(faces)[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2), axis=1)
    return np.unique(edges, axis=0, return_counts=True)[1]


@dataclass(frozen=True)
class InertiaDecision:
    """A recorded decision to keep a non-physical reported inertia (spec_sim.py): the reported
    tensor and the problem with it, and the balanced tensor the URDF and MJCF carry instead
    (filled by the derive step; (ixx, iyy, izz, ixy, ixz, iyz), kg m^2)."""

    action: str
    reason: str
    reported: tuple[float, float, float, float, float, float]
    problem: str
    emitted: tuple[float, float, float, float, float, float] | None = None


@dataclass(frozen=True)
class Link:
    """A rigid body. `solid` is the visual solid (None until derived); `collision` holds the
    convex pieces or primitives (empty until derived)."""

    name: str
    mass: float
    inertial: Inertial | None
    material: str | None
    shapes: tuple[Shape, ...]
    collision_method: str
    collision_primitives: tuple[Shape, ...] = ()
    estimated: tuple[str, ...] = ()
    note: str | None = None
    solid: Mesh | None = None
    #: `given` collision: shapes whose convex hulls are the pieces (spec collision_shapes)
    collision_shapes: tuple[Shape, ...] = ()
    #: their convex hulls in the link frame (filled with the solid)
    given_hulls: tuple[Mesh, ...] = ()
    collision: tuple[Mesh, ...] = ()
    collision_report: dict | None = None
    inertia_decision: InertiaDecision | None = None


@dataclass(frozen=True)
class Drive:
    """Motor and gearbox data behind a joint's armature and peak torque."""

    motor: str | None
    motor_peak_torque: float
    rotor_inertia: float
    gearbox: str | None
    gear_ratio: float
    gear_inertia: float
    efficiency: float
    gear_max_output_torque: float | None


@dataclass(frozen=True)
class Joint:
    """A joint; `xyz`/`rpy` give T_parent_child at q = 0. Angles in rad, speeds in rad/s."""

    name: str
    type: str
    parent: str
    child: str
    xyz: Vec3
    rpy: Vec3
    axis: Vec3
    lower: float | None = None
    upper: float | None = None
    max_velocity: float | None = None
    effort_peak: float | None = None
    effort_continuous: float | None = None
    drive_peak_torque_at_joint: float | None = None
    armature: float = 0.0
    damping: float = 0.0
    friction: float = 0.0
    stiffness: float = 0.0
    springref: float = 0.0
    actuated: bool = True
    drive: Drive | None = None
    estimated: tuple[str, ...] = ()
    solreflimit: tuple[float, float] | None = None
    solimplimit: tuple[float, float, float] | None = None
    margin: float = 0.0
    kp: float | None = None
    kv: float | None = None
    mjcf_class: str | None = None
    #: (leader joint, multiplier, offset): value = multiplier * leader + offset
    mimic: tuple[str, float, float] | None = None

    @property
    def movable(self) -> bool:
        """A one-degree-of-freedom joint (a floating base is neither fixed nor 1-DOF: it has
        no entry in poses, robot.json `joints` or the servos)."""
        return self.type not in ("fixed", "floating")


@dataclass(frozen=True)
class Loop:
    """A kinematic loop closed by a constraint (spec `loops`): `link2`'s frame held at
    `xyz` (m) / `rpy` (rad) in `link1`'s frame, its pose at home. `link1` may be the root."""

    name: str
    type: str  # "weld": position and orientation held
    link1: str
    link2: str
    xyz: Vec3
    rpy: Vec3


@dataclass(frozen=True)
class Frame:
    """A massless frame fixed to `parent` (a link or the root)."""

    name: str
    parent: str
    xyz: Vec3
    rpy: Vec3
    estimated: tuple[str, ...] = ()
    site_size: float | None = None
    joint: str | None = None  # the URDF fixed joint's name; None: NAME_joint

    @property
    def joint_name(self) -> str:
        """The name of the fixed joint that holds the frame in the kit's URDF."""
        return self.joint or f"{self.name}_joint"


@dataclass(frozen=True)
class Actuator:
    """A position servo on a joint: kp (N m/rad), kv (N m s/rad), force limit (N m)."""

    joint: str
    kp: float
    kv: float
    forcerange: float


@dataclass(frozen=True)
class PlanningGroup:
    """A MoveIt planning group: the chain from link `base` to link or frame `tip`."""

    name: str
    base: str
    tip: str


@dataclass(frozen=True)
class Products:
    """What the derive steps add that has no natural field on a link or joint. Each field has
    exactly one writer (named below) and is read by emitters; robot.json's shape is decided
    in one place, `emit/robot_json.py`. Values are plain data (dicts, lists, arrays), replaced
    wholesale with `dataclasses.replace`, never mutated. None / empty: not derived."""

    #: derive/references.py: FK reference poses, the frame they are expressed in, reach (m)
    fk_reference: list = field(default_factory=list)
    base_frame: str | None = None
    reach_geometric: dict | None = None
    #: derive/per_link.py: how collision pieces were made, per link and overall
    geometry_links: list = field(default_factory=list)
    geometry_collision: dict | None = None
    #: every seeded step records its seed here (robot.json provenance.seeds), in step order
    seeds: dict = field(default_factory=dict)
    #: derive/ros2_control.py: robot.json `ros2_control` and the package's extra dependencies
    ros2_control: dict | None = None
    ros2_exec_depends: list = field(default_factory=list)
    #: derive/collision_pairs.py: SRDF disabled pairs and robot.json `collision_pairs`
    collision_pairs: dict | None = None
    #: derive/arm.py: ik_cases.json and robot.json `ik_reference`
    ik_cases: dict | None = None
    ik_reference: dict | None = None
    #: derive/arm.py: robot.json `motion` and per-joint additions (derived accelerations)
    motion: dict | None = None
    joint_motion: dict = field(default_factory=dict)
    #: derive/arm.py: robot.json `benchmarks` (before the simulate stage adds its
    #: inverse-dynamics figures), both cycles' samples, and the 1 kg trajectory files' data
    benchmarks: dict | None = None
    benchmark_cycles: dict = field(default_factory=dict)
    benchmark_trajectory: dict | None = None
    #: derive/gpu_scene.py: the GPU scene's colliders, contact pairs and sizes (mjcf/NAME_mjx.xml)
    gpu_scene: dict | None = None
    #: derive/step_plan.py: the STEP candidate kept per piece of each mesh link that needed
    #: checking ({link: [k, ...]}), and the links left out of the STEP ([{link, why}])
    step_plans: dict = field(default_factory=dict)
    step_left_out: list = field(default_factory=list)


@dataclass(frozen=True)
class SimReports:
    """What the simulate stage measured on the staged files (plain data). Only the report
    emitters read it (robot.json, the validation files), after the simulate stage."""

    #: simulate/freefall.py: {"record": robot.json validation.freefall, "data": trajectories}
    freefall: dict | None = None
    #: simulate/benchmark.py: {cycle name: inverse-dynamics torques and forcerange fractions}
    benchmark_torques: dict | None = None
    #: simulate/self_collision.py: robot.json geometry.self_collision (clearance at home,
    #: collision-free ranges, self-contact fraction of random configurations)
    self_collision: dict | None = None


@dataclass(frozen=True)
class Robot:
    """The whole robot: links and joints in tree order (parents before children)."""

    name: str
    title: str
    description: str
    root: str
    floating_base: bool
    links: tuple[Link, ...]
    joints: tuple[Joint, ...]
    frames: tuple[Frame, ...]
    materials: tuple[tuple[str, Rgba], ...]
    poses: tuple[tuple[str, tuple[float, ...]], ...]
    published: dict
    published_estimated: tuple[str, ...]
    sources: tuple[str, ...]
    wrist_centre: str | None
    tool_frame: str | None
    seed: int
    spec_sha256: str
    spec_file: str
    actuators: tuple[Actuator, ...] = ()
    products: Products = field(default_factory=Products)
    planning_groups: tuple[PlanningGroup, ...] = ()
    #: MuJoCo scene settings (`spec_mjcf.MjcfSpec`, frozen), or None for simkit's defaults.
    mjcf: MjcfSpec | None = None
    asset_dir: str | None = None
    #: whether the kit has `step/NAME.step` (spec `step`; `--no-step` overrides)
    step: bool = True
    #: Gazebo / ros2_control additions and the free-fall validation (frozen spec sections)
    ros2_control: Ros2ControlSpec | None = None
    freefall: FreefallSpec | None = None
    #: URDF elements carried over verbatim (spec `urdf_blocks`: an import's gazebo,
    #: transmission and ros2_control blocks), as XML text
    urdf_blocks: tuple[str, ...] = ()
    #: package.xml: the spec's maintainer (name, email) and licence, or None (ros2.py defaults)
    maintainer: tuple[str, str] | None = None
    #: the spec says no source names a maintainer (`maintainer: unnamed`): no warning
    maintainer_unnamed: bool = False
    license: str | None = None
    #: an import's kept source: (file name beside the spec, SHA-256), or None
    source: tuple[str, str] | None = None
    #: an MJCF source's other files: (path relative to the source, SHA-256)
    source_assets: tuple[tuple[str, str], ...] = ()
    #: the source's format, the original's SHA-256 (when the kept file is not the original)
    #: and the xacro args, as robot.json's `source` records them: (key, value) pairs
    source_about: tuple[tuple[str, object], ...] = ()
    #: the kit's intended differences from that source: (what, reason, kit name or None)
    source_differences: tuple[tuple[str, str, str | None], ...] = ()
    #: link pairs the source excludes from contact (spec `contact_excludes`), names sorted
    #: within each pair and the pairs sorted
    contact_excludes: tuple[tuple[str, str], ...] = ()
    #: why the floating robot needs active balance (spec `needs_active_balance`), or None
    needs_active_balance: str | None = None
    #: kinematic loops closed by a constraint (spec `loops`), in spec order
    loops: tuple[Loop, ...] = ()

    @cached_property
    def by_name(self) -> tuple[dict[str, Link], dict[str, Joint]]:
        """Links and joints by name (the first of a name): lookups in constant time, so that
        a walk over a chain of thousands of links stays linear."""
        links: dict[str, Link] = {}
        joints: dict[str, Joint] = {}
        for link in self.links:
            links.setdefault(link.name, link)
        for joint in self.joints:
            joints.setdefault(joint.name, joint)
        return links, joints

    def link(self, name: str) -> Link:
        return self.by_name[0][name]

    def joint(self, name: str) -> Joint:
        return self.by_name[1][name]

    @property
    def floating_joint(self) -> Joint | None:
        """The free joint between the root and the floating base link, if any."""
        return next((j for j in self.joints if j.type == "floating"), None)

    @property
    def movable_joints(self) -> tuple[Joint, ...]:
        return tuple(j for j in self.joints if j.movable)

    def pose(self, name: str) -> tuple[float, ...]:
        return dict(self.poses)[name]

    @property
    def total_mass(self) -> float:
        return sum(link.mass for link in self.links)

    def parent_joint(self, link_name: str) -> Joint | None:
        for joint in self.joints:
            if joint.child == link_name:
                return joint
        return None

    def material_rgba(self, name: str | None) -> Rgba:
        return dict(self.materials).get(name or "", (0.7, 0.7, 0.7, 1.0))
