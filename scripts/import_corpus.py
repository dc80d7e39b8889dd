"""Import and build every URDF and MJCF of a folder with `simkit import`'s default flags.

    python scripts/import_corpus.py CORPUS_DIR [--exclude GLOB ...] [--movable-only]
        [--only GLOB ...] [--title TITLE] [--timeout S] [--out DIR] [--md FILE] [--limit N]
        [--ray] [--mjcf | --sdf]

Robot files are found by what they are: `*.urdf`, or with `--mjcf` the `*.xml` whose root
element is `<mujoco>` (`--movable-only`: with a joint inside a body), or with `--sdf` the
`*.sdf` files (`--movable-only`: with a `<joint>`). Each (sorted by path,
`--exclude` globs matched against the path relative to CORPUS_DIR): `simkit import URDF
--out DIR` with no other flag, a cold build with an empty cache, then the same import again
into the same folder. It checks issue 22's invariant: an import either refuses in one line
naming the URDF's own file, or writes a spec that validates, builds and compiles in MuJoCo;
never a traceback; the re-import gives byte-identical files and no stale ones. The table
(one per `--title`, default the folder's name) goes into docs/import-corpus.md, replacing
that corpus's earlier table, with the median import + cold build time. Runs one command at a
time, or with `--ray` one Ray task per URDF ($RAY_ADDRESS, else a local Ray), rows in the
same order: the same table. Beside the wall seconds each row gives the CPU seconds of the
import and the build (their processes and children: the figure other work on the machine
does not inflate) and the load average when it started. No robot is named here."""

from __future__ import annotations

import argparse
import fnmatch
import os
import re
import resource
import shutil
import statistics
import subprocess
import sys
import time
import xml.etree.ElementTree as ET
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
MOVABLE = {"revolute", "continuous", "prismatic"}


def urdfs(
    root: Path,
    exclude: list[str],
    movable_only: bool,
    only: list[str] = (),
    mjcf: bool = False,
    sdf: bool = False,
) -> list[Path]:
    """The corpus's URDFs, sorted, less the excluded ones, only those matching `only` if
    given (and those without a movable joint when asked; a file that does not parse is kept:
    the import must refuse it)."""
    out = []
    found = (p for p in root.rglob("*") if _is_mjcf(p)) if mjcf else root.rglob("*.urdf")
    found = root.rglob("*.sdf") if sdf else found
    for path in sorted(found):
        rel = path.relative_to(root).as_posix()
        if any(fnmatch.fnmatch(rel, glob) for glob in exclude):
            continue
        if only and not any(fnmatch.fnmatch(rel, glob) for glob in only):
            continue
        if movable_only and not _has_movable(path):
            continue
        out.append(path)
    return out


def _is_mjcf(path: Path) -> bool:
    """An `.xml` file whose root element is `<mujoco>` (an MJCF model or include)."""
    if path.suffix != ".xml" or not path.is_file():
        return False
    with path.open("rb") as handle:
        head = re.sub(rb"<!--.*?-->|<\?.*?\?>", b"", handle.read(65536), flags=re.S)
    return re.match(rb"\s*<\s*mujoco[\s>/]", head) is not None


def _has_movable(path: Path) -> bool:
    if path.suffix == ".sdf":  # an SDFormat file: any <joint> (its model moves on it)
        try:
            return any(True for _ in ET.parse(path).getroot().iter("joint"))
        except ET.ParseError:
            return True
    if path.suffix == ".xml":  # an MJCF: a joint inside a body (not a default class's)
        try:
            bodies = ET.parse(path).getroot().iter("body")
        except ET.ParseError:
            return True
        return any(b.find("joint") is not None or b.find("freejoint") is not None for b in bodies)
    try:
        text = path.read_bytes().lstrip()
        root = ET.fromstring(text[text.find(b"<robot") :] if b"<robot" in text else text)
    except ET.ParseError:
        return b'type="revolute"' in text or b'type="continuous"' in text
    return any(j.get("type") in MOVABLE for j in root.iter("joint"))


def _name(rel: Path) -> str:
    """A spec name from the URDF's whole relative path (two folders may hold the same file
    name), [a-z][a-z0-9_]*, 48 characters at most (a digest ends a longer one)."""
    import hashlib

    parts = [*rel.parent.parts, rel.name.split(".")[0]]
    name = re.sub(r"[^a-z0-9_]+", "_", "_".join(parts).lower()).strip("_") or "robot"
    name = name if name[0].isalpha() else f"r_{name}"
    if len(name) > 48:
        name = name[:41].rstrip("_") + "_" + hashlib.sha256(name.encode()).hexdigest()[:6]
    return name


def _cpu() -> float:
    """CPU seconds (user + system) of this process's waited-for children so far."""
    used = resource.getrusage(resource.RUSAGE_CHILDREN)
    return used.ru_utime + used.ru_stime


