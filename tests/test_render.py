"""Issue 16: MuJoCo renders of a kit (`simkit render`) and the HTML visual diff
(`simkit diff --html`). Real MuJoCo offscreen rendering (EGL or OSMesa); skipped, with the
reason, where neither gives an OpenGL context."""

from __future__ import annotations

import base64
import itertools
import json
import os
import re
import shutil
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from simkit.cli import main
from simkit.errors import SimkitError
from simkit.kitio.resources import robot_names
from simkit.pipeline import build
from simkit.review.diff_html import HIGHLIGHT, diff_image
from simkit.review.png import png_bytes, read_png
from simkit.review.render import NO_GL_HINT, gl_backend, render_kit
from simkit.review.scene import Camera, fit_camera, parse_camera, parse_size, scene_xml

SPECS = Path(__file__).resolve().parent / "specs"
SIZE = (320, 240)


@pytest.fixture(scope="session")
def gl() -> str:
    backend = gl_backend()
    if backend is None:
        if os.environ.get("SIMKIT_REQUIRE_RENDER"):  # .ci/run installed libosmesa6
            pytest.fail(NO_GL_HINT)
        pytest.skip(NO_GL_HINT)
    return backend


def _robot_pixels(image: np.ndarray) -> int:
    """Pixels far from the grey-white floor and sky: the robot (and its shadow)."""
    spread = image.astype(int).max(axis=2) - image.astype(int).min(axis=2)
    return int(((spread > 40) | (image.max(axis=2) < 150)).sum())


# ---- fast: pure functions ----------------------------------------------------------------


def test_parse_camera_and_size():
    assert parse_camera("90,-30") == Camera(90.0, -30.0, None, None)
    assert parse_camera("90,-30,2.5,0,0,0.5") == Camera(90.0, -30.0, 2.5, (0.0, 0.0, 0.5))
    assert parse_size("800x600") == (800, 600)
    for bad in ("90", "a,b", "90,-30,-1", "1,2,3,4"):
        with pytest.raises(SimkitError, match="--camera"):
            parse_camera(bad)
    for bad in ("800", "8x6", "800x600x3", "99999x10"):
        with pytest.raises(SimkitError, match="--size"):
            parse_size(bad)


def test_fitted_camera_sees_every_point():
    rng = np.random.default_rng(1)
    points = rng.uniform((-0.2, -0.1, 0.0), (1.1, 0.1, 0.9), (500, 3))
    cam = fit_camera(Camera(135.0, -20.0), points, 45.0, 4 / 3)
    az, el = np.radians(cam.azimuth), np.radians(cam.elevation)
    forward = np.array([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)])
    right = np.cross(forward, (0, 0, 1))
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    v = points - (np.asarray(cam.lookat) - cam.distance * forward)
    depth = v @ forward
    x, y = (v @ right) / depth, (v @ up) / depth
    tan_v = np.tan(np.radians(22.5))
    assert (depth > 0).all()
    assert np.abs(y).max() <= tan_v and np.abs(x).max() <= tan_v * 4 / 3
    # and not absurdly far: the points fill most of the frame in one direction
    assert max(np.abs(y).max() / tan_v, np.abs(x).max() / (tan_v * 4 / 3)) > 0.8


def test_scene_xml_replaces_lights_and_adds_floor():
    xml = scene_xml(
        '<mujoco><compiler meshdir="../meshes"/><worldbody><light pos="0 0 3"/>'
        '<body><light pos="1 0 0"/><geom type="sphere" size="0.1"/></body></worldbody></mujoco>',
        Path("/abs/meshes"),
    )
    assert 'meshdir="/abs/meshes"' in xml
    assert xml.count("<light") == 2 and "simkit_render_key" in xml and "simkit_render_fill" in xml
    assert 'name="simkit_render_floor" type="plane"' in xml


def test_diff_image_marks_exactly_the_changed_pixels():
    old = np.full((4, 5, 3), 200, dtype=np.uint8)
    new = old.copy()
    new[1, 2] = (10, 20, 30)
    new[3, 4, 0] = 201
    image, changed = diff_image(old, new)
    assert changed == 2
    marked = np.all(image == HIGHLIGHT, axis=2)
    assert marked.sum() == 2 and marked[1, 2] and marked[3, 4]


