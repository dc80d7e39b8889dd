"""Issue 16: `simkit view`, the three.js page served on 127.0.0.1. The server is tested with
plain HTTP; the page in real headless Chromium (Debian's `chromium`, driven by Playwright from
PyPI; no browser download), skipped with the reason where either is missing."""

from __future__ import annotations

import io
import json
import os
import shutil
import urllib.error
import urllib.request
from pathlib import Path

import numpy as np
import pytest

from simkit.errors import SimkitError
from simkit.kitio.resources import robot_names
from simkit.review.view import WEB, serve_kit, start_server, start_site_server

CHROMIUM = os.environ.get("SIMKIT_CHROMIUM") or shutil.which("chromium")
FLAGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--no-first-run",
]


def _get(url: str) -> tuple[int, bytes, str]:
    try:
        with urllib.request.urlopen(url, timeout=10) as response:
            return response.status, response.read(), response.headers["Content-Type"]
    except urllib.error.HTTPError as exc:
        return exc.code, b"", ""


@pytest.fixture()
def small_kit(tmp_path) -> Path:
    kit = tmp_path / "kit"
    (kit / "meshes/collision").mkdir(parents=True)
    (kit / "robot.json").write_text('{"name": "tiny", "joints": []}')
    (kit / "meshes/collision/base_link_00.stl").write_bytes(b"solid x\nendsolid x\n")
    (tmp_path / "secret.txt").write_text("not for the browser")
    return kit


def test_server_serves_page_vendored_three_and_kit_files_only(small_kit):
    server = start_server(small_kit, 0)
    base = f"http://127.0.0.1:{server.server_address[1]}"
    try:
        status, body, ctype = _get(base + "/")
        assert status == 200 and ctype.startswith("text/html") and b"importmap" in body
        status, body, ctype = _get(base + "/vendor/three/three.module.min.js")
        assert status == 200 and ctype.startswith("text/javascript") and len(body) > 100_000
        for name in ("loaders/GLTFLoader.js", "loaders/STLLoader.js", "controls/OrbitControls.js"):
            assert _get(f"{base}/vendor/three/addons/{name}")[0] == 200
        assert _get(base + "/kit/robot.json")[1] == (small_kit / "robot.json").read_bytes()
        files = json.loads(_get(base + "/kit-files.json")[1])
        assert files == ["meshes/collision/base_link_00.stl", "robot.json"]
        for escape in ("/kit/../secret.txt", "/kit/%2e%2e/secret.txt", "/../secret.txt"):
            assert _get(base + escape)[0] == 404, escape
    finally:
        server.shutdown()
        server.server_close()


def _raw(port: int, target: str) -> bytes:
    """The status line of a raw GET (urllib would re-quote or refuse odd targets)."""
    import socket

    with socket.create_connection(("127.0.0.1", port), timeout=10) as conn:
        conn.sendall(f"GET {target} HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n".encode())
        data = b""
        while chunk := conn.recv(65536):
            data += chunk
    return data.split(b"\r\n", 1)[0]


def test_nul_bytes_and_long_urls_get_400_or_404_not_a_traceback(small_kit, capfd):
    """Issue 24: `%00` and a 10,000-character URL dropped the connection with a traceback."""
    server = start_server(small_kit, 0)
    port = server.server_address[1]
    try:
        assert _raw(port, "/kit/%00") == b"HTTP/1.0 400 control character in URL"
        assert _raw(port, "/kit/robot.json%00.png").startswith(b"HTTP/1.0 400")
        assert _raw(port, "/%0a").startswith(b"HTTP/1.0 400")
        assert _raw(port, "/kit/" + "a" * 10_000).startswith(b"HTTP/1.0 404")
        assert _raw(port, "/kit/" + "a/" * 4_000).startswith(b"HTTP/1.0 404")
        assert _raw(port, "/" + "b" * 300).startswith(b"HTTP/1.0 404")  # one name > 255 bytes
        assert _raw(port, "/kit/robot.json").startswith(b"HTTP/1.0 200")  # still serving
    finally:
        server.shutdown()
        server.server_close()
    err = capfd.readouterr().err
    assert "Traceback" not in err and "Error" not in err, err


def test_zip_with_a_file_and_a_folder_of_one_name_is_one_line(tmp_path):
    """Issue 24: `simkit view` crashed on a zip holding `meshes` and `meshes/part.stl`."""
    import zipfile

    from click.testing import CliRunner

    from simkit.cli import main

    bad = tmp_path / "clash.zip"
    with zipfile.ZipFile(bad, "w") as archive:
        archive.writestr("kit/robot.json", '{"name": "tiny", "joints": []}')
        archive.writestr("kit/meshes", b"a file")
        archive.writestr("kit/meshes/part.stl", b"solid x\nendsolid x\n")
    with pytest.raises(SimkitError, match="'meshes' is both a file and a folder"):
        serve_kit(bad, 0, open_browser=False)
    result = CliRunner().invoke(main, ["view", str(bad), "--no-browser", "--port", "0"])
    assert result.exit_code == 2 and result.output.count("\n") == 1, result.output
    assert "both a file and a folder" in result.output


