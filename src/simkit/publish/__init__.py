"""`simkit publish`: build every robot and lay the kits out as the download site serves them.

Kit page, "Downloads": every file of every kit has its own URL under /assets/sim/<model>/,
with the same layout as the zip, and /assets/sim/index.json lists the kits and all their
files. So the output folder (the site's /assets/sim/) holds:

    index.json                       kits, and every file with its size and sha256
    rosie-1000-sim-kit.zip           the kit zip (unzips to rosie_1000_description/)
    1000/robot.json, 1000/urdf/...   the kit's files, one URL each (<model> = spec asset_dir)
    index.html, 1000/index.html      the gallery and the kit's page (site.py, pages.py)
    viewer/                          the live viewer, one copy for every page

index.json's `format` is INDEX_FORMAT; each kit also carries what Menagerie's registry does
(registry.py): licence, category, DoF, entry points, the zip's sha256 (in `zip`), and the
checks passed per format. Fields are only ever added, so a reader of format 1 still works.

The whole folder is built beside the output and swapped in at the end, so a failed build
leaves the previous publication in place. Publications into one folder serialize on a lock of
its parent, and the swap is one `renameat2` exchange (`kitio.atomic.swap_folder`): a kill at
any instant leaves the old site or the new one, and the next publish removes what it left.
Files whose bytes did not change are hard links to the published ones (`kitio/reuse.py`), so
they keep their mtime, and a publication equal to the published one writes nothing: an
`rsync -a` to the server then sends only what changed.
"""

from __future__ import annotations

import hashlib
import json
import shutil
import tempfile
from collections.abc import Callable, Sequence
from pathlib import Path

from simkit.errors import SimkitError
from simkit.kitio import atomic, interrupt, layout, reuse
from simkit.kitio.jsonout import dumps
from simkit.kitio.resources import robot_names
from simkit.pipeline import BuildResult, build, find_spec, write_tree
from simkit.publish import registry
from simkit.publish.site import Pictures, write_pages
from simkit.spec.validate import load_spec

#: 1: kits, zips and files; 2: + licence, category, dof, mass, reach, entry_points,
#: thumbnail, checks per kit, and the pages (index.html)
INDEX_FORMAT = 2


def _entry(path: str, data: bytes, url: str | None = None) -> dict:
    out = {"path": path, "size": len(data), "sha256": hashlib.sha256(data).hexdigest()}
    if url is not None:
        out["url"] = url
    return out


def _asset_dir(target: str, name: str) -> str:
    spec, _ = load_spec(find_spec(target)[0])
    return layout.asset_dir(name, spec.asset_dir)


def _check_out_dir(out_dir: Path) -> None:
    """Refuse to replace a folder that is not an earlier publication."""
    if out_dir.is_file():
        raise SimkitError(f"{out_dir}: is a file, not a folder")
    if out_dir.is_dir() and any(out_dir.iterdir()) and not (out_dir / layout.INDEX_JSON).is_file():
        raise SimkitError(
            f"{out_dir}: not empty and not an earlier publication (no "
            f"{layout.INDEX_JSON}); choose another --out"
        )


def publish(
    out_dir: Path,
    targets: Sequence[str] | None = None,
    progress: Callable[[str], None] | None = None,
    on_ray: bool = False,
    pictures: Pictures | None = None,
    built: Sequence[BuildResult] | None = None,
    **build_options,
) -> dict:
    """Build `targets` (default: every robot in robots/), check them, and write the site
    folder; returns the index. `build_options` go to `build.build` (cache, jobs); `on_ray`:
    one Ray task per robot (simkit/cluster.py), the site still written here. `pictures`:
    kit folder -> {pose: PNG} for the kit pages (the CLI passes simkit render's). `built`:
    kits already built and checked (their robot names are the targets), published as they
    are instead of building `targets`."""
    say = progress or (lambda _msg: None)
    out_dir = Path(out_dir)
    _check_out_dir(out_dir)
    names = [r.robot for r in built] if built else list(targets) if targets else robot_names()
    if built:
        build_options = {**build_options, "built": list(built)}
    with atomic.locked(out_dir.parent):  # one publish at a time; makes the parent (one line)
        atomic.recover_folder(out_dir)
        options = {**build_options, "on_ray": on_ray}
        return _publish_locked(out_dir, names, say, options, pictures)