def test_png_round_trip_is_byte_stable(tmp_path):
    pixels = np.arange(4 * 6 * 3, dtype=np.uint8).reshape(4, 6, 3)
    assert png_bytes(pixels) == png_bytes(pixels.copy())
    (tmp_path / "a.png").write_bytes(png_bytes(pixels))
    assert np.array_equal(read_png(tmp_path / "a.png"), pixels)
    assert b"tIME" not in png_bytes(pixels) and b"tEXt" not in png_bytes(pixels)


# ---- slow: real kits, real renders -------------------------------------------------------


@pytest.mark.slow
@pytest.mark.parametrize("name", robot_names())
def test_every_pose_renders_non_blank_and_poses_differ(kit_factory, gl, tmp_path, name):
    kit = kit_factory(name).kit_dir
    poses = json.loads((kit / "robot.json").read_text())["poses"]
    paths = render_kit(kit, tmp_path, size=SIZE)
    assert [p.name for p in paths] == [f"{pose}.png" for pose in poses]
    images = {p.stem: read_png(p) for p in paths}
    for pose, image in images.items():
        assert image.shape == (SIZE[1], SIZE[0], 3)
        assert _robot_pixels(image) > 0.01 * image[..., 0].size, f"{name} {pose}: blank"
        assert image.std() > 10
    for a, b in itertools.combinations(images, 2):
        if poses[a] != poses[b]:
            changed = np.any(images[a] != images[b], axis=2).mean()
            assert changed > 0.005, f"{name}: poses {a} and {b} render alike"


@pytest.mark.slow
def test_same_kit_same_pixels_zip_or_folder_and_collision_view(rosie_1000, gl, tmp_path):
    first = render_kit(rosie_1000.kit_dir, tmp_path / "a", ["work"], SIZE)[0]
    again = render_kit(rosie_1000.zip_path, tmp_path / "b", ["work"], SIZE)[0]
    assert first.read_bytes() == again.read_bytes()
    collision = render_kit(rosie_1000.kit_dir, tmp_path / "c", ["work"], SIZE, collision=True)[0]
    a, c = read_png(first), read_png(collision)
    assert np.any(a != c, axis=2).mean() > 0.01
    # the collision pieces are drawn in saturated colours; the kit's shell is white and grey
    saturation = c.astype(int).max(axis=2) - c.astype(int).min(axis=2)
    assert (saturation > 80).sum() > 10 * max((np.ptp(a.astype(int), axis=2) > 80).sum(), 1)
    assert sorted(p.name for p in (tmp_path / "a").iterdir()) == ["work.png"]  # no leftovers


@pytest.mark.slow
def test_cli_render_writes_pngs_logs_progress_and_refuses_unknown_pose(rosie_1000, gl, tmp_path):
    runner = CliRunner()
    kit = str(rosie_1000.kit_dir)
    result = runner.invoke(main, ["render", kit, "--out", str(tmp_path), "--size", "160x120"])
    assert result.exit_code == 0, result.output
    assert sorted(p.name for p in tmp_path.glob("*.png")) == [
        "home.png",
        "stretched.png",
        "work.png",
    ]
    assert "render 3/3:" in result.output  # not a terminal: plain log lines
    bad = runner.invoke(main, ["render", kit, "--out", str(tmp_path / "x"), "--pose", "nope"])
    assert bad.exit_code == 2
    assert bad.output.count("\n") == 1 and "no pose 'nope'" in bad.output
    assert not (tmp_path / "x").exists()