def test_page_and_vendored_files_reference_nothing_outside():
    """No URL with a scheme in what the page loads (three.js's comments aside)."""
    page = "".join(
        (WEB / name).read_text() for name in ("index.html", "viewer.js", "geoms.js", "camera.js")
    )
    assert "http:" not in page and "https:" not in page
    assert "@mujoco/mujoco@3.14.0" in (WEB / "vendor/mujoco/README.md").read_text()
    assert (WEB / "vendor/mujoco/LICENSE").read_text().lstrip().startswith("Apache License")
    assert (WEB / "vendor/three/LICENSE").read_text().startswith("The MIT License")
    assert "three@0.170.0" in (WEB / "vendor/three/README.md").read_text()


def test_refuses_a_folder_that_is_no_kit(tmp_path):
    with pytest.raises(SimkitError, match="not a kit folder"):
        start_server(tmp_path, 0)


def _servo_hold(kit: Path, joint: str, value: float, steps: int) -> dict:
    """Python MuJoCo on the kit's MJCF: from home with the servos holding it, `joint`'s servo
    target set to `value`, `steps` steps -> qpos by joint name and the tool site (world, m)."""
    import mujoco

    doc = json.loads((kit / "robot.json").read_text())
    model = mujoco.MjModel.from_xml_path(str(kit / doc["files"]["mjcf"]))
    data = mujoco.MjData(model)
    movable = [j["name"] for j in doc["joints"] if j["type"] != "fixed"]
    targets = {**dict(zip(movable, doc["home"], strict=True)), joint: value}
    for name, q in targets.items():
        adr = model.joint(name).qposadr[0]
        data.qpos[adr] = dict(zip(movable, doc["home"], strict=True))[name]
        for a in range(model.nu):
            if model.actuator_trnid[a, 0] == model.joint(name).id:
                data.ctrl[a] = q
    mujoco.mj_forward(model, data)
    for _ in range(steps):
        mujoco.mj_step(model, data)
    qpos = {name: float(data.qpos[model.joint(name).qposadr[0]]) for name in movable}
    return {"qpos": qpos, "tool": data.site(doc["tool_frame"]).xpos.copy()}


def _wait_ready(page) -> None:
    page.evaluate("window.simkitViewer.ready.catch(() => null)")
    assert page.evaluate("window.simkitViewer.error") is None


@pytest.mark.slow
def test_viewer_in_headless_chromium(rosie_1000, tmp_path):
    """The live viewer: sliders and pose buttons from robot.json; a slider sets the servo
    target and, stepped while paused, the arm moves as Python MuJoCo's does."""
    if CHROMIUM is None:
        missing = "no chromium on PATH (Debian: apt-get install chromium)"
        if os.environ.get("SIMKIT_REQUIRE_RENDER"):  # .ci/run installed it
            pytest.fail(missing)
        pytest.skip(missing)
    sync_api = pytest.importorskip("playwright.sync_api", reason="playwright not installed")
    from PIL import Image

    kit = rosie_1000.kit_dir
    doc = json.loads((kit / "robot.json").read_text())
    j2 = [j for j in doc["joints"] if j["type"] != "fixed"][1]  # the second movable joint
    value = round(min(j2["upper"], 0.6), 6)
    steps = 750  # 1.5 s at the MJCF's 2 ms
    expected = _servo_hold(kit, j2["name"], value, steps)
    server = start_server(kit, 0)
    problems: list[str] = []
    try:
        with sync_api.sync_playwright() as pw:
            browser = pw.chromium.launch(executable_path=CHROMIUM, args=FLAGS)
            page = browser.new_page(viewport={"width": 1000, "height": 700})
            page.on("console", lambda m: m.type == "error" and problems.append(m.text))
            page.on("pageerror", lambda e: problems.append(str(e)))
            page.on(
                "request",
                lambda r: (
                    r.url.startswith("http://127.0.0.1:")
                    or r.url.startswith("data:")
                    or problems.append(f"outside request {r.url}")
                ),
            )
            page.goto(f"http://127.0.0.1:{server.server_address[1]}/")
            _wait_ready(page)
            sliders = page.locator("input[type=range][data-joint]")
            assert sliders.count() == len(doc["joints"])
            for joint in doc["joints"]:
                slider = page.locator(f'input[data-joint="{joint["name"]}"]')
                assert float(slider.get_attribute("min")) == pytest.approx(joint["lower"])
                assert float(slider.get_attribute("max")) == pytest.approx(joint["upper"])
            assert page.locator("button[data-pose]").count() == len(doc["poses"])
            tool = doc["tool_frame"]
            page.evaluate("simkitViewer.pause(true); simkitViewer.reset('home')")
            seen_before = np.array(page.evaluate(f"simkitViewer.framePosition('{tool}')"))
            page.eval_on_selector(
                f'input[data-joint="{j2["name"]}"]',
                "(s, v) => { s.value = v; s.dispatchEvent(new Event('input', {bubbles: true})); }",
                value,
            )
            page.evaluate(f"simkitViewer.step({steps})")
            seen = page.evaluate("simkitViewer.qpos()")
            seen_after = np.array(page.evaluate(f"simkitViewer.framePosition('{tool}')"))
            page.click('input[data-collision="*"]')
            page.click('input[data-contacts="*"]')
            page.evaluate("simkitViewer.step(1)")
            shot = page.screenshot()
            browser.close()
    finally:
        server.shutdown()
        server.server_close()
    assert problems == []
    for joint, q in expected["qpos"].items():
        assert seen[joint] == pytest.approx(q, abs=1e-6), joint
    assert seen[j2["name"]] == pytest.approx(value, abs=0.02)  # the servo got there
    assert np.abs(seen_after - expected["tool"]).max() < 1e-5
    assert np.linalg.norm(seen_after - seen_before) > 0.05  # a real move, not a no-op
    image = np.asarray(Image.open(io.BytesIO(shot)).convert("RGB"))
    view = image[:, 320:]  # right of the side panel: the 3D view
    assert view.std() > 10 and len(np.unique(view.reshape(-1, 3), axis=0)) > 200
    (tmp_path / "viewer.png").write_bytes(shot)


