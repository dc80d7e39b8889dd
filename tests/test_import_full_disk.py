"""A failing import writes nothing in `--out` (issue 32, class 10): a full disk while the
finished files are moved into place leaves no spec, kept source or mesh, puts back the files
of an earlier import it had replaced, and removes the `--out` folder it made. The disk is
really full: a file size limit (RLIMIT_FSIZE) in a child process while the files move into
place, and, where root may mount one, a small tmpfs under a whole import; the one-line error
names the file's place under `--out`, never the staging folder."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from simkit.errors import SimkitError
from simkit.importer import import_robot


def _files(folder: Path) -> dict[str, bytes]:
    return {
        str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()
    }


def test_a_file_too_large_to_write_leaves_out_as_it_was(tmp_path):
    stage, out = tmp_path / "stage", tmp_path / "out"
    (stage / "meshes").mkdir(parents=True)
    (stage / "r.source.urdf").write_bytes(b"<robot/>\n" * 100)
    (stage / "r.yaml").write_bytes(b"name: r\n" * 100)
    (stage / "meshes" / "big.stl").write_bytes(b"\0" * 200_000)  # over the limit below
    out.mkdir()
    (out / "r.yaml").write_bytes(b"the earlier import\n")
    before = _files(out)
    child = textwrap.dedent(
        f"""
        import resource, signal
        from pathlib import Path
        from simkit.errors import SimkitError
        from simkit.importer.write.output import publish
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # EFBIG instead of a kill
        resource.setrlimit(resource.RLIMIT_FSIZE, (100_000, resource.RLIM_INFINITY))
        try:
            publish(Path({str(stage)!r}), Path({str(out)!r}))
        except SimkitError as exc:
            print("REFUSED", exc)
        """
    )
    env = {**os.environ, "PYTHONPATH": str(Path(__file__).parents[1] / "src")}
    done = subprocess.run([sys.executable, "-c", child], capture_output=True, text=True, env=env)
    assert done.stdout.startswith("REFUSED"), done.stdout + done.stderr
    assert "cannot write" in done.stdout and "big.stl" in done.stdout
    assert _files(out) == before  # the earlier spec kept, nothing added
    assert sorted(p.name for p in out.iterdir()) == ["r.yaml"]  # no meshes/, no partial


def test_a_failed_rename_puts_back_what_it_replaced(tmp_path):
    """The last file cannot take its place (a folder is in the way): every file already
    renamed over an earlier import's is put back."""
    from simkit.importer.write.output import publish

    stage, out = tmp_path / "stage", tmp_path / "out"
    (stage / "meshes").mkdir(parents=True)
    (stage / "meshes" / "z.stl").write_bytes(b"new mesh")
    (stage / "r.yaml").write_bytes(b"new spec")
    (out / "meshes" / "z.stl").mkdir(parents=True)  # a folder where the mesh goes
    (out / "meshes" / "z.stl" / "x").write_bytes(b"")
    (out / "r.yaml").write_bytes(b"old spec")
    before = _files(out)
    with pytest.raises(SimkitError, match="cannot write"):
        publish(stage, out)
    assert _files(out) == before
    assert not [p for p in out.iterdir() if p.name.startswith(".import-")]


MESH_URDF = """<?xml version="1.0"?>
<robot name="r">
  <link name="base"><inertial><mass value="1"/><inertia ixx="0.001" iyy="0.001" izz="0.001"
    ixy="0" ixz="0" iyz="0"/></inertial>
    <visual><geometry><mesh filename="ball.stl"/></geometry></visual></link>
</robot>
"""


@pytest.fixture
def small_disk(tmp_path):
    """A 400 kB tmpfs (root only; skipped where mounting is not allowed)."""
    disk = tmp_path / "disk"
    disk.mkdir()
    mounted = subprocess.run(
        ["mount", "-t", "tmpfs", "-o", "size=400k", "tmpfs", str(disk)], capture_output=True
    )
    if mounted.returncode != 0:
        pytest.skip("cannot mount a tmpfs here (needs root)")
    try:
        yield disk
    finally:
        subprocess.run(["umount", str(disk)], check=True)


def test_a_full_disk_during_an_import_writes_nothing(tmp_path, small_disk):
    import trimesh

    ball = trimesh.creation.icosphere(subdivisions=4, radius=0.05)  # 5,120 faces: 256 kB
    ball.export(tmp_path / "ball.stl")
    urdf = tmp_path / "r.urdf"
    urdf.write_text(MESH_URDF)
    out = small_disk / "kit"  # the staged mesh fits, a second copy of it does not
    with pytest.raises(SimkitError) as refused:
        import_robot(urdf, out)
    message = str(refused.value)
    assert "cannot write" in message and "\n" not in message
    assert message.startswith(f"{out / 'meshes' / 'ball.stl'}: ")  # its place in --out
    assert ".import-" not in message  # never the staging folder
    assert list(small_disk.iterdir()) == []  # no spec, no source, no mesh, no --out folder