@pytest.fixture(scope="session")
def planar_pair(kit_factory, tmp_path_factory) -> tuple[Path, Path]:
    """The planar 2R test kit and a copy of its spec with link_1 60 mm longer."""
    old = kit_factory(str(SPECS / "planar_2r.yaml")).kit_dir
    work = tmp_path_factory.mktemp("planar_longer")
    text = (SPECS / "planar_2r.yaml").read_text()
    longer = text.replace("to: [0.3, 0, 0]}", "to: [0.36, 0, 0]}")
    longer = longer.replace("    xyz: [0.3, 0, 0]", "    xyz: [0.36, 0, 0]")
    assert longer.count("0.36") == 2
    (work / "planar_2r.yaml").write_text(longer)
    new = build(str(work / "planar_2r.yaml"), work / "out").kit_dir
    return old, new


@pytest.mark.slow
def test_diff_html_is_self_contained_and_shows_the_change(planar_pair, gl, tmp_path):
    old, new = planar_pair
    report = tmp_path / "report.html"
    plain = CliRunner().invoke(main, ["diff", str(old), str(new)])
    result = CliRunner().invoke(main, ["diff", str(old), str(new), "--html", str(report)])
    assert result.exit_code == 1  # different kits
    assert plain.stdout == result.stdout  # stdout is today's report, unchanged
    text = report.read_text(encoding="utf-8")
    assert "joint_2" in text and "origin_xyz" in text  # the semantic table
    for forbidden in ("http:", "https:", "url(", "@import", "<script", "<link", "href="):
        assert forbidden not in text, forbidden
    sources = re.findall(r'src="([^"]*)"', text)
    assert sources and all(s.startswith("data:image/png;base64,") for s in sources)
    poses = json.loads((old / "robot.json").read_text())["poses"]
    assert len(sources) == 3 * len(poses)  # OLD, NEW, difference per pose; no collision row
    images = [np.asarray(read_png_bytes(s)) for s in sources]
    for k in range(len(poses)):
        a, b, d = images[3 * k : 3 * k + 3]
        assert np.any(a != b)  # link_1 is longer: the renders differ
        assert np.all(d == HIGHLIGHT, axis=2).sum() == np.any(a != b, axis=2).sum()
    same = tmp_path / "same.html"
    equal = CliRunner().invoke(main, ["diff", str(old), str(old), "--html", str(same)])
    assert equal.exit_code == 0
    assert "0 pixels changed (0.00 %)" in same.read_text(encoding="utf-8")


def read_png_bytes(uri: str) -> np.ndarray:
    from io import BytesIO

    from PIL import Image

    data = base64.b64decode(uri.split(",", 1)[1])
    with Image.open(BytesIO(data)) as image:
        return np.asarray(image.convert("RGB"))


@pytest.mark.slow
def test_diff_html_gets_a_collision_row_when_collision_pieces_change(rosie_1000, gl, tmp_path):
    old = rosie_1000.kit_dir
    new = tmp_path / "new"
    shutil.copytree(old, new)
    from simkit.kitio.obj import from_obj, to_obj

    piece = new / "meshes/collision/link_2_00.obj"
    mesh = from_obj(piece.read_bytes())
    piece.write_bytes(to_obj(mesh._replace(vertices=mesh.vertices * 1.3), "link_2_00"))
    report = tmp_path / "report.html"
    result = CliRunner().invoke(main, ["diff", str(old), str(new), "--html", str(report)])
    assert result.exit_code == 1, result.output
    text = report.read_text(encoding="utf-8")
    assert "home (collision geometry)" in text
    row = text[text.index("home (collision geometry)") :]
    assert "0 pixels changed" not in row.split("</tr>")[0]


@pytest.mark.slow
def test_without_opengl_one_line_names_the_package(rosie_1000, tmp_path, monkeypatch):
    """GLX with no display makes no context, as EGL and OSMesa do where they are missing."""
    from simkit.review import render

    monkeypatch.setattr(render, "BACKENDS", ("glx",))
    monkeypatch.setattr(render, "_working", [])
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("MUJOCO_GL", raising=False)
    out = tmp_path / "out"
    result = CliRunner().invoke(main, ["render", str(rosie_1000.kit_dir), "--out", str(out)])
    assert result.exit_code == 2
    assert result.output == f"simkit: error: {NO_GL_HINT}\n"
    assert "libosmesa6" in NO_GL_HINT
    assert not out.exists() and list(tmp_path.iterdir()) == []  # nothing half-written