@pytest.mark.parametrize("name", ["../evil.txt", "/abs/evil.txt", "kit/../../evil.txt"])
def test_zip_entries_outside_the_kit_are_refused(tmp_path, name):
    import zipfile

    bad = tmp_path / "sub" / "escape.zip"
    bad.parent.mkdir()
    with zipfile.ZipFile(bad, "w") as archive:
        archive.writestr("kit/robot.json", '{"name": "tiny", "joints": []}')
        archive.writestr(name, b"outside")
    with pytest.raises(SimkitError) as info:
        serve_kit(bad, 0, open_browser=False)
    assert "\n" not in str(info.value)
    assert not list(tmp_path.rglob("evil.txt"))


@pytest.mark.slow
@pytest.mark.parametrize("name", robot_names())
def test_viewer_frames_the_whole_robot_in_every_pose(kit_factory, name, tmp_path):
    """Issue 25: the camera is fitted to every named pose, not home alone (the flange of
    rosie_1000 left the canvas in "stretched")."""
    if CHROMIUM is None:
        if os.environ.get("SIMKIT_REQUIRE_RENDER"):
            pytest.fail("no chromium on PATH (Debian: apt-get install chromium)")
        pytest.skip("no chromium on PATH (Debian: apt-get install chromium)")
    sync_api = pytest.importorskip("playwright.sync_api", reason="playwright not installed")
    kit = kit_factory(name).kit_dir
    poses = json.loads((kit / "robot.json").read_text())["poses"]
    server = start_server(kit, 0)
    boxes = {}
    try:
        with sync_api.sync_playwright() as pw:
            browser = pw.chromium.launch(executable_path=CHROMIUM, args=FLAGS)
            page = browser.new_page(viewport={"width": 900, "height": 600})
            page.goto(f"http://127.0.0.1:{server.server_address[1]}/")
            _wait_ready(page)
            page.evaluate("simkitViewer.pause(true)")
            for pose in poses:  # the servos drive the robot there: 3 s, stepped while paused
                page.click(f'button[data-pose="{pose}"]')
                page.evaluate("simkitViewer.step(Math.round(3 / simkitViewer.timestep()))")
                boxes[pose] = page.evaluate("simkitViewer.screenBox()")
                (tmp_path / f"{pose}.png").write_bytes(page.screenshot())
            browser.close()
    finally:
        server.shutdown()
        server.server_close()
    for pose, box in boxes.items():
        lo, hi = np.array(box["lo"]), np.array(box["hi"])
        assert (lo >= -1).all() and (hi <= 1).all(), f"{name} {pose}: leaves the canvas {box}"
        assert ((hi - lo) / 2).max() > 0.3, f"{name} {pose}: the robot is a speck {box}"


def test_publish_serve_is_a_static_server_of_the_site_on_loopback(tmp_path):
    """`simkit publish --serve`: the site folder as files, nothing outside it, 127.0.0.1."""
    site = tmp_path / "sim"
    (site / "viewer").mkdir(parents=True)
    (site / "index.html").write_text("<!DOCTYPE html><title>kits</title>")
    (site / "viewer" / "mujoco.wasm").write_bytes(b"\0asm")
    (tmp_path / "secret.txt").write_text("not for the browser")
    server = start_site_server(site, 0)
    host, port = server.server_address[:2]
    base = f"http://127.0.0.1:{port}"
    try:
        assert host == "127.0.0.1"
        assert _get(base + "/")[1] == (site / "index.html").read_bytes()
        status, body, ctype = _get(base + "/viewer/mujoco.wasm")
        assert (status, body, ctype) == (200, b"\0asm", "application/wasm")
        assert _get(base + "/../secret.txt")[0] == 404
    finally:
        server.shutdown()
        server.server_close()
    with pytest.raises(SimkitError, match="no such site folder"):
        start_site_server(tmp_path / "missing", 0)