def _publish_locked(
    out_dir: Path,
    names: list[str],
    say: Callable[[str], None],
    build_options: dict,
    pictures: Pictures | None = None,
) -> dict:
    """`publish` with the lock held: build every kit and the index into a staging folder
    beside `out_dir`, then swap it in as one unit (`atomic.swap_folder`)."""
    staging = None
    try:
        with interrupt.held():  # a signal right after mkdir still finds `staging` set
            staging = _make_staging(out_dir)
        site, work = staging / "site", staging / "kits"
        site.mkdir()
        kits, kit_dirs = [], {}
        for target, result in zip(names, _build_all(names, work, say, build_options), strict=True):
            top = layout.kit_dir_name(result.robot)
            folder = _asset_dir(target, result.robot)
            if any(kit["folder"] == f"{folder}/" for kit in kits):
                raise SimkitError(
                    f"{target}: asset folder '{folder}' is already used by "
                    "another kit (set a distinct asset_dir in the spec)"
                )
            zip_data = result.zip_path.read_bytes()
            reuse.write_file(site / result.zip_path.name, zip_data, out_dir / result.zip_path.name)
            write_tree(site / folder, result.files, out_dir / folder)
            doc = json.loads(result.files[layout.ROBOT_JSON])
            kit_dirs[result.robot] = result.kit_dir
            kits.append(
                {
                    "name": result.robot,
                    "title": doc.get("title", result.robot),
                    "folder": f"{folder}/",
                    "top_folder": f"{top}/",
                    "zip": _entry(result.zip_path.name, zip_data),
                    "files": [
                        _entry(f"{top}/{path}", data, f"{folder}/{path}")
                        for path, data in sorted(result.files.items())
                    ],
                    "page": f"{folder}/index.html",
                    **registry.facts(result.files, result.findings),
                }
            )
        index = {
            "format": INDEX_FORMAT,
            "note": "paths are as in each zip; urls are relative to this file's folder",
            "kits": kits,
        }
        reuse.write_file(site / layout.INDEX_JSON, dumps(index), out_dir / layout.INDEX_JSON)
        write_pages(site, out_dir, index, kit_dirs, pictures)
        if not reuse.same_tree(site, out_dir):  # else: the same publication, left untouched
            if out_dir.is_dir():
                reuse.keep_folder_times(site, out_dir)
            atomic.swap_folder(site, out_dir)
    finally:
        if staging is not None:
            shutil.rmtree(staging, ignore_errors=True)
    return index


def _make_staging(out_dir: Path) -> Path:
    """A fresh staging folder beside `out_dir`; one line when it cannot be made."""
    try:
        made = tempfile.mkdtemp(prefix=f".{out_dir.name}.", suffix=".staging", dir=out_dir.parent)
    except OSError as exc:
        raise SimkitError(f"{out_dir.parent}: cannot create a folder: {exc.strerror}") from None
    return Path(made)


def _build_all(names: list[str], work: Path, say: Callable[[str], None], options: dict) -> list:
    """Every kit, built here one after another or as Ray tasks (`on_ray`), published into
    `work` either way."""
    options = dict(options)
    if options.get("built"):
        return options["built"]
    if options.pop("on_ray", False):
        from simkit.cluster import build_on_ray

        return build_on_ray(names, work, say, check=True, **options)
    results = []
    for target in names:
        say(f"build {target}")
        results.append(build(target, work, check=True, progress=say, remember=False, **options))
    return results
