"""Hostile USD input (issue 39): a layer outside the model's folder, or not USD, is refused in
one line before the stage opens, and the outside file is never opened."""

from __future__ import annotations

import pytest
from tests.usd_stages import arm

from simkit.errors import SpecError
from simkit.importer import import_robot

pytest.importorskip("pxr")

OUTSIDE = '#usda 1.0\ndef Xform "secret"\n{\n}\n'


def _with_arc(tmp_path, arc: str):
    """The two-link arm whose root layer gains one composition arc, `arc`, on a new prim
    (text such as `references = @../x.usda@`); an outside layer beside the model's folder."""
    folder = tmp_path / "model"
    folder.mkdir()
    outside = tmp_path / "outside.usda"
    outside.write_text(OUTSIDE)
    path = arm(folder / "arm.usda")
    text = path.read_text()
    path.write_text(text + f'\ndef Xform "extra" (\n    prepend {arc}\n)\n{{\n}}\n')
    return path, outside


def _refused(path, tmp_path, match: str) -> str:
    with pytest.raises(SpecError, match=match) as caught:
        import_robot(path, tmp_path / "out")
    assert "\n" not in str(caught.value)
    assert not (tmp_path / "out").exists()
    return str(caught.value)


def _never_opened(outside) -> None:
    from pxr import Sdf

    assert Sdf.Layer.Find(str(outside)) is None
    assert Sdf.Layer.Find(str(outside.resolve())) is None


def test_reference_up_and_out(tmp_path) -> None:
    path, outside = _with_arc(tmp_path, "references = @../outside.usda@")
    said = _refused(path, tmp_path, "outside the model's folder")
    assert "@../outside.usda@" in said and "arm.usda" in said
    _never_opened(outside)


def test_absolute_payload(tmp_path) -> None:
    path, outside = _with_arc(tmp_path, f"payload = @{tmp_path / 'outside.usda'}@")
    _refused(path, tmp_path, "outside the model's folder")
    _never_opened(outside)


def test_symlink_out(tmp_path) -> None:
    path, outside = _with_arc(tmp_path, "references = @./inside.usda@")
    (path.parent / "inside.usda").symlink_to(outside)
    _refused(path, tmp_path, "outside the model's folder")
    _never_opened(outside)


def test_sublayer_out(tmp_path) -> None:
    folder = tmp_path / "model"
    folder.mkdir()
    outside = tmp_path / "outside.usda"
    outside.write_text(OUTSIDE)
    path = arm(folder / "arm.usda")
    text = path.read_text().replace(
        "#usda 1.0\n(", "#usda 1.0\n(\n    subLayers = [@../outside.usda@]", 1
    )
    path.write_text(text)
    _refused(path, tmp_path, "outside the model's folder")
    _never_opened(outside)


def test_garbage_layer(tmp_path) -> None:
    path, _ = _with_arc(tmp_path, "references = @./junk.usda@")
    (path.parent / "junk.usda").write_text("#usda 1.0\nthis is { not USD at all\n")
    _refused(path, tmp_path, "junk.usda.*not a USD layer")


def test_reference_to_text(tmp_path) -> None:
    path, _ = _with_arc(tmp_path, "references = @./notes.txt@")
    (path.parent / "notes.txt").write_text("hello\n")
    _refused(path, tmp_path, "not a USD layer")


def test_root_not_usd(tmp_path) -> None:
    path = tmp_path / "robot.usda"
    path.write_text("garbage, not a layer\n")
    _refused(path, tmp_path, "not a USD layer")
