"""`simkit import`: a URDF (or xacro) to a spec plus the meshes it needs (issue 15).

The spec keeps the URDF's numbers exactly; gaps are filled with plausible values listed under
`estimated` and reported one line each (`--strict` refuses them), and every element simkit
does not keep is reported too. Output: DIR/NAME.yaml and DIR/meshes/*.stl (relative paths),
written only when the whole import succeeded.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

from simkit.errors import SpecError
from simkit.importer.reading import ReadOptions
from simkit.importer.report import Report


@dataclass(frozen=True)
class Imported:
    """The written spec, its report lines and the number of meshes written."""

    spec_path: Path
    lines: tuple[str, ...]
    meshes: int
    links: int


def _stand(spec: dict, report: Report, doc, spec_path: Path, path: Path) -> str:
    """Move home out of self-contact and onto a stance it rests on (`_free_stance`), raise
    the floating base so the robot stands on the floor at home; rewrite the spec."""
    from simkit.importer import standing, upright, writer

    joint = spec["joints"][0]
    turned = upright.upright(spec_path)
    if turned is not None:  # a Y-up robot lies on its side at the identity
        joint["rpy"], joint["estimated"] = [float(f"{v:.6g}") for v in turned[0]], ["rpy"]
        report.assumed(doc, doc.root, turned[1])
        spec_path.write_text(writer.spec_yaml(spec, report.lines, path), encoding="utf-8")
    _free_stance(spec, report, doc, spec_path, path)
    height = standing.standing_height(spec_path)
    if height is None:
        return spec_path.read_text(encoding="utf-8")
    joint["xyz"] = [0.0, 0.0, float(f"{height:.6f}")]
    joint["estimated"] = sorted({*joint.get("estimated", []), "xyz"})
    report.changed(
        doc,
        doc.root,
        f"floating base placed {height:.6f} m up: its lowest point at home on the floor",
    )
    text = writer.spec_yaml(spec, report.lines, path)
    spec_path.write_text(text, encoding="utf-8")
    return _settle(spec, report, doc, spec_path, path) or text


def _settle(spec: dict, report: Report, doc, spec_path: Path, path: Path) -> str | None:
    """Start the free joint where the robot comes to rest at home when that is tilted onto
    its frame (importer/settle.py: a flying arm leaning on its arm); the new spec text."""
    from simkit.importer import settle, writer

    found = settle.rest_pose(spec_path)
    if found is None:
        return None
    pose, rest, why = found
    if pose != spec["poses"]["home"]:
        moved = ", ".join(
            f"{j['name']}: {a:.4g} -> {b:.4g}"
            for j, a, b in zip(_movable(spec), spec["poses"]["home"], pose, strict=True)
            if a != b
        )
        why = f"home: the rest with the least servo load; {moved} rad or m; " + why
        spec["poses"]["home"] = pose
    joint = spec["joints"][0]
    joint["xyz"] = [round(v, 4) + 0.0 for v in rest.xyz]
    joint["rpy"] = [round(v, 4) + 0.0 for v in rest.rpy]
    joint["estimated"] = sorted({*joint.get("estimated", []), "xyz", "rpy"})
    report.assumed(doc, doc.root, why)
    text = writer.spec_yaml(spec, report.lines, path)
    spec_path.write_text(text, encoding="utf-8")
    return text


def _movable(spec: dict) -> list[dict]:
    """The spec's one-degree-of-freedom joints, in spec (pose) order."""
    return [j for j in spec["joints"] if j["type"] not in ("fixed", "floating")]


def _step_budget(spec: dict, stage: Path, report: Report, doc) -> None:
    """`step: false` (reported) when the visual meshes are too large for a faceted STEP."""
    from simkit.importer.step_budget import step_fits

    fits, why = step_fits(spec, stage)
    if not fits:
        spec["step"] = False
        report.changed(doc, doc.root, why)


def _up_axis(doc, mesh_writer, report: Report) -> None:
    """Turn the URDF's Y_UP COLLADA meshes Z-up where its joints and inertials say they were
    drawn so (up_axis.py); one report line either way when it has such meshes."""
    from simkit.importer.up_axis import turn_y_up

    mesh_writer.turn_y_up, why = turn_y_up(doc)
    if why:
        report.changed(doc, doc.root, why)


def robot_name(path: Path) -> str:
    """A spec name (`[a-z][a-z0-9_]*`) from a file name."""
    stem = path.name.split(".")[0].lower()
    name = re.sub(r"[^a-z0-9_]+", "_", stem).strip("_") or "robot"
    return name if name[0].isalpha() else f"robot_{name}"