def _run(args: list[str], timeout: float) -> tuple[int, str, str, float]:
    """Exit code, stdout, stderr and wall seconds of one simkit command."""
    start = time.perf_counter()
    try:
        done = subprocess.run(
            [sys.executable, "-m", "simkit.cli", *args],
            capture_output=True,
            text=True,
            timeout=timeout,
        )
    except subprocess.TimeoutExpired:
        return 124, "", f"timed out after {timeout:.0f} s", time.perf_counter() - start
    return done.returncode, done.stdout, done.stderr, time.perf_counter() - start


def _files(folder: Path) -> dict[str, bytes]:
    return {
        p.relative_to(folder).as_posix(): p.read_bytes()
        for p in sorted(folder.rglob("*"))
        if p.is_file()
    }


def _refusal(urdf: Path, stderr: str) -> str:
    """'' when an import's refusal keeps the invariant (one line naming the URDF's file),
    else what is wrong with it."""
    lines = [ln for ln in stderr.strip().splitlines() if ln.strip()]
    if "Traceback" in stderr:
        return "traceback"
    if len(lines) != 1:
        return f"{len(lines)} lines of error"
    if urdf.name not in lines[0]:
        return "the error does not name the URDF"
    return ""


def one(urdf: Path, root: Path, work: Path, timeout: float) -> dict:
    """Import, build and re-import one URDF; its table row."""
    rel = urdf.relative_to(root)
    name = _name(rel)
    row = {"robot": rel.as_posix(), "import": "", "build": "", "reason": "", "invariant": "ok",
           "seconds": None, "cpu": None, "base": "", "load": os.getloadavg()[0]}  # fmt: skip
    cpu = _cpu()
    out = work / "specs" / name
    shutil.rmtree(out, ignore_errors=True)
    rc, stdout, stderr, import_s = _run(["import", str(urdf), "--name", name, "--out", str(out)],
                                        timeout)  # fmt: skip
    if rc:
        row["import"] = "refused"
        said = stderr.strip().splitlines()[-1] if stderr.strip() else f"rc {rc}"
        said = said.removeprefix("simkit: error: ").replace(str(root) + "/", "")
        row["reason"] = said[:160]  # the corpus's own path taken out first: the reason is kept
        bad = _refusal(urdf, stderr) if rc != 124 else "timed out"
        row["invariant"] = bad or "ok"
        return row
    row["import"] = "ok"
    row["base"] = "floating" if "floating base:" in stdout else "fixed"
    first = _files(out)
    cache = work / "cache" / name
    shutil.rmtree(cache, ignore_errors=True)  # cold means cold
    build = ["build", str(out / f"{name}.yaml"), "--out", str(work / "kits"), "-q"]
    rc, _o, stderr, build_s = _run([*build, "--cache-dir", str(cache)], timeout)
    row["seconds"] = import_s + build_s
    row["cpu"] = _cpu() - cpu  # the import's and the build's, with their child processes
    failed = re.search(r"FAIL ([\w.]+)", stderr)
    if rc == 0:
        row["build"] = "ok"
    elif rc == 124:  # the machine's load, not the invariant: no verdict
        row["build"] = "timed out"
        row["reason"] = stderr
    elif failed:  # built and compiled; a check failed
        row["build"] = "check failed"
        row["reason"] = " ".join(stderr.split())[stderr.find("FAIL") :][:160]
    else:  # the written spec was refused, or the build broke: the invariant is broken
        row["build"] = "error"
        row["reason"] = (stderr.strip().splitlines() or ["?"])[-1][:160]
        row["invariant"] = "traceback" if "Traceback" in stderr else "spec refused by build"
    rc, _o, _e, _s = _run(["import", str(urdf), "--name", name, "--out", str(out)], timeout)
    if rc or _files(out) != first:
        row["invariant"] = "re-import differs"
    return row


def table(rows: list[dict], total: int) -> str:
    kind = "MJCF" if rows and all(r["robot"].endswith(".xml") for r in rows) else "URDF"
    head = (
        f"| {kind} | base | import | build | invariant | import + cold build s | CPU s | load "
        "| reason |"
    )
    lines = [head, "|---|---|---|---|---|---:|---:|---:|---|"]
    for r in rows:
        seconds = f"{r['seconds']:.1f}" if r["seconds"] is not None else ""
        cpu = f"{r['cpu']:.1f}" if r.get("cpu") is not None else ""
        reason = r["reason"].replace("|", "\\|")
        lines.append(
            f"| {r['robot']} | {r['base']} | {r['import']} | {r['build']} | {r['invariant']} "
            f"| {seconds} | {cpu} | {r.get('load', 0):.1f} | {reason} |"
        )
    passed = sum(r["build"] == "ok" for r in rows)
    kept = sum(r["invariant"] == "ok" for r in rows)
    times = [r["seconds"] for r in rows if r["seconds"] is not None]
    median = f"{statistics.median(times):.1f} s" if times else "n/a"
    cpus = [r["cpu"] for r in rows if r.get("cpu") is not None]
    if cpus:
        median += f" wall, {statistics.median(cpus):.1f} s CPU"
    partial = "" if len(rows) == total else f" (partial: {len(rows)} of {total} run)"
    lines += [
        "",
        f"{passed} of {len(rows)} give a checked kit ({100 * passed / max(len(rows), 1):.1f} "
        f"%){partial}; the invariant holds for {kept} of {len(rows)}; median import + cold "
        f"build {median} per robot that imported.",
    ]
    return "\n".join(lines) + "\n"


