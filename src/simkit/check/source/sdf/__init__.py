"""The kit is the SDFormat robot it was imported from, proved through Drake's SDFormat parser
(libsdformat inside `pydrake`), not simkit's reader: Drake reads the source SDF and the
kit's URDF into two MultibodyPlants, and this compares, under the source's names (robot.json
renames applied; a nested model's `a::b`):

- joint types (a ball as three revolute joints NAME_x, NAME_y, NAME) and position limits;
- every body's mass, CoM and inertia (<= 1e-6 relative), in the kit's link frame;
- every body's pose, and every `<frame>`'s the kit carries as a frame, at 100 seeded
  configurations (<= 1e-6 m, 1e-6 in rotation), relative to
  the world where the source mounts the robot on it, else to the root body;
- masses and joint limits against the kit's composed USD too (kit_usd.py).

Frames: the kit's link frame of a body is its inboard joint's frame (Drake's frame on the
child), the body frame itself for the root, as the import defines it
(importer/formats/sdf/tree.py). A difference passes only where robot.json's
`source_differences` lists it. The source's files (includes, meshes) are laid out from
`NAME.source.assets/SHA256.EXT` (or beside a given file), each checked against its recorded
digest; each top folder is a model (`model://NAME`).

The package: this module lays the source's files out and runs the proof; plant.py reads a
file with Drake (`Plant`), comparison.py compares two plants (`Compare`).

Without `pydrake` the proof cannot run: one failing finding says `pip install drake`. It
fails rather than skips because the user asked for this proof (`--source`, or a build of an
imported spec), and a kit whose source is unproved must not pass silently; the other format's
proofs fail likewise when their reader cannot run.
"""

from __future__ import annotations

import hashlib
import tempfile
from pathlib import Path, PurePosixPath

import numpy as np

from simkit.check.findings import Finding, require
from simkit.check.kit import Kit
from simkit.check.source import kit_usd as source_usd
from simkit.check.source.sdf.comparison import FK_TOL, SEEDS, SPLIT, Compare
from simkit.check.source.sdf.plant import Plant
from simkit.check.source.shared import SHOWN, Allowed
from simkit.kitio.oneline import one_line

__all__ = [
    "FK_TOL",
    "SEEDS",
    "SPLIT",
    "Compare",
    "Plant",
    "compare",
    "model_folders",
    "remake",
    "usd_view",
]


def remake(path: Path, args: dict[str, str]) -> bytes:
    """The kept file made from the original: an SDF is kept byte for byte."""
    return path.read_bytes()


def compare(kit: Kit, path: Path) -> list[Finding]:
    """Findings for the SDF at `path` against the kit's URDF, both read by Drake."""
    try:
        import pydrake  # noqa: F401
    except ImportError:
        why = "the SDFormat source proof reads the source with Drake: pip install drake"
        return [require("source.read", False, why)]
    recorded = kit.doc.get("source") or {}
    if hashlib.sha256(path.read_bytes()).hexdigest() != recorded.get("sha256"):
        return []  # not the file the import read (source.digest fails): never read
    with tempfile.TemporaryDirectory(prefix="simkit-source-") as tmp:
        main, problems = _lay_out(path, recorded, Path(tmp))
        if problems:
            return [require("source.digest", False, p) for p in problems[:SHOWN]]
        try:
            source = Plant(main, Path(tmp))
        except Exception as exc:  # Drake raises RuntimeError with its parser's message
            return [require("source.read", False, f"Drake cannot read the source: {_why(exc)}")]
    try:
        built = Plant(kit.path(kit.urdf), kit.path(".").parent)
    except Exception as exc:
        return [require("source.read", False, f"Drake cannot read the kit's URDF: {_why(exc)}")]
    allowed = Allowed.of(kit.doc)
    return Compare(source, built, allowed).findings() + source_usd.compare(
        kit, usd_view(source), allowed
    )


def usd_view(source: Plant) -> tuple[dict[str, float], dict[str, tuple]]:
    """The source as kit_usd.py compares it with the kit's USD: ({link: mass kg},
    {joint: (revolute or prismatic, (lower, upper) deg or m, or None)})."""
    masses = {name: float(body.default_mass()) for name, body in source.bodies.items()}
    joints: dict[str, tuple] = {}
    for name, joint in source.joints.items():
        kind = joint.type_name()
        if kind not in ("revolute", "prismatic"):
            continue
        low, high = joint.position_lower_limits()[0], joint.position_upper_limits()[0]
        scale = np.degrees(1.0) if kind == "revolute" else 1.0
        finite = np.isfinite(low) and np.isfinite(high)
        joints[name] = (kind, (low * scale, high * scale) if finite else None)
    return masses, joints


def _why(exc: Exception) -> str:
    return one_line(" ".join(str(exc).split())[:300])


def _lay_out(given: Path, recorded: dict, folder: Path) -> tuple[Path, list[str]]:
    """The source's files in `folder` as the import read them (relative to the model
    path); the model file's place in it, and problems (a file missing or changed)."""
    digest = recorded.get("sha256")
    kept = given.parent / (given.name.removesuffix(".sdf") + ".assets")
    main, problems = folder / given.name, []
    assets = recorded.get("assets") or {}
    key = next((rel for rel, want in assets.items() if want == digest), given.name)
    up = given.resolve().parents
    base = up[min(len(PurePosixPath(key).parts), len(up)) - 1]  # the model path
    for rel, want in sorted(assets.items()):
        target = (folder / rel).resolve()
        if folder.resolve() not in target.parents or ".." in rel.split("/"):
            problems.append(f"asset '{rel}' lies outside the source's folder")
            continue
        if want == digest:
            main = target
        found = [given] if want == digest else []
        found += [
            base / rel,
            kept / f"{want}{PurePosixPath(rel).suffix.lower()}",
        ]
        for candidate in found:
            if candidate.is_file() and hashlib.sha256(candidate.read_bytes()).hexdigest() == want:
                target.parent.mkdir(parents=True, exist_ok=True)
                target.write_bytes(candidate.read_bytes())
                break
        else:
            problems.append(f"source file '{rel}' is missing or not the one the import read")
    if not main.is_file():
        main.write_bytes(given.read_bytes())
    for laid in folder.rglob("*.sdf"):
        model_folders(laid, folder)
    return main, problems


def model_folders(path: Path, folder: Path) -> None:
    """`<uri>model://NAME</uri>` (a model folder, which Gazebo reads through its
    model.config and Drake does not) made `model://NAME/FILE`, the newest SDF the laid-out
    model.config names; in the laid-out copy only."""
    import re

    def named(match: re.Match) -> bytes:
        file = _config_file(folder / match.group(1).decode() / "model.config")
        return b"<uri>model://%s/%s</uri>" % (match.group(1), file.encode()) if file else match[0]

    data = path.read_bytes()
    done = re.sub(rb"<uri>\s*model://([A-Za-z0-9_.-]+)/?\s*</uri>", named, data)
    if done != data:
        path.write_bytes(done)


def _config_file(config: Path) -> str | None:
    """The SDF file a model.config names (its newest `<sdf version>`), or None."""
    from lxml import etree

    try:
        root = etree.fromstring(config.read_bytes(), etree.XMLParser(resolve_entities=False))
    except (OSError, etree.XMLSyntaxError):
        return None
    named = []
    for element in root.iter("sdf"):
        version = tuple(int(v) for v in (element.get("version") or "0").split(".") if v.isdigit())
        if (element.text or "").strip():
            named.append((version, element.text.strip()))
    return max(named)[1] if named else None
