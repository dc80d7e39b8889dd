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
from simkit.review.render import NO_GL_HINT, Item, gl_backend, render_kit, run_job
from simkit.review.render_worker import clean_shadows
from simkit.review.scene import (
    Camera,
    fit_camera,
    framing_points,
    parse_camera,
    parse_size,
    scene_xml,
)

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
    """Pixels far from the dark blue-grey floor and sky: the robot (white, grey or coloured).
    The backdrop is darker than 130 and bluer than it is red."""
    rgb = image.astype(int)
    backdrop = (rgb.max(axis=2) < 130) & (rgb[..., 2] - rgb[..., 0] > 8)
    return int((~backdrop).sum())


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


def test_framing_keeps_fixtures_only_near_the_moving_links():
    arm = np.array([[0.0, 0.0, 0.5], [0.3, 0.1, 0.8]])
    plate = np.array([[-0.5, -0.05, 0.0], [0.5, 0.05, 1.0], [0.1, 0.0, 0.6], [0.32, 0.1, 0.5]])
    points = framing_points(np.concatenate([arm, plate]), np.array([1, 1, 0, 0, 0, 0], bool))
    # the plate's far corners go, its points beside the arm (within 10 % of 0.3 m) stay
    assert points.tolist() == [*arm.tolist(), plate[2].tolist(), plate[3].tolist()]
    alone = framing_points(plate, np.zeros(4, bool))  # no moving links: everything counts
    assert (alone == plate).all()


def _luminance(rgb) -> float:
    """WCAG relative luminance of an sRGB colour (0..1 channels)."""
    c = np.asarray(rgb, float)[:3]
    lin = np.where(c <= 0.03928, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)
    return float(lin @ (0.2126, 0.7152, 0.0722))


def test_floor_and_backdrop_contrast_with_every_light_robot_material():
    """Issue 25: a white robot on a light floor had low contrast. Every light material of the
    five robots (luminance above 0.3) stands out from the floor's and the sky's colours by a
    WCAG contrast ratio of at least 3."""
    import xml.etree.ElementTree as ET

    from simkit.pipeline import model_from_spec
    from simkit.review.scene import SCENE_ASSETS

    assets = ET.fromstring(SCENE_ASSETS)
    backdrop = [
        [float(v) for v in texture.get(key).split()]
        for texture in assets.iter("texture")
        for key in ("rgb1", "rgb2", "markrgb")
        if texture.get(key)
    ]
    light = [
        (name, rgba)
        for robot in robot_names()
        for name, rgba in model_from_spec(robot).materials
        if _luminance(rgba) > 0.3 and rgba[3] == 1
    ]
    assert len(light) >= 3  # white shells, light greys, turquoise
    for name, rgba in light:
        for colour in backdrop:
            dark, bright = sorted((_luminance(colour), _luminance(rgba)))
            assert (bright + 0.05) / (dark + 0.05) >= 3, (name, colour)


def test_shadow_box_covers_the_robot_and_the_floor_in_view():
    from simkit.review.scene import shadow_clip

    points = np.array([[0.0, 0.0, 0.0], [0.2, 0.1, 0.9]])
    light = np.array([-0.4, 0.4, -0.82])
    centre = points.mean(axis=0)
    near = fit_camera(Camera(135.0, -20.0), points, 45.0, 4 / 3)
    far = Camera(135.0, -20.0, 3 * near.distance, near.lookat)
    clip = shadow_clip(near, 45.0, 4 / 3, points, 0.0, centre, light)
    d = points - centre
    across = d - np.outer(d @ light, light) / (light @ light)
    assert clip >= np.linalg.norm(across, axis=1).max()  # the robot
    assert shadow_clip(far, 45.0, 4 / 3, points, 0.0, centre, light) > 2 * clip  # more floor
    up = Camera(135.0, 30.0, near.distance, near.lookat)  # looking up: no floor at the bottom
    assert shadow_clip(up, 45.0, 4 / 3, points, 0.0, centre, light) == pytest.approx(
        np.linalg.norm(across, axis=1).max()
    )


def test_clean_shadows_removes_speckle_and_keeps_shadows():
    plain = np.full((40, 40, 3), 120, dtype=np.uint8)
    shadowed = plain.copy()
    shadowed[10:30, 5:25] = 60  # a real shadow: a region
    rng = np.random.default_rng(3)
    speckle = rng.random((40, 40)) < 0.08  # acne: isolated dark pixels
    shadowed[speckle] = 20
    out = clean_shadows(shadowed, plain)
    assert (out[13:27, 8:22] < 70).all()  # the shadow stays, inside and up to near its edge
    outside = np.ones((40, 40), bool)
    outside[8:32, 3:27] = False
    assert (out[outside] == 120).all()  # every speckle outside it is gone


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


