"""The importer's shape (issue 22): one in-memory draft through ordered steps, written and
validated once; the base decided from the robot's structure; URDF names kept; masses
estimated from the visual solid where the URDF gives none."""

from __future__ import annotations

from pathlib import Path

import yaml

from simkit.importer import import_robot, writer

URDF = Path(__file__).resolve().parent / "specs" / "urdf"
ARM = URDF / "pkg_demo" / "urdf" / "arm.urdf"


def _inertial(mass: float | None, xyz: str = "0 0 0") -> str:
    if mass is None:
        return ""
    return (
        f'<inertial><origin xyz="{xyz}"/><mass value="{mass}"/>'
        '<inertia ixx="0.001" iyy="0.001" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial>'
    )


def box(name: str, size: str, xyz: str = "0 0 0", mass: float | None = 1.0) -> str:
    """A link: a box (visual and collision) at `xyz`, with `mass` kg there (None: none)."""
    geometry = f'<origin xyz="{xyz}"/><geometry><box size="{size}"/></geometry>'
    return (
        f'<link name="{name}">{_inertial(mass, xyz)}<visual>{geometry}</visual>'
        f"<collision>{geometry}</collision></link>"
    )


def joint(name, kind, parent, child, xyz, axis="0 1 0", lower=-1.0, upper=1.0, effort=50):
    limit = f'<limit lower="{lower}" upper="{upper}" effort="{effort}" velocity="2"/>'
    return (
        f'<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>'
        f'<origin xyz="{xyz}"/><axis xyz="{axis}"/>{limit if kind != "fixed" else ""}</joint>'
    )


def write(tmp_path: Path, body: str, name: str = "robot") -> Path:
    path = tmp_path / f"{name}.urdf"
    path.write_text(f'<?xml version="1.0"?>\n<robot name="{name}">{body}</robot>\n')
    return path


def test_one_import_writes_and_validates_the_spec_once(tmp_path, monkeypatch):
    calls = {"spec_yaml": 0, "check": 0}
    spec_yaml, check = writer.spec_yaml, writer.check

    def counted_yaml(*args, **kwargs):
        calls["spec_yaml"] += 1
        return spec_yaml(*args, **kwargs)

    def counted_check(*args, **kwargs):
        calls["check"] += 1
        return check(*args, **kwargs)

    monkeypatch.setattr(writer, "spec_yaml", counted_yaml)
    monkeypatch.setattr(writer, "check", counted_check)
    done = import_robot(ARM, tmp_path)
    assert calls == {"spec_yaml": 1, "check": 1}
    assert yaml.safe_load(done.spec_path.read_text())["name"] == "arm"
    assert [p.name for p in tmp_path.iterdir() if p.name.startswith(".import-")] == []


def test_reimport_is_byte_identical_and_leaves_no_stale_mesh(tmp_path):
    first = import_robot(ARM, tmp_path / "out")
    files = {p: p.read_bytes() for p in (tmp_path / "out").rglob("*") if p.is_file()}
    stale = tmp_path / "out" / "meshes" / "gone.stl"
    spec = yaml.safe_load(first.spec_path.read_text())
    mesh = next(s for link in spec["links"] for s in link.get("solid", []) if "file" in s)
    # an earlier import that used a mesh this one does not
    stale.write_bytes((tmp_path / "out" / mesh["file"]).read_bytes())
    text = first.spec_path.read_text().replace(mesh["file"], "meshes/gone.stl", 1)
    first.spec_path.write_text(text)
    import_robot(ARM, tmp_path / "out")
    again = {p: p.read_bytes() for p in (tmp_path / "out").rglob("*") if p.is_file()}
    assert again == files
