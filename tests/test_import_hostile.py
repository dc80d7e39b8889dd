"""Import crashes and hangs found with hostile or unlucky URDFs (issue 24): each is now a
one-line error naming the URDF or the path, or an import that works; nothing half-written and
no staging folder left behind, also on SIGTERM, after a kill, or on a full disk."""

from __future__ import annotations

import os
import resource
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
import yaml

from simkit.errors import SimkitError, SpecError
from simkit.importer import import_robot

BOX = '<geometry><box size="0.05 0.05 0.2"/></geometry>'


def _link(name: str, mass: str = "1", geometry: str = BOX) -> str:
    return (
        f'<link name="{name}"><inertial><mass value="{mass}"/><inertia ixx="0.001" iyy="0.001" '
        'izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial>'
        f"<visual>{geometry}</visual><collision>{geometry}</collision></link>"
    )


def _joint(name: str, parent: str, child: str, z: float = 0.2) -> str:
    return (
        f'<joint name="{name}" type="revolute"><parent link="{parent}"/><child link="{child}"/>'
        f'<origin xyz="0 0 {z}"/><axis xyz="1 0 0"/>'
        '<limit lower="-1" upper="1" effort="20" velocity="2"/></joint>'
    )


def _write(tmp_path: Path, *body: str, name: str = "r", head: str = "") -> Path:
    urdf = tmp_path / f"{name}.urdf"
    text = (
        f'<?xml version="1.0"?>\n{head}<robot name="{name}">\n' + "\n".join(body) + "\n</robot>\n"
    )
    urdf.write_text(text)
    return urdf


def _no_staging(out: Path) -> None:
    assert not [p.name for p in out.glob(".import-*")]


def test_a_root_link_named_world_with_geometry_imports(tmp_path):
    urdf = _write(tmp_path, _link("world"), _link("arm"), _joint("j1", "world", "arm"))
    done = import_robot(urdf, tmp_path / "out")  # looped forever, growing memory
    spec = yaml.safe_load(done.spec_path.read_text())
    assert [link["name"] for link in spec["links"]] == ["world_link", "arm"]
    assert spec["root"] == "world_frame"


def test_a_chain_longer_than_the_spec_limit_is_refused_in_one_line(tmp_path):
    """10,001 links, one more than a spec holds (spec/bounds.py MAX_BODIES): a one-line
    refusal naming the limit, before any per-link work. Chains up to the limit import
    (tests/test_long_chain.py; times: scripts/time_long_chain.py, docs/performance.md)."""
    body = [_link("l0")]
    for k in range(1, 10001):
        body += [_link(f"l{k}"), _joint(f"j{k}", f"l{k - 1}", f"l{k}", 0.01)]
    with pytest.raises(
        SpecError, match=r"r\.urdf:2: robot\[r\]: 10001 links: a spec holds at most 10000"
    ):
        import_robot(_write(tmp_path, *body), tmp_path / "out")
    _no_staging(tmp_path / "out")


def test_duplicate_joint_names_are_one_line(tmp_path):
    body = [_link("a"), _link("b"), _link("c"), _joint("j", "a", "b"), _joint("j", "b", "c")]
    with pytest.raises(SpecError, match=r"r\.urdf:7: joint\[j\]: joint 'j' is defined twice"):
        import_robot(_write(tmp_path, *body), tmp_path / "out")


def test_a_mass_of_1e308_is_one_line_at_the_link(tmp_path):
    body = [_link("base"), _link("arm", mass="1e308"), _joint("j", "base", "arm")]
    with pytest.raises(SpecError, match=r"r\.urdf:4: link\[arm\]: the imported spec's links\[1\]"):
        import_robot(_write(tmp_path, *body), tmp_path / "out")


def test_an_entity_inside_a_gazebo_block_is_left_out_with_a_report_line(tmp_path):
    head = '<!DOCTYPE robot [<!ENTITY plugin "libfoo.so">]>\n'
    gazebo = '<gazebo><plugin name="p" filename="&plugin;"/></gazebo>'
    urdf = _write(
        tmp_path, _link("base"), _link("arm"), _joint("j", "base", "arm"), gazebo, head=head
    )
    done = import_robot(urdf, tmp_path / "out")
    assert any("gazebo: not imported: not well-formed on its own" in line for line in done.lines)


def test_an_out_folder_that_cannot_be_created_is_one_line(tmp_path):
    urdf = _write(tmp_path, _link("base"), _link("arm"), _joint("j", "base", "arm"))
    (tmp_path / "file").write_text("")
    with pytest.raises(SimkitError, match=r"file/out: cannot write: Not a directory"):
        import_robot(urdf, tmp_path / "file" / "out")