# ---- issue 25: framing, floor speckle, contrast (all five kits) ---------------------------


def _basis(camera: Camera) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    az, el = np.radians(camera.azimuth), np.radians(camera.elevation)
    forward = np.array([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)])
    right = np.cross(forward, (0, 0, 1))
    right /= np.linalg.norm(right)
    return forward, right, np.cross(right, forward)


def _project(camera: Camera, points: np.ndarray, aspect: float) -> np.ndarray:
    """(N, 2) image coordinates in [-1, 1] (x right, y up) of world points, pinhole camera
    with MuJoCo's 45 degree vertical field of view."""
    forward, right, up = _basis(camera)
    v = points - (np.asarray(camera.lookat) - camera.distance * forward)
    depth = v @ forward
    assert (depth > 0).all()
    tan_v = np.tan(np.radians(22.5))
    return np.column_stack([(v @ right) / depth / (tan_v * aspect), (v @ up) / depth / tan_v])


def _floor_mask(camera: Camera, size, floor_z: float, robot_box) -> np.ndarray:
    """Pixels that see the floor within four camera distances, outside the robot's box."""
    w, h = size
    forward, right, up = _basis(camera)
    eye = np.asarray(camera.lookat) - camera.distance * forward
    tan_v = np.tan(np.radians(22.5))
    x = (2 * (np.arange(w) + 0.5) / w - 1)[None, :, None]
    y = (1 - 2 * (np.arange(h) + 0.5) / h)[:, None, None]
    rays = forward + x * tan_v * w / h * right + y * tan_v * up
    t = (floor_z - eye[2]) / np.where(rays[..., 2] < 0, rays[..., 2], -1e-9)
    hits = (rays[..., 2] < 0) & (np.linalg.norm(rays * t[..., None], axis=2) < 4 * camera.distance)
    (x0, y0), (x1, y1) = robot_box
    cols = (np.arange(w) + 0.5) / w * 2 - 1
    rows = 1 - (np.arange(h) + 0.5) / h * 2
    pad = 16 / h
    inside = ((rows[:, None] > y0 - pad) & (rows[:, None] < y1 + pad)) & (
        (cols[None, :] > x0 - pad) & (cols[None, :] < x1 + pad)
    )
    return hits & ~inside


def _speckle(image: np.ndarray, mask: np.ndarray) -> float:
    """High-frequency energy: the share of masked pixels more than 20 grey levels from the
    median of their 3x3 neighbourhood (isolated dots; the checker's edges are softer)."""
    from scipy.ndimage import median_filter

    grey = image.astype(float).mean(axis=2)
    return float((np.abs(grey - median_filter(grey, size=3)) > 20)[mask].mean())


@pytest.mark.slow
def test_robot_fills_the_frame_and_the_floor_is_clean_for_every_kit(kit_factory, gl, tmp_path):
    import mujoco

    from simkit.diff import load_kit
    from simkit.review.scene import load_scene, posed_points

    size = (640, 480)
    aspect = size[0] / size[1]
    speckle: dict[str, float] = {}
    for name in robot_names():
        kit = kit_factory(name).kit_dir
        poses = list(json.loads((kit / "robot.json").read_text())["poses"])
        items = [Item(0, pose, False, tmp_path / f"{name}_{pose}.png") for pose in poses]
        cameras = run_job([kit], items, size)["cameras"]
        (tmp_path / name).mkdir()
        scene = load_scene(load_kit(kit), tmp_path / name, name)
        data = mujoco.MjData(scene.model)
        floor_z = min(0.0, float(posed_points(scene, data)[0][:, 2].min()))
        scores = []
        for item in items:
            points, moving = posed_points(scene, data, [item.pose])
            xy = _project(cameras[item.pose], points[moving], aspect)
            lo, hi = xy.min(axis=0), xy.max(axis=0)
            where = f"{name} {item.pose}"
            assert (lo >= -1).all() and (hi <= 1).all(), f"{where}: the robot leaves the frame"
            assert ((hi - lo) / 2).max() >= 0.6, f"{where}: the robot spans {(hi - lo) / 2}"
            everything = _project(cameras[item.pose], points, aspect)
            box = (everything.min(axis=0), everything.max(axis=0))
            mask = _floor_mask(cameras[item.pose], size, floor_z, box)
            assert mask.mean() > 0.05, f"{where}: too little floor to measure"
            image = read_png(item.file)
            scores.append(_speckle(image, mask))
            # contrast: the robot's pixels differ from the backdrop's
            assert _robot_pixels(image) > 0.05 * mask.size, f"{where}: the robot is hard to see"
        speckle[name] = max(scores)
    cleanest = max(min(speckle.values()), 1e-4)
    assert max(speckle.values()) <= 2 * cleanest, speckle
