"""A build's error names the kit's place under `--out`, never the staging folder the user
never sees (issue 32, class 3): a kit file over the size cap is named by its place in the
kit, with the cap it is over."""

from __future__ import annotations

import os

import pytest

from simkit.errors import CheckFailed, SimkitError, SpecError
from simkit.kitio.kitread import read_folder_safely
from simkit.pipeline import unstaged


def _sparse(path, size: int) -> None:
    """A file of `size` bytes that takes no disk space."""
    path.parent.mkdir(parents=True, exist_ok=True)
    with open(path, "wb") as handle:
        handle.truncate(size)


def test_a_file_over_the_cap_names_its_place_and_the_cap(tmp_path):
    out = tmp_path / "kits"
    staging = out / ".r.abc123.staging"
    kit = staging / "r_description"
    _sparse(kit / "step" / "r.step", (64 << 20) + 1)
    with pytest.raises(SimkitError) as refused:
        read_folder_safely(kit, read=False)
    message = str(unstaged(refused.value, staging, out))
    assert message == (
        f"{out / 'r_description'}: step/r.step is over the kit size cap: 64.0 MiB, 64 MiB per file"
    )
    assert "staging" not in message


def test_errors_without_the_staging_folder_are_kept():
    spec = SpecError("robots/r.yaml", 3, "links.a.mass", "must be > 0")
    assert unstaged(spec, "/x/.r.s.staging", "/x") is spec
    failed = CheckFailed("/x/.r.s.staging/r_description: 1 check failed")
    again = unstaged(failed, "/x/.r.s.staging", "/x")
    assert type(again) is CheckFailed and str(again) == "/x/r_description: 1 check failed"
    assert os.sep == "/"  # the kit paths above are POSIX
