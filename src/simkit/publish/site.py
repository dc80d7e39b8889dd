"""The readable part of the site beside the kits: the gallery, one page per kit, the pose
pictures and one shared copy of the live viewer (its JavaScript, three.js and MuJoCo's
WebAssembly build, ~11 MB, loaded once by the browser for every kit page).

Layout (in the site folder, beside index.json and the zips):

    index.html                 gallery
    site.css                   the pages' style
    <asset_dir>/index.html     the kit's page, beside the kit's files
    pictures/<asset_dir>/<pose>.png   the kit at each named pose (when a renderer is given)
    viewer/                    viewer.js, geoms.js, camera.js, vendor/three/, vendor/mujoco/

The viewer's files are those of `simkit view` (simkit/review/web, read as package data: the
publish layer imports nothing from review).
"""

from __future__ import annotations

import json
import re
from collections.abc import Callable
from pathlib import Path

from simkit.errors import SimkitError
from simkit.kitio import layout, reuse
from simkit.kitio.resources import data_dir
from simkit.publish import pages

#: simkit view's page files, shared with the site (package data of simkit.review)
WEB = Path(__file__).resolve().parents[1] / "review" / "web"
VIEWER_FILES = ("viewer.js", "geoms.js", "camera.js")
PAGE = "index.html"
SAFE_NAME = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_.-]*$")

#: kit folder -> {pose: PNG bytes}
Pictures = Callable[[Path], dict[str, bytes]]


def viewer_files() -> dict[str, bytes]:
    """viewer/<path> -> bytes: the viewer scripts and every vendored file, sorted."""
    files = {f"{pages.VIEWER}/{name}": (WEB / name).read_bytes() for name in VIEWER_FILES}
    vendor = WEB / "vendor"
    for path in sorted(p for p in vendor.rglob("*") if p.is_file()):
        files[f"{pages.VIEWER}/vendor/{path.relative_to(vendor).as_posix()}"] = path.read_bytes()
    return files


def picture_urls(folder: str, pictures: dict[str, bytes]) -> dict[str, str]:
    """pose -> site path of its PNG, in the renderer's order (robot.json's); a pose whose
    name is not a safe file name gets its position instead (the caption still names it)."""
    return {
        pose: f"pictures/{folder}/{pose if SAFE_NAME.match(pose) else f'pose_{i}'}.png"
        for i, pose in enumerate(pictures)
    }


def write_pages(
    site: Path, out_dir: Path, index: dict, kit_dirs: dict[str, Path], render: Pictures | None
) -> None:
    """Write the gallery, the kit pages, the pictures and the viewer into `site` (staging),
    hard-linking files equal to those published in `out_dir`."""

    def put(rel: str, data: bytes) -> None:
        reuse.write_file(site / rel, data, out_dir / rel)

    for kit in index["kits"]:
        folder = kit["folder"].rstrip("/")
        if any(f["url"] == f"{folder}/{PAGE}" for f in kit["files"]):
            raise SimkitError(f"{kit['name']}: the kit has a file {PAGE} at its top")
        kit_dir = kit_dirs[kit["name"]]
        shots = render(kit_dir) if render else {}
        urls = picture_urls(folder, shots)
        for pose, rel in urls.items():
            put(rel, shots[pose])
        doc = json.loads((kit_dir / layout.ROBOT_JSON).read_text())
        readme_path = kit_dir / layout.README
        readme = readme_path.read_text() if readme_path.is_file() else ""
        relative = {pose: f"../{rel}" for pose, rel in urls.items()}
        put(f"{folder}/{PAGE}", pages.kit_page(kit, doc, readme, relative).encode())
    put(PAGE, pages.gallery(index).encode())
    put("site.css", (data_dir("templates") / "site" / "site.css").read_bytes())
    for rel, data in viewer_files().items():
        put(rel, data)
