"""Issue 40: the published site in real Chromium (Debian's `chromium` through Playwright), served
by `python -m http.server` on 127.0.0.1 with every other request blocked and recorded.

The seed kits come from the session fixtures (no extra builds); `publish(built=...)` lays them
out as `simkit publish` does, with the pose pictures. Physics: the WebAssembly MuJoCo of the
page against Python's MuJoCo on the same MJCF, both stepped from a named pose with the servos
holding it (docs/publish.md gives the measured agreement and the tolerance)."""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
import socket
import subprocess
import sys
import time
import urllib.request
from pathlib import Path

import pytest
from tests.test_view import CHROMIUM, FLAGS

#: rad: |WASM - Python| of every joint after 1 s (measured: docs/publish.md)
ARM_TOLERANCE = 1e-6
#: m: pelvis height after 2 s (the issue's bound)
STAND_TOLERANCE = 0.01

pytestmark = pytest.mark.slow


def _need_browser():
    if CHROMIUM is None:
        missing = "no chromium on PATH (Debian: apt-get install chromium)"
        if os.environ.get("SIMKIT_REQUIRE_RENDER"):
            pytest.fail(missing)
        pytest.skip(missing)
    return pytest.importorskip("playwright.sync_api", reason="playwright not installed")


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@contextlib.contextmanager
def _serve_folder(folder: Path):
    """`python -m http.server` on 127.0.0.1 serving `folder`; yields its base URL."""
    port = _free_port()
    server = subprocess.Popen(
        [sys.executable, "-m", "http.server", str(port), "-b", "127.0.0.1", "-d", str(folder)],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    base = f"http://127.0.0.1:{port}/"
    for _ in range(100):
        try:
            urllib.request.urlopen(base + "index.json", timeout=1).read()
            break
        except OSError:
            time.sleep(0.1)
    try:
        yield base
    finally:
        server.terminate()
        server.wait(10)


@pytest.fixture(scope="module")
def site(seed_kits, tmp_path_factory):
    """(site folder, index, base URL): the seed kits published and served on 127.0.0.1."""
    from simkit.publish import publish
    from simkit.review.view import pose_pictures

    folder = tmp_path_factory.mktemp("site") / "sim"
    index = publish(folder, built=list(seed_kits.values()), pictures=pose_pictures)
    with _serve_folder(folder) as base:
        yield folder, index, base


@pytest.fixture(scope="module")
def browser(site):
    sync_api = _need_browser()
    with sync_api.sync_playwright() as pw:
        chromium = pw.chromium.launch(executable_path=CHROMIUM, args=FLAGS)
        yield chromium
        chromium.close()


def _open(browser, url: str, problems: list[str]):
    """A page at `url` that records console errors, page errors, failed requests and any
    request not to 127.0.0.1 (aborted)."""
    page = browser.new_page(viewport={"width": 1100, "height": 800})
    page.on("console", lambda m: m.type == "error" and problems.append(f"console: {m.text}"))
    page.on("pageerror", lambda e: problems.append(f"pageerror: {e}"))
    page.on("requestfailed", lambda r: problems.append(f"failed: {r.url}"))

    def gate(route):
        url = route.request.url
        if url.startswith("http://127.0.0.1:") or url.startswith("data:"):
            return route.continue_()
        problems.append(f"outside request: {url}")
        return route.abort()

    page.route("**/*", gate)
    page.goto(url)
    return page


def _images_loaded(page) -> list[str]:
    return page.evaluate(
        "[...document.images].filter(i => !(i.complete && i.naturalWidth > 0)).map(i => i.src)"
    )


def test_gallery_and_every_kit_page_load_with_pictures_and_a_running_viewer(site, browser):
    folder, index, base = site
    problems: list[str] = []
    page = _open(browser, base + "index.html", problems)
    page.wait_for_load_state("load")
    assert page.locator("article.card").count() == len(index["kits"])
    assert page.locator("article.card img").count() == len(index["kits"])
    assert _images_loaded(page) == []
    for kit in index["kits"]:
        page = _open(browser, base + kit["page"], problems)
        page.evaluate("window.simkitViewer.ready")
        t0 = page.evaluate("simkitViewer.time()")
        page.wait_for_function(f"simkitViewer.time() > {t0} + 0.05", timeout=30_000)
        page.wait_for_load_state("load")
        assert _images_loaded(page) == [], kit["name"]
        pictures = page.locator("#pictures img").count()
        assert pictures == len(
            json.loads((folder / kit["folder"] / "robot.json").read_text())["poses"]
        )
        assert page.locator("#kit-title").text_content() == kit["title"]
        assert page.locator("input[data-joint]").count() == kit["dof"]
        page.close()
    assert problems == []


def test_every_download_link_resolves_and_matches_index_json(site, browser):
    _, index, base = site
    expected = {kit["zip"]["path"]: kit["zip"]["sha256"] for kit in index["kits"]}
    expected.update({f["url"]: f["sha256"] for kit in index["kits"] for f in kit["files"]})
    problems: list[str] = []
    seen = set()
    for kit in index["kits"]:
        page = _open(browser, base + kit["page"], problems)
        page.wait_for_load_state("load")
        hrefs = page.evaluate("[...document.querySelectorAll('a[href]')].map(a => a.href)")
        page.close()
        for href in hrefs:
            assert href.startswith(base), href
            rel = href[len(base) :]
            if rel in expected:
                data = urllib.request.urlopen(href, timeout=30).read()
                assert hashlib.sha256(data).hexdigest() == expected[rel], rel
                seen.add(rel)
    assert seen == set(expected)  # every zip and every file is linked from a page
    assert problems == []


def _python_mujoco(kit_dir: Path, pose: list[float], seconds: float) -> dict:
    """qpos by joint name and body positions after `seconds`, stepped from `pose` as the
    viewer's reset(pose) does: the model's initial state, the joints at the pose, servos on."""
    import mujoco

    doc = json.loads((kit_dir / "robot.json").read_text())
    main = doc["files"].get("mjcf_scene") or doc["files"]["mjcf"]
    model = mujoco.MjModel.from_xml_path(str(kit_dir / main))
    data = mujoco.MjData(model)
    movable = [j["name"] for j in doc["joints"] if j["type"] != "fixed"]
    for name, q in zip(movable, pose, strict=True):
        joint = model.joint(name)
        data.qpos[joint.qposadr[0]] = q
        for a in range(model.nu):
            if model.actuator_trnid[a, 0] == joint.id:
                data.ctrl[a] = q
    mujoco.mj_forward(model, data)
    for _ in range(round(seconds / model.opt.timestep)):
        mujoco.mj_step(model, data)
    qpos = {name: float(data.qpos[model.joint(name).qposadr[0]]) for name in movable}
    bodies = {model.body(b).name: data.xpos[b].copy() for b in range(model.nbody)}
    return {"qpos": qpos, "bodies": bodies, "timestep": model.opt.timestep}


def _browser_run(page, pose: str, seconds: float, timestep: float) -> None:
    page.evaluate(
        "([pose, n]) => { const v = simkitViewer; v.pause(true); v.reset(pose); v.step(n); }",
        [pose, round(seconds / timestep)],
    )


def test_each_arm_holds_its_named_poses_as_c_mujoco_does(site, browser, seed_kits):
    _, index, base = site
    problems: list[str] = []
    worst = 0.0
    arms = [kit for kit in index["kits"] if kit["category"] == "arm"]
    assert arms
    for kit in arms:
        kit_dir = seed_kits[kit["name"]].kit_dir
        page = _open(browser, base + kit["page"], problems)
        page.evaluate("window.simkitViewer.ready")
        poses = json.loads((kit_dir / "robot.json").read_text())["poses"]
        for name, values in poses.items():
            expected = _python_mujoco(kit_dir, values, 1.0)
            _browser_run(page, name, 1.0, expected["timestep"])
            assert page.evaluate("simkitViewer.time()") == pytest.approx(1.0, abs=1e-9)
            seen = page.evaluate("simkitViewer.qpos()")
            for joint, q in expected["qpos"].items():
                worst = max(worst, abs(seen[joint] - q))
                assert seen[joint] == pytest.approx(q, abs=ARM_TOLERANCE), (kit["name"], name)
        page.close()
    print(f"worst joint difference WASM vs Python MuJoCo after 1 s: {worst:.3g} rad")
    assert problems == []


def test_a_legged_robot_stands_as_in_c_mujoco(site, browser, seed_kits):
    _, index, base = site
    problems: list[str] = []
    legged = [kit for kit in index["kits"] if kit["category"] == "legged"]
    assert legged
    for kit in legged:
        kit_dir = seed_kits[kit["name"]].kit_dir
        doc = json.loads((kit_dir / "robot.json").read_text())
        root = doc["floating_base"]["child"]
        expected = _python_mujoco(kit_dir, doc["home"], 2.0)
        page = _open(browser, base + kit["page"], problems)
        page.evaluate("window.simkitViewer.ready")
        _browser_run(page, "home", 2.0, expected["timestep"])
        height = page.evaluate(f"simkitViewer.bodyPosition({json.dumps(root)})")[2]
        c_height = float(expected["bodies"][root][2])
        print(f"{kit['name']}: {root} at {height:.6f} m, C MuJoCo {c_height:.6f} m")
        print(f"{kit['name']}: height difference {abs(height - c_height):.3g} m")
        assert height == pytest.approx(c_height, abs=STAND_TOLERANCE)
        assert height > 0.5 * doc["floating_base"]["origin_xyz"][2]  # standing, not fallen
        page.close()
    assert problems == []