def _free_home(spec: dict, report: Report, doc, spec_path: Path, path: Path) -> None:
    """Move a fixed-base robot's `home` out of self-contact (home.py), then to where its
    servos can hold it against gravity (gravity.py); rewrite the spec."""
    from simkit.importer import gravity, home

    why = "the links collide at the first guess (0, or mid-range outside the limits)"
    _new_home(home.free_home(spec_path), why, spec, report, doc, spec_path, path)
    held = gravity.held_home(spec_path)
    if held is not None:
        _new_home(held[:2], held[2], spec, report, doc, spec_path, path)


def _new_home(found, why: str, spec: dict, report: Report, doc, spec_path: Path, path: Path):
    """Record a searched `home` (`found`: (pose, changes) or None) with one report line and
    rewrite the spec."""
    from simkit.importer import writer

    if found is None:
        return
    spec["poses"]["home"], changes = found
    report.assumed(doc, doc.root, f"home: {why}; " + ", ".join(changes) + " rad or m")
    spec_path.write_text(writer.spec_yaml(spec, report.lines, path), encoding="utf-8")


def import_robot(
    path: Path,
    out_dir: Path,
    name: str | None = None,
    package_dirs: tuple[Path, ...] = (),
    strict: bool = False,
    floating: bool = False,
    hull_collision: bool = False,
    reading: ReadOptions | None = None,
) -> Imported:
    """Import `path` into `out_dir`; SpecError (one line) on input simkit cannot use.
    `hull_collision`: links whose URDF collision has meshes collide with their visual
    solid's convex hull instead (one piece; reported per link). `reading`: what the reader
    may do (xacro args, environment, files outside the package; importer/reading.py)."""
    from simkit.importer import blocks, convert, located, meshes, names, provenance, source, writer
    from simkit.importer.output import publish, staging

    name = name or robot_name(path)
    if not re.fullmatch(r"[a-z][a-z0-9_]*", name):
        raise SpecError(str(path), None, "--name", f"'{name}' is not [a-z][a-z0-9_]*")
    report = Report(strict=strict)
    doc = source.load(path, package_dirs, report, reading)
    with staging(out_dir) as stage:  # removed on every way out, SIGTERM included
        mesh_writer = meshes.MeshWriter(stage)
        _up_axis(doc, mesh_writer, report)
        spec = convert.convert(doc, name, mesh_writer, report, floating, hull_collision)
        renames = names.make_legal(spec, doc, report)
        blocks.keep(spec, doc, report, blocks.collect(doc), renames)
        if strict and report.problems:
            first = report.problems[0]
            first.more = len(report.problems) - 1
            raise SpecError(first.file, first.line, first.field, first.message, first.more)
        _step_budget(spec, stage, report, doc)
        text = writer.spec_yaml(spec, report.lines, path)
        (stage / f"{name}.yaml").write_text(text, encoding="utf-8")
        located.check(stage / f"{name}.yaml", spec, doc, renames)  # before the pose fix-ups
        if floating:  # stance.py: out of self-contact with the feet kept, then stand
            text = _stand(spec, report, doc, stage / f"{name}.yaml", path)
        else:  # home.py: out of self-contact, any joint between touching links may move
            _free_home(spec, report, doc, stage / f"{name}.yaml", path)
        _narrow_limits(spec, report, doc, stage / f"{name}.yaml", path)
        provenance.record(spec, doc, report, renames, stage / f"{name}.yaml", path)
        located.check(stage / f"{name}.yaml", spec, doc, renames)
        publish(stage, out_dir)  # each file whole, or one line naming it
    return Imported(
        out_dir / f"{name}.yaml", tuple(report.lines), len(mesh_writer.done), len(spec["links"])
    )


def _free_stance(spec: dict, report: Report, doc, spec_path: Path, path: Path) -> None:
    """Move a floating robot's `home` out of self-contact, feet kept (stance.py); rewrite the
    spec."""
    from simkit.importer import stance

    why = (
        "at the first guess (0, or mid-range outside the limits) links collide or the robot "
        "cannot rest on the floor"
    )
    _new_home(stance.free_home(spec_path), why, spec, report, doc, spec_path, path)


def _narrow_limits(spec: dict, report: Report, doc, spec_path: Path, path: Path) -> None:
    """Estimated position limits narrowed to the joint's range free of self-contact from home
    (limits.py), one report line per joint; rewrite the spec."""
    from simkit.importer import limits, writer

    found = limits.narrowed(spec_path)
    if not found:
        return
    for joint in spec["joints"]:
        if joint["name"] in found:
            old = (joint["lower"], joint["upper"])
            joint["lower"], joint["upper"] = found[joint["name"]]
            element = doc.root.find(f"joint[@name='{joint['name']}']")
            report.assumed(
                doc,
                doc.root if element is None else element,
                f"estimated limits {old[0]:.4g} .. {old[1]:.4g} narrowed to "
                f"{joint['lower']:.4g} .. {joint['upper']:.4g}, the range the joint turns "
                "from home without self-contact",
            )
    spec_path.write_text(writer.spec_yaml(spec, report.lines, path), encoding="utf-8")