@pytest.mark.skipif(os.geteuid() == 0, reason="root writes to read-only folders")
def test_a_read_only_out_folder_is_one_line(tmp_path):
    urdf = _write(tmp_path, _link("base"), _link("arm"), _joint("j", "base", "arm"))
    out = tmp_path / "out"
    out.mkdir(mode=0o500)
    with pytest.raises(SimkitError, match=r"cannot write: Permission denied"):
        import_robot(urdf, out)


def test_a_mesh_scale_that_leaves_no_finite_triangles_is_left_out(tmp_path):
    import trimesh

    trimesh.creation.box(extents=(0.1, 0.1, 0.1)).export(tmp_path / "part.stl")
    huge = '<geometry><mesh filename="part.stl" scale="1e300 1 1"/></geometry>'
    body = [_link("base"), _link("arm", geometry=huge), _joint("j", "base", "arm")]
    done = import_robot(_write(tmp_path, *body), tmp_path / "out")
    assert any("scale (1e+300, 1.0, 1.0) makes it" in line for line in done.lines)
    assert not (tmp_path / "out" / "meshes").exists()


def test_names_with_a_newline_cannot_inject_yaml(tmp_path):
    evil = "arm&#10;injected: 1"
    body = [_link("base"), _link(evil), _joint("j&#10;also: 2", "base", evil)]
    done = import_robot(_write(tmp_path, *body, name="n"), tmp_path / "out")
    text = done.spec_path.read_text()
    spec = yaml.safe_load(text)
    assert "injected" not in spec and "also" not in spec
    assert all(line.startswith("#") for line in text.splitlines()[: len(done.lines) + 2])
    assert "link[arm\\ninjected: 1]: changed: renamed" in text


def _import_until_staged(urdf, out):
    """`simkit import` in a child process, returned once its staging folder exists (or it
    ended). The command line turns SIGTERM into the normal clean-up (kitio/interrupt.py)."""
    cmd = [sys.executable, "-m", "simkit.cli", "import", str(urdf), "--out", str(out), "-q"]
    child = subprocess.Popen(cmd, stderr=subprocess.DEVNULL)
    deadline = time.monotonic() + 60
    while not list(out.glob(".import-*")) and child.poll() is None and time.monotonic() < deadline:
        time.sleep(0.01)
    return child


def test_a_folder_left_by_a_killed_import_is_removed_by_the_next(tmp_path):
    urdf = _write(tmp_path, _link("base"), _link("arm"), _joint("j", "base", "arm"))
    out = tmp_path / "out"
    child = _import_until_staged(urdf, out)
    child.send_signal(signal.SIGKILL)
    child.wait()
    left = list(out.glob(".import-*"))
    if not left:
        pytest.skip("the import ended before it could be killed")
    import_robot(urdf, out)
    _no_staging(out)


def test_sigterm_removes_the_staging_folder(tmp_path):
    body = [_link("l0")]
    for k in range(1, 40):  # long enough to be caught while it runs
        body += [_link(f"l{k}"), _joint(f"j{k}", f"l{k - 1}", f"l{k}", 0.05)]
    urdf = _write(tmp_path, *body)
    out = tmp_path / "out"
    child = _import_until_staged(urdf, out)
    if child.poll() is not None:
        pytest.skip("the import ended before SIGTERM")
    child.send_signal(signal.SIGTERM)
    child.wait(timeout=60)
    _no_staging(out)
    assert not (out / "r.yaml").exists()


def _limited(size: int):
    def apply() -> None:
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # a write past the limit fails: EFBIG
        resource.setrlimit(resource.RLIMIT_FSIZE, (size, size))

    return apply


def test_a_full_disk_is_one_line_and_leaves_nothing_truncated(tmp_path):
    """RLIMIT_FSIZE makes every write past 3,000 bytes fail, as a full disk does."""
    import trimesh

    trimesh.creation.icosphere(subdivisions=3).export(tmp_path / "ball.stl")  # 64 kB
    mesh = '<geometry><mesh filename="ball.stl" scale="0.05 0.05 0.05"/></geometry>'
    body = [_link("base"), _link("arm", geometry=mesh), _joint("j", "base", "arm")]
    urdf = _write(tmp_path, *body)
    out = tmp_path / "out"
    run = subprocess.run(
        [sys.executable, "-m", "simkit.cli", "import", str(urdf), "--out", str(out), "-q"],
        preexec_fn=_limited(3000),
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert run.returncode == 2, run.stderr
    assert "Traceback" not in run.stderr and run.stderr.count("\n") == 1
    assert "cannot write: File too large" in run.stderr
    assert [p.name for p in out.rglob("*")] == []  # no staging, no truncated mesh
