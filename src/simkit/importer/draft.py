"""The import in progress: one typed draft that every step of the import receives in turn.

`import_robot` (importer/__init__.py) makes a draft of the read source and the user's
`Options`, passes it through the ordered steps (importer.STEPS: translate.to_spec, then
fixups.STEPS), and writes and validates it once at the end (write.finish). A step reads the
resolved robot (`Draft.robot()`, resolved from the draft on first use after a change, never
from a file) and records what it changes through the draft's methods, each with its report
record at the source element that caused it.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from simkit.importer.diagnostics import Report
from simkit.importer.read.source import Source
from simkit.model.resolve import resolve
from simkit.model.robot import Robot
from simkit.spec.schema import RobotSpec

#: kg/m^3 of an estimated solid (`--density` sets another): the median mass / visual volume
#: of the 238 distinct links that give both in example-robot-data and pybullet_data (1373;
#: quartiles 762 and 2712; `scripts/density_from_corpora.py`, docs/import-corpus.md class
#: 6a). Most links are hollow shells, so aluminium's 2700 doubled an arm's mass.
DENSITY = 1400.0


class Unresolvable(Exception):
    """The draft's spec is one the schema refuses (a mass of 1e308): the import stops, and
    write.refuse names the source element in one line (the draft cannot: write sits above
    it in the importer's layers)."""


@dataclass(frozen=True)
class Options:
    """What the user asked of the import: the spec's `name`; `floating` True or False sets
    the base, None decides it from the robot's structure (translate/base.py); with
    `hull_collision`, collision meshes are the visual's convex hull; `density` (kg/m^3) makes
    a massless link's mass from its solid."""

    name: str
    floating: bool | None = None
    hull_collision: bool = False
    density: float = DENSITY


@dataclass
class Draft:
    """The spec dict being built, its report, the URDF it comes from (`source`, at `path`),
    the user's `options` and the staging folder (`stage`) that holds its meshes, against
    which the spec's relative mesh paths resolve."""

    source: Source
    path: Path
    stage: Path
    report: Report
    options: Options
    spec: dict = field(default_factory=dict)
    #: the resolved model of `spec`, or None after a change (resolved again on demand)
    resolved: Robot | None = None
    #: legs hang from the root (base.decide), whether or not the base floats
    legged: bool = False
    #: the URDF as read, before any rewrite (provenance.as_read): what the kit is compared with
    kept: Source | None = None
    #: names.make_legal's renames, {"links" | "joints" | "frames": {URDF name: spec name}}
    renames: dict = field(default_factory=dict)
    #: mesh files translate wrote into `stage`
    meshes: int = 0
    #: (what, reason) of differences the fix-ups make, added to `source_differences` by
    #: the format's keep (fixups/overlap.py: pairs excluded at the source's home)
    listed: list = field(default_factory=list)
    #: the source's first element of each (tag, name), built on first use by `where`

    def robot(self) -> Robot:
        """The draft as simkit's model (model/resolve.py): schema-checked, not yet
        validated as a whole (write.finish does that once); `Unresolvable` when the schema
        refuses it."""
        if self.resolved is None:
            try:
                spec = RobotSpec.model_validate(self.spec)
            except ValueError as exc:  # a pydantic error: one line at the URDF element
                raise Unresolvable(str(exc)) from None
            self.resolved = resolve(spec, b"", f"{self.spec['name']}.yaml")
        return self.resolved

    def where(self, tag: str, name: str, child: str | None = None):
        """Where in the source a report record about spec item `name` points: the first
        link or joint (`tag`) of that name in the source model (its `child` element, a
        joint's `limit`, when it has one), else the document's root. The fix-ups locate
        their records so, without querying the source."""
        robot = self.source.robot
        node = robot.joint(name) if tag == "joint" else robot.link(name)
        if node is None:
            return robot.at
        found = getattr(node, child, None) if child else None
        return node.at if found is None else found.at

    def note(self, message: str, where=None) -> None:
        """A report record (`estimated`, never refused by --strict) of a value the import
        chose, at `where` (an element `where()` gave), else the document's root."""
        self.report.assumed(self.source, self.source.robot.at if where is None else where, message)

    def note_named(self, tag: str, name: str, message: str) -> None:
        """A report record (`changed`) at the first `<tag name=...>` anywhere in the source
        (a renamed link or joint, by its source name)."""
        robot = self.source.robot
        node = robot.joint(name) if tag == "joint" else robot.link(name)
        self.report.changed(self.source, None if node is None else node.at, message)

    def note_change(self, message: str) -> None:
        """A report record (`changed`) of the robot kept in another form, at the root."""
        self.report.changed(self.source, self.source.robot.at, message)

    def changed(self) -> None:
        """Forget the resolved model after a change of `spec`."""
        self.resolved = None

    @property
    def source_noun(self) -> str:
        """The source format's word, for report lines ("URDF", "MJCF")."""
        return self.source.noun

    @property
    def a_noun(self) -> str:
        """The source format's word with its article, for report lines ("an MJCF")."""
        return self.source.a_noun

    @property
    def floating(self) -> bool:
        return bool(self.spec.get("floating_base"))

    @property
    def base_joint(self) -> dict:
        """The spec joint that holds the root link to the world (fixed or floating)."""
        return self.spec["joints"][0]

    def movable(self) -> list[dict]:
        """The spec's one-degree-of-freedom joints, in spec (pose) order."""
        return [j for j in self.spec["joints"] if j["type"] not in ("fixed", "floating")]

    def set_home(self, found: tuple[list[float], list[str]] | None, why: str) -> None:
        """Take a searched `home` (`found`: (pose, changes `joint: a -> b`), or None for no
        change) with one report line giving the reason."""
        if found is None:
            return
        self.spec["poses"]["home"], changes = found
        self.note(f"home: {why}; " + ", ".join(changes) + " rad or m")
        self.changed()

    def estimate_base(self, keys: tuple[str, ...], **values: list[float]) -> None:
        """Set the base joint's `xyz` and/or `rpy` (m, rad), marked estimated."""
        joint = self.base_joint
        joint.update(values)
        joint["estimated"] = sorted({*joint.get("estimated", []), *keys})
        self.changed()
