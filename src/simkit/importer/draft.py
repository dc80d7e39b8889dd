"""The import in progress: one in-memory spec draft that the import's steps change in turn.

`import_robot` (importer/__init__.py) translates the URDF into a draft, passes it through
the ordered fix-up steps (importer/fixups.py), and writes and validates it once at the end
(writer.finish). A step reads the resolved robot (`Draft.robot()`, resolved from the draft
on first use after a change, never from a file) and records what it changes through the
draft's methods, each with its report line at the URDF element that caused it.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from simkit.importer.report import Report
from simkit.importer.source import Source


@dataclass
class Draft:
    """The spec dict being built, its report, the URDF it comes from (`source`, at `path`)
    and the staging folder (`stage`) that holds its meshes, against which the spec's
    relative mesh paths resolve."""

    source: Source
    path: Path
    stage: Path
    report: Report
    spec: dict = field(default_factory=dict)
    #: the resolved model of `spec`, or None after a change (resolved again on demand)
    resolved: object | None = None
    #: legs hang from the root (base.decide), whether or not the base floats
    legged: bool = False
    #: the URDF as read, before any rewrite (provenance.as_read): what the kit is compared with
    kept: Source | None = None
    #: names.make_legal's renames, {"links" | "joints" | "frames": {URDF name: spec name}}
    renames: dict = field(default_factory=dict)

    def robot(self):
        """The draft as simkit's model (model/resolve.py): schema-checked, not yet
        validated as a whole (writer.finish does that once)."""
        if self.resolved is None:
            from simkit.model.resolve import resolve
            from simkit.spec.schema import RobotSpec

            try:
                spec = RobotSpec.model_validate(self.spec)
            except ValueError:  # a pydantic error: one line at the URDF element
                self._refuse()
            self.resolved = resolve(spec, b"", f"{self.spec['name']}.yaml")
        return self.resolved

    def _refuse(self) -> None:
        """Raise the spec's first problem where the URDF holds it (importer/located.py): a
        draft the fix-ups cannot resolve (a mass of 1e308) stops in one line, not deep in a
        fix-up."""
        from simkit.importer import located, writer

        staged = self.stage / f"{self.spec['name']}.yaml"
        staged.write_text(writer.spec_yaml(self.spec, self.report.lines, self.path), "utf-8")
        located.check(staged, self.spec, self.source, self.renames)
        raise RuntimeError("a spec the schema refused passed simkit's validation")

    def changed(self) -> None:
        """Forget the resolved model after a change of `spec`."""
        self.resolved = None

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
        self.report.assumed(
            self.source,
            self.source.root,
            f"home: {why}; " + ", ".join(changes) + " rad or m",
        )
        self.changed()

    def estimate_base(self, keys: tuple[str, ...], **values: list[float]) -> None:
        """Set the base joint's `xyz` and/or `rpy` (m, rad), marked estimated."""
        joint = self.base_joint
        joint.update(values)
        joint["estimated"] = sorted({*joint.get("estimated", []), *keys})
        self.changed()