def save(md: Path, title: str, command: str, body: str) -> None:
    """Replace (or append) the `## title` section of `md`."""
    text = md.read_text(encoding="utf-8") if md.is_file() else ""
    if not text.startswith("# Import corpora"):
        text = (
            "# Import corpora\n\nMade by `scripts/import_corpus.py`: every URDF imported "
            "with `simkit import`'s default flags, built with an empty cache (wall seconds "
            "on 2 shared cores; CPU seconds of the import and build processes, which the "
            "other work on the machine does not inflate; the 1-minute load average when the "
            "row started), then imported again into the same folder.\n"
        )
    section = f"## {title}\n\n`{command}`\n\n{body}"
    pattern = re.compile(rf"^## {re.escape(title)}\n.*?(?=^## |\Z)", re.S | re.M)
    if pattern.search(text):
        text = pattern.sub(lambda _m: section + "\n", text)
    else:
        text = text.rstrip("\n") + "\n\n" + section
    md.write_text(text.rstrip("\n") + "\n", encoding="utf-8")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("corpus", type=Path, help="folder searched for *.urdf")
    parser.add_argument("--exclude", action="append", default=[], help="glob of paths to skip")
    parser.add_argument("--movable-only", action="store_true", help="only URDFs with a joint")
    parser.add_argument("--only", action="append", default=[], help="glob of paths to run")
    parser.add_argument("--title", default=None, help="the table's heading [folder name]")
    parser.add_argument("--timeout", type=float, default=600.0, help="s per command")
    parser.add_argument("--limit", type=int, default=0, help="run the first N only")
    parser.add_argument("--out", type=Path, default=Path("/tmp/simkit-corpus"))
    parser.add_argument("--md", type=Path, default=REPO / "docs" / "import-corpus.md")
    parser.add_argument("--ray", action="store_true", help="one Ray task per URDF")
    parser.add_argument("--mjcf", action="store_true", help="MJCF files (<mujoco> root), not URDF")
    parser.add_argument("--sdf", action="store_true", help="SDFormat files (*.sdf), not URDF")
    args = parser.parse_args()
    root = args.corpus.resolve()
    if not root.is_dir():
        sys.exit(f"{args.corpus}: not a folder")
    found = urdfs(root, args.exclude, args.movable_only, args.only, args.mjcf, args.sdf)
    found = found[: args.limit] if args.limit else found
    title = args.title or root.name
    flags = [f"--exclude '{g}'" for g in args.exclude] + [f"--only '{g}'" for g in args.only]
    flags += ["--movable-only"] if args.movable_only else []
    flags += ["--mjcf"] if args.mjcf else []
    flags += ["--sdf"] if args.sdf else []
    command = " ".join(["python scripts/import_corpus.py CORPUS", *flags])

    def done(rows: list[dict], r: dict) -> None:
        print(f"{r['robot']}: {r['import']} {r['build']} {r['invariant']} {r['reason']}",
              flush=True)  # fmt: skip
        save(args.md, title, command.strip(), table(rows, len(found)))

    rows = (_on_ray if args.ray else _serial)(found, root, args, done)
    print(table(rows, len(found)))


def _serial(found: list[Path], root: Path, args, done) -> list[dict]:
    rows: list[dict] = []
    for urdf in found:
        rows.append(one(urdf, root, args.out, args.timeout))
        done(rows, rows[-1])
    return rows


def _on_ray(found: list[Path], root: Path, args, done) -> list[dict]:
    """One Ray task per URDF ($RAY_ADDRESS, else a local Ray; the corpus folder and `--out`
    at the same paths on every worker); rows kept in the serial order, so the table is the
    serial one."""
    import os

    import ray

    if not ray.is_initialized():
        ray.init(address=os.environ.get("RAY_ADDRESS") or None, include_dashboard=False)
    task = ray.remote(num_cpus=1, max_retries=2)(one)
    index = {task.remote(urdf, root, args.out, args.timeout): i for i, urdf in enumerate(found)}
    slots: list[dict | None] = [None] * len(found)
    pending = list(index)
    while pending:
        ready, pending = ray.wait(pending, num_returns=1)
        slots[index[ready[0]]] = row = ray.get(ready[0])
        done([r for r in slots if r is not None], row)
    return [r for r in slots if r is not None]


if __name__ == "__main__":
    main()
