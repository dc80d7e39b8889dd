"""The source model: what every format's reader gives the translation, numbers as numbers.

One frozen tree of links and joints in the source's document order, the same for every
format: a URDF's elements read once, each number parsed once (lenient forms reported where
they are read), and the other formats' models in the same terms. The translation
(importer/translate) turns it into a spec and reads nothing else of the source.

Units and frames are the URDF's: metres, radians (metres for a prismatic joint's limits),
kilograms, kg m^2 about the CoM in the inertial frame; a joint's origin places its child
link's frame in its parent link's frame, a geometry's origin in its link's frame, and
`rpy` is fixed-axis roll, pitch, yaw. A value the source leaves out is None where the
translation tells absence apart from a default (a limit), else the default (a zero origin).

Each node keeps `at`, where it is in the source (tag, name, line), for report lines: an
`At` reads like the lxml element diagnostics name (`sourceline`, `tag`, `get("name")`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

Vec3 = tuple[float, float, float]
ZERO: Vec3 = (0.0, 0.0, 0.0)


@dataclass(frozen=True)
class At:
    """Where a node is in the source file: its element's tag, name and line (None: unknown;
    a format without lines, a compiled MJCF's added link, says 0 or None)."""

    tag: str
    name: str | None = None
    sourceline: int | None = None

    def get(self, key: str, default=None):
        """The element's `name` (diagnostics.describe reads it so); no other attribute."""
        return self.name if key == "name" and self.name is not None else default

    @classmethod
    def of(cls, element) -> At:
        """The place of an lxml element (or of anything with tag, get and sourceline)."""
        return cls(str(element.tag), element.get("name"), element.sourceline)


@dataclass(frozen=True)
class Pose:
    """An `<origin>`: xyz (m) and rpy (rad) in the parent's frame; `at` None when absent."""

    xyz: Vec3 = ZERO
    rpy: Vec3 = ZERO
    at: At | None = None


@dataclass(frozen=True)
class Inertial:
    """A link's `<inertial>`: `mass` (kg; None when no `<mass>` or not a number, which
    reads as massless), the CoM frame `origin`, and `inertia` (ixx, iyy, izz, ixy, ixz,
    iyz; kg m^2 about the CoM in the origin's axes; None without `<inertia>`)."""

    at: At
    origin: Pose = Pose()
    mass: float | None = None
    mass_at: At | None = None
    inertia: tuple[float, float, float, float, float, float] | None = None
    inertia_at: At | None = None

    @property
    def massive(self) -> bool:
        """A positive mass (a link without one is massless: estimated or a frame)."""
        return self.mass is not None and self.mass > 0


@dataclass(frozen=True)
class Shape:
    """A `<geometry>`'s shape: `kind` is box, cylinder, capsule, sphere or mesh (or the tag
    of a shape simkit does not read, which the translation reports); sizes in m, `filename`
    a mesh's URI as written, `scale` its per-axis scale."""

    kind: str
    at: At
    size: Vec3 | None = None
    radius: float | None = None
    length: float | None = None
    filename: str | None = None
    scale: Vec3 = (1.0, 1.0, 1.0)


@dataclass(frozen=True)
class Material:
    """A `<material>`: its name and its `<color>` rgba (0..1; None without one)."""

    at: At
    name: str | None = None
    rgba: tuple[float, float, float, float] | None = None


@dataclass(frozen=True)
class Geometry:
    """A `<visual>` or `<collision>`: its pose in the link frame, its shape (None: none
    given), its material (visuals) and `piece_of`, the one source several convex pieces
    come from (a USD's split collision mesh: formats/usd/shapes.py)."""

    at: At
    origin: Pose = Pose()
    shape: Shape | None = None
    material: Material | None = None
    piece_of: str | None = None


@dataclass(frozen=True)
class Link:
    """A `<link>` and what it holds; `unknown`: its child elements simkit does not read."""

    name: str
    at: At
    inertial: Inertial | None = None
    visuals: tuple[Geometry, ...] = ()
    collisions: tuple[Geometry, ...] = ()
    unknown: tuple[At, ...] = ()

    @property
    def massive(self) -> bool:
        return self.inertial is not None and self.inertial.massive

    @property
    def drawn(self) -> bool:
        """Whether it has any visual or collision element."""
        return bool(self.visuals or self.collisions)


@dataclass(frozen=True)
class Limit:
    """A `<limit>`: position limits (rad or m), effort (N m or N), velocity (rad/s or
    m/s) and a spherical joint's `twist` (rad), each None when not given."""

    at: At
    lower: float | None = None
    upper: float | None = None
    effort: float | None = None
    velocity: float | None = None
    twist: float | None = None


@dataclass(frozen=True)
class Dynamics:
    """A `<dynamics>`: damping (N m s/rad or N s/m) and friction (N m or N), None when not
    given."""

    at: At
    damping: float | None = None
    friction: float | None = None


@dataclass(frozen=True)
class Mimic:
    """A `<mimic>`: q = multiplier q_leader + offset (rad or m)."""

    at: At
    joint: str | None = None
    multiplier: float = 1.0
    offset: float = 0.0


@dataclass(frozen=True)
class Joint:
    """A `<joint>`: type as written (revolute, continuous, prismatic, fixed, floating,
    spherical, or another the translation refuses), parent and child link names (None when
    the element or its `link` is missing), the child frame's `origin`, the unit-free `axis`
    (None without `<axis>`) and the optional elements. `listed` names a format's own
    element this joint stands for (an MJCF weld, in `source_differences`)."""

    name: str | None
    type: str
    at: At
    parent: str | None = None
    child: str | None = None
    origin: Pose = Pose()
    axis: Vec3 | None = None
    axis_at: At | None = None
    limit: Limit | None = None
    dynamics: Dynamics | None = None
    mimic: Mimic | None = None
    unknown: tuple[At, ...] = ()
    listed: str | None = None


@dataclass(frozen=True)
class Robot:
    """The robot: links and joints in document order, every `<material>` with a colour
    (anywhere in the document, by name: a visual names one), and the top-level elements
    that are none of these (`others`: reported or kept by the format)."""

    at: At
    name: str | None = None
    links: tuple[Link, ...] = ()
    joints: tuple[Joint, ...] = ()
    materials: tuple[Material, ...] = ()
    others: tuple[At, ...] = ()
    _by_name: dict = field(default_factory=dict, compare=False, repr=False, init=False)

    def link(self, name: str | None) -> Link | None:
        """The first link of that name (None: none)."""
        return self._index()[0].get(name)

    def joint(self, name: str | None) -> Joint | None:
        """The first joint of that name (None: none)."""
        return self._index()[1].get(name)

    def _index(self) -> tuple[dict, dict]:
        if not self._by_name:
            links: dict = {}
            joints: dict = {}
            for link in self.links:
                links.setdefault(link.name, link)
            for joint in self.joints:
                joints.setdefault(joint.name, joint)
            self._by_name.update(links=links, joints=joints)
        return self._by_name["links"], self._by_name["joints"]
