"""Convert URDF and MJCF corpora to USD with NVIDIA's converters, import each USD back with
`simkit import`'s default flags, and compare the imported robot with the ORIGINAL file.

    python scripts/usd_corpus.py CORPUS_DIR [--mjcf] [--only GLOB ...] [--exclude GLOB ...]
        [--venv DIR] [--out DIR] [--build] [--reuse] [--limit N] [--title TITLE] [--md FILE]

Each robot file (`*.urdf` with a movable joint; with `--mjcf` the `*.xml` whose root is
`<mujoco>` and that has a joint) is converted with its default flags by
`urdf_usd_converter FILE DIR` or `mujoco_usd_converter FILE DIR` from the converters' own
venv (`--venv`, default
~/.cache/simkit-ci/venv-usdconv: they pin their own usd-core), then `simkit import DIR/X.usda`
(no flag), and the imported spec compared with the original, read by yourdfpy (URDF) or
compiled by MuJoCo (MJCF), independently of both converter and importer:

- each original body of positive mass: its mass (1e-6 relative) in the spec under the same
  name (names made USD identifiers, as the converters make them; renames from the spec's
  `source_differences`); a value the import estimated (the spec's `estimated`: a zero
  inertia, a missing limit) is the import's, as for a URDF import, and not compared;
- each original movable joint: its type (revolute, continuous, prismatic) and limits (a
  limit of 1e15 or more is none, `NO_LIMIT`: a revolute joint with it is continuous);
- at 20 seeded configurations (hinge and slide joints in their limits, balls and free joints
  at rest), every massive body's centre of mass (1e-6 m) and inertia tensor in the root
  body's frame: quantities that do not depend on where a format puts its link frames.

With `--reuse` a USD an earlier run converted is not converted again (it is imported again,
by this code). With `--build` each spec is also built (`simkit build`, its checks; the log in
OUT/ROBOT/build.log, a failing build's row names its failing checks). A row: the robot file,
the step reached (convert, import, compare, build), the result and the first difference.
The table goes into docs/import-corpus.md under its title. No robot is named here.
"""

from __future__ import annotations

import argparse
import fnmatch
import math
import os
import re
import shutil
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import yaml

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "src"))
VENV = Path(os.environ.get("XDG_CACHE_HOME", Path.home() / ".cache")) / "simkit-ci/venv-usdconv"
SEEDS = 20
TOL = 1e-6
#: |limit| (rad or m) from which an original's joint limit is no limit: SDFormat's default
#: limit is +-1e16 and URDFs made from SDF (a multirotor's rotors) carry it. At the spec's
#: fastest joint (200 rad/s) 1e15 rad takes 160,000 years: no motion ever reaches it, so
#: such a revolute joint moves as a continuous one and is compared as one (simkit's own URDF
#: and SDF imports read it so too). A limit of a few turns (a cable's) stays a limit.
NO_LIMIT = 1e15


def robots(root: Path, mjcf: bool, only: list[str], exclude: list[str]) -> list[Path]:
    """The corpus's robot files, sorted by path."""
    found = sorted(root.rglob("*.xml" if mjcf else "*.urdf"))
    out = []
    for path in found:
        rel = path.relative_to(root).as_posix()
        if only and not any(fnmatch.fnmatch(rel, g) for g in only):
            continue
        if any(fnmatch.fnmatch(rel, g) for g in exclude):
            continue
        if not (_jointed_mjcf(path) if mjcf else _jointed_urdf(path)):
            continue
        out.append(path)
    return out


def _jointed_mjcf(path: Path) -> bool:
    try:
        root = ET.parse(path).getroot()
    except ET.ParseError:
        return False
    return root.tag == "mujoco" and any(e.tag in ("joint", "freejoint") for e in root.iter())


def _jointed_urdf(path: Path) -> bool:
    """A URDF with a movable joint (a robot, not a prop)."""
    try:
        root = ET.parse(path).getroot()
    except ET.ParseError:
        return True  # the converter or the import must say why
    kinds = {j.get("type") for j in root.iter("joint")}
    return bool(kinds & {"revolute", "continuous", "prismatic"})


def identifier(name: str) -> str:
    """A name as a USD prim name (what the converters make of it)."""
    out = re.sub(r"[^A-Za-z0-9_]", "_", name)
    return out if out and not out[0].isdigit() else f"_{out}"


def _run(args: list[str], timeout: float, env=None) -> tuple[int, str]:
    try:
        done = subprocess.run(args, capture_output=True, text=True, timeout=timeout, env=env)
    except subprocess.TimeoutExpired:
        return 124, "timed out"
    return done.returncode, (done.stderr or done.stdout).strip()


def one(path: Path, root: Path, work: Path, args) -> dict:
    """Convert, import, compare (and build) one robot file; its row."""
    rel = path.relative_to(root).as_posix()
    row = {"file": rel, "step": "convert", "ok": False, "why": ""}
    done = _steps(path, rel, work, row, args)
    # no machine's paths in the table: the corpus and work folders by name
    why = done["why"].replace(str(root), root.name).replace(str(work), "OUT")
    done["why"] = why.replace(str(Path.home()), "~")
    return done


def _steps(path: Path, rel: str, work: Path, row: dict, args) -> dict:
    """The steps of `one`, filling `row`."""
    slug = re.sub(r"[^A-Za-z0-9]+", "_", rel).strip("_").lower()
    conv, out = work / slug / "usd", work / slug / "spec"
    name = f"r_{slug[-40:]}".strip("_")
    env = dict(os.environ, PYTHONPATH=str(REPO / "src"))
    usdas = sorted(conv.glob("*.usda")) if args.reuse and conv.is_dir() else []
    if not usdas:
        tool = "mujoco_usd_converter" if args.mjcf else "urdf_usd_converter"
        code, text = _run([str(venv_dir(args) / "bin" / tool), str(path), str(conv)], args.timeout)
        usdas = sorted(conv.glob("*.usda")) if conv.is_dir() else []
        if code or not usdas:
            shutil.rmtree(conv, ignore_errors=True)  # a failed conversion's part: not reused
            row["why"] = _last(text) or "no USD written"
            return row
    row["step"] = "import"  # always with this code: a reused USD is imported again
    cmd = [sys.executable, "-m", "simkit.cli", "import", str(usdas[0]), "--out", str(out)]
    code, text = _run([*cmd, "--name", name, "-q"], args.timeout, env)
    if code:
        row["why"] = _last(text)
        return row
    row["step"] = "compare"
    spec = yaml.safe_load((out / f"{name}.yaml").read_text())
    try:
        problems = compare_mjcf(path, spec) if args.mjcf else compare_urdf(path, spec)
    except Exception as exc:  # a reader's own failure is a row, not the run's end
        problems = [f"comparison failed: {type(exc).__name__}: {_last(str(exc))}"]
    if problems:
        row["why"] = f"{len(problems)} differences; {problems[0]}"
        return row
    if args.build:
        row["step"] = "build"
        cmd = [sys.executable, "-m", "simkit.cli", "build", str(out / f"{name}.yaml")]
        code, text = _run([*cmd, "--out", str(work / slug / "kits")], args.timeout, env)
        (work / slug / "build.log").write_text(text + "\n")
        if code:
            row["why"] = _failed(text)
            return row
    row["ok"] = True
    return row


def venv_dir(args) -> Path:
    """The converters' venv."""
    return Path(args.venv)


def _failed(text: str) -> str:
    """A failed build's checks: the failing checks' names, then the first one's line."""
    fails = [line.strip() for line in text.splitlines() if line.strip().startswith("FAIL ")]
    if not fails:
        return _last(text)
    names = ", ".join(sorted({line.split()[1].rstrip(":") for line in fails}))
    return f"{names}: {fails[0]}"[:300].replace("|", "/")


def _last(text: str) -> str:
    lines = [line for line in text.splitlines() if line.strip()]
    return (lines[-1] if lines else "")[:200].replace("|", "/")


# --- the spec's robot ---------------------------------------------------------------


def _rpy(r, p, y) -> np.ndarray:
    cr, sr, cp, sp, cy, sy = (
        math.cos(r),
        math.sin(r),
        math.cos(p),
        math.sin(p),
        math.cos(y),
        math.sin(y),
    )
    return np.array([
        [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
        [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
        [-sp, cp * sr, cp * cr],
    ])  # fmt: skip


def _axis_turn(axis, angle: float) -> np.ndarray:
    x, y, z = np.asarray(axis, float) / np.linalg.norm(axis)
    k = np.array([[0, -z, y], [z, 0, -x], [-y, x, 0]])
    return np.eye(3) + math.sin(angle) * k + (1 - math.cos(angle)) * k @ k


def _spec_poses(spec: dict, q: dict[str, float]) -> dict[str, np.ndarray]:
    """Each spec link's pose in the spec's root frame at joint values `q` (by spec name)."""
    out = {spec["root"]: np.eye(4)}
    joints = list(spec["joints"])
    while joints:
        rest = []
        for j in joints:
            if j["parent"] not in out:
                rest.append(j)
                continue
            t = np.eye(4)
            t[:3, :3] = _rpy(*j.get("rpy", [0, 0, 0]))
            t[:3, 3] = j.get("xyz", [0, 0, 0])
            m = np.eye(4)
            value = q.get(j["name"], 0.0)
            if j["type"] in ("revolute", "continuous"):
                m[:3, :3] = _axis_turn(j.get("axis", [1, 0, 0]), value)
            elif j["type"] == "prismatic":
                m[:3, 3] = np.asarray(j.get("axis", [1, 0, 0]), float) * value
            out[j["child"]] = out[j["parent"]] @ t @ m
        if len(rest) == len(joints):
            break
        joints = rest
    return out


def _renames(spec: dict) -> dict[str, str]:
    out = {}
    for item in spec.get("source_differences", []):
        kind, _, rest = str(item.get("what", "")).partition(".")
        name, _, attr = rest.rpartition(".")
        if attr == "name" and kind in ("links", "joints") and item.get("kit"):
            out[f"{kind}.{name}"] = item["kit"]
    return out


class Kit:
    """The imported spec, looked up by the original's names."""

    def __init__(self, spec: dict) -> None:
        self.spec = spec
        self.renames = _renames(spec)
        self.links = {link["name"]: link for link in spec["links"]}
        self.joints = {j["name"]: j for j in spec["joints"]}

    def name(self, kind: str, original: str) -> str:
        """The kit's name of an original element: as the import renamed it, else its own
        (a converter keeps it as the prim's displayName), else as a USD identifier."""
        table = self.links if kind == "links" else self.joints
        for candidate in (original, identifier(original)):
            if f"{kind}.{candidate}" in self.renames:
                return self.renames[f"{kind}.{candidate}"]
            if candidate in table:
                return candidate
        return identifier(original)

    def com_world(self, poses: dict, link: str) -> tuple[np.ndarray, np.ndarray]:
        """(CoM, inertia tensor) of a spec link in the root frame."""
        item, pose = self.links[link], poses[link]
        rot = pose[:3, :3]
        com = pose[:3, :3] @ np.asarray(item.get("com", [0, 0, 0]), float) + pose[:3, 3]
        i = item.get("inertia", {})
        tensor = np.array([
            [i.get("ixx", 0), i.get("ixy", 0), i.get("ixz", 0)],
            [i.get("ixy", 0), i.get("iyy", 0), i.get("iyz", 0)],
            [i.get("ixz", 0), i.get("iyz", 0), i.get("izz", 0)],
        ])  # fmt: skip
        return com, rot @ tensor @ rot.T


def _close(a, b, scale: float, floor: float) -> bool:
    return bool(np.max(np.abs(np.asarray(a, float) - np.asarray(b, float))) <= TOL * scale + floor)


def _merged(kit: Kit, bodies: dict, welded: dict[str, str]) -> tuple[dict, dict]:
    """(original body -> the kit link it is in, kit-side name -> summed original mass): a
    body the kit lacks that is welded to its parent (a fixed joint; a converter merges such
    bodies into one rigid body) counts in its parent's link."""
    into = {}
    for name in bodies:
        at, seen = name, set()
        while kit.name("links", at) not in kit.links and at in welded and at not in seen:
            seen.add(at)
            at = welded[at]
        into[name] = at
    masses: dict[str, float] = {}
    for name, (mass, _) in bodies.items():
        masses[into[name]] = masses.get(into[name], 0.0) + mass
    return into, masses


def _combined(parts: list[tuple[float, np.ndarray, np.ndarray]]) -> tuple:
    """(CoM, inertia about it) of bodies (mass, CoM, inertia about own CoM), one frame."""
    total = sum(m for m, _, _ in parts)
    com = sum(m * c for m, c, _ in parts) / total
    tensor = np.zeros((3, 3))
    for m, c, i in parts:
        d = c - com
        tensor += i + m * (np.dot(d, d) * np.eye(3) - np.outer(d, d))
    return com, tensor


def _compare_bodies(
    kit: Kit, bodies: dict[str, tuple], joints: dict, poses_fn, welded: dict[str, str]
) -> list[str]:
    """Common comparison: `bodies` original name -> (mass, None), `joints` original name ->
    (type, limits or None), `poses_fn(rng)` -> (q for the kit by original joint name,
    {original body: (CoM, inertia) in the root frame}); `welded`: body -> the parent it is
    fixed to (bodies the kit lacks are compared merged into it, `_merged`)."""
    out = []
    into, merged = _merged(kit, bodies, welded)
    for name, mass in sorted(merged.items()):
        link = kit.links.get(kit.name("links", name))
        if link is None:
            out.append(f"link {name} missing")
        elif "mass" not in link.get("estimated", []) and not _close(link["mass"], mass, mass, 0):
            out.append(
                f"link {name}: mass {mass:.9g} in the original, {link.get('mass')} in the kit"
            )
    for name, (kind, limits) in sorted(joints.items()):
        joint = kit.joints.get(kit.name("joints", name))
        if joint is None:
            out.append(f"joint {name} missing")
            continue
        if joint["type"] != kind:
            out.append(f"joint {name}: {kind} in the original, {joint['type']} in the kit")
        elif limits is not None and not {"lower", "upper"} & set(joint.get("estimated", [])):
            got = (joint.get("lower"), joint.get("upper"))
            if None in got or not _close(got, limits, max(map(abs, limits)), 1e-9):
                out.append(f"joint {name}: limits {limits} in the original, {got} in the kit")
    if out:
        return out
    rng = np.random.default_rng(0)
    for _ in range(SEEDS):
        q, each = poses_fn(rng)
        groups: dict[str, list] = {}
        for name, (com, tensor) in each.items():
            groups.setdefault(into[name], []).append((bodies[name][0], com, tensor))
        wanted = {name: _combined(parts) for name, parts in groups.items()}
        poses = _spec_poses(kit.spec, {kit.name("joints", k): v for k, v in q.items()})
        for name, (com, tensor) in sorted(wanted.items()):
            link = kit.name("links", name)
            if link not in poses:
                return [f"link {name} not in the kit's tree"]
            got_com, got_tensor = kit.com_world(poses, link)
            estimated = set(kit.links[link].get("estimated", []))
            if "com" not in estimated and not _close(got_com, com, 1.0, TOL):
                far = float(np.max(np.abs(got_com - com)))
                return [f"link {name}: CoM off by {far:.3g} m at a seeded configuration"]
            scale = float(np.linalg.norm(tensor))
            if scale < 1e-12:  # the original gives its body no inertia: nothing to compare
                continue
            if "inertia" not in estimated and not _close(got_tensor, tensor, scale, 1e-12):
                return [f"link {name}: inertia (root frame) differs at a seeded configuration"]
    return out


def _unlimited(kind: str, limits: tuple | None) -> tuple[str, tuple | None]:
    """(type, limits) of an original joint as it moves: a limit at or beyond NO_LIMIT is
    none, and a revolute joint with such a limit is continuous. (A URDF revolute without
    lower/upper is not: its limits default to 0, which the import estimates.)"""
    if limits is None or max(map(abs, limits)) < NO_LIMIT:
        return kind, limits
    return ("continuous" if kind == "revolute" else kind), None


def compare_urdf(path: Path, spec: dict) -> list[str]:
    """The spec against the original URDF (yourdfpy)."""
    import tempfile

    from simkit.check.source.urdf import load_urdf

    with tempfile.TemporaryDirectory() as tmp:  # yourdfpy's parser wants no text before <?xml
        clean = Path(tmp) / path.name
        clean.write_bytes(path.read_bytes().lstrip())
        robot = load_urdf(clean, [])
    kit = Kit(spec)
    bodies = {}
    for link in robot.links:
        if link.inertial is not None and (link.inertial.mass or 0) > 0:
            bodies[link.name] = (float(link.inertial.mass), None)
    joints = {}
    for j in robot.joints:
        if j.type in ("revolute", "continuous", "prismatic") and j.mimic is None:
            lim = j.limit
            limits = None
            if j.type != "continuous" and lim is not None and lim.lower is not None:
                limits = (float(lim.lower), float(lim.upper))
            joints[j.name] = _unlimited(j.type, limits)
    children = {j.child for j in robot.joints}
    root = next(link.name for link in robot.links if link.name not in children)
    kit_root = kit.name("links", root)

    def poses_fn(rng):
        q = {}
        for j in robot.joints:
            if j.type in ("revolute", "continuous", "prismatic") and j.mimic is None:
                lo, hi = sorted(joints[j.name][1] or (-math.pi, math.pi))
                q[j.name] = float(rng.uniform(lo, hi))
        for j in robot.joints:
            if j.mimic is not None and j.mimic.joint in q:
                q[j.name] = q[j.mimic.joint] * (j.mimic.multiplier or 1.0) + (j.mimic.offset or 0.0)
        world = _urdf_poses(robot, root, q)
        base = _spec_poses(kit.spec, {kit.name("joints", k): v for k, v in q.items()})
        shift = base[kit_root] if kit_root in base else np.eye(4)
        wanted = {}
        for name in bodies:
            link = next(x for x in robot.links if x.name == name)
            origin = np.eye(4) if link.inertial.origin is None else np.asarray(link.inertial.origin)
            tensor = np.asarray(link.inertial.inertia, float)
            pose = shift @ world[name] @ origin
            wanted[name] = (pose[:3, 3], pose[:3, :3] @ tensor @ pose[:3, :3].T)
        return q, wanted

    welded = {j.child: j.parent for j in robot.joints if j.type == "fixed"}
    return _compare_bodies(kit, bodies, joints, poses_fn, welded)


def _urdf_poses(robot, root: str, q: dict) -> dict[str, np.ndarray]:
    out, todo = {root: np.eye(4)}, [root]
    while todo:
        at = todo.pop(0)
        for j in robot.joints:
            if j.parent != at:
                continue
            origin = np.eye(4) if j.origin is None else np.asarray(j.origin, float)
            m = np.eye(4)
            axis = np.asarray((1, 0, 0) if j.axis is None else j.axis, float)
            if j.type in ("revolute", "continuous"):
                m[:3, :3] = _axis_turn(axis, q.get(j.name, 0.0))
            elif j.type == "prismatic":
                m[:3, 3] = axis / np.linalg.norm(axis) * q.get(j.name, 0.0)
            out[j.child] = out[at] @ origin @ m
            todo.append(j.child)
    return out


def compare_mjcf(path: Path, spec: dict) -> list[str]:
    """The spec against the original MJCF (compiled by MuJoCo)."""
    import mujoco

    model = mujoco.MjModel.from_xml_path(str(path))
    data = mujoco.MjData(model)
    tops = {int(model.body_rootid[model.jnt_bodyid[j]]) for j in range(model.njnt)}
    top = min(tops) if tops else 1
    kit = Kit(spec)
    mine = [b for b in range(1, model.nbody) if model.body_rootid[b] == top]
    name = {b: model.body(b).name or f"body{b}" for b in mine}
    for b in mine:  # an unnamed body: the kit's link its last joint moves
        count = int(model.body_jntnum[b])
        if not model.body(b).name and count:
            last = int(model.body_jntadr[b]) + count - 1
            joint = kit.joints.get(kit.name("joints", model.joint(last).name or f"jnt{last}"))
            if joint is not None:
                kit.renames[f"links.{name[b]}"] = joint["child"]
    bodies = {name[b]: (float(model.body_mass[b]), None) for b in mine if model.body_mass[b] > 0}
    joints = {}
    for j in range(model.njnt):
        if model.jnt_type[j] in (2, 3) and model.body_rootid[model.jnt_bodyid[j]] == top:
            kind = "prismatic" if model.jnt_type[j] == 2 else "revolute"
            limits = tuple(float(v) for v in model.jnt_range[j]) if model.jnt_limited[j] else None
            if kind == "revolute" and limits is None:
                kind = "continuous"
            joints[model.joint(j).name or f"jnt{j}"] = _unlimited(kind, limits)
    kit_root = kit.name("links", name[top])

    def poses_fn(rng):
        data.qpos[:] = model.qpos0
        q = {}
        for j in range(model.njnt):
            jn = model.joint(j).name or f"jnt{j}"
            if jn not in joints:
                continue
            lo, hi = sorted(joints[jn][1] or (-math.pi, math.pi))
            value = float(rng.uniform(lo, hi))
            adr = model.jnt_qposadr[j]
            data.qpos[adr] = value
            q[jn] = value - float(model.qpos0[adr])
        mujoco.mj_kinematics(model, data)
        mujoco.mj_comPos(model, data)
        base = _spec_poses(kit.spec, {kit.name("joints", k): v for k, v in q.items()})
        at = np.eye(4)
        at[:3, :3], at[:3, 3] = data.xmat[top].reshape(3, 3), data.xpos[top]
        shift = (base[kit_root] if kit_root in base else np.eye(4)) @ np.linalg.inv(at)
        wanted = {}
        for b in mine:
            if model.body_mass[b] <= 0:
                continue
            rot = data.ximat[b].reshape(3, 3)
            pose = np.eye(4)
            pose[:3, :3], pose[:3, 3] = rot, data.xipos[b]
            pose = shift @ pose
            tensor = np.diag(model.body_inertia[b])
            wanted[name[b]] = (pose[:3, 3], pose[:3, :3] @ tensor @ pose[:3, :3].T)
        return q, wanted

    welded = {
        name[b]: name.get(int(model.body_parentid[b]), "")
        for b in mine
        if model.body_jntnum[b] == 0 and b != top
    }
    return _compare_bodies(kit, bodies, joints, poses_fn, welded)


def table(rows: list[dict], title: str, command: str) -> str:
    """The corpus's table: one row per robot file, and the counts. A one-line refusal by the
    import (a scene of several robots, no articulation) is the original format's own import's
    answer too, and a file the converter does not convert has no USD: both are counted apart
    from the robots that do not come back equal."""
    building = any(r["step"] == "build" for r in rows)
    unbuilt = [r for r in rows if building and r["ok"] and r["step"] == "compare"]
    good = sum(r["ok"] for r in rows) - len(unbuilt)
    converted = [r for r in rows if r["step"] != "convert"]
    refused = [r for r in converted if r["step"] == "import" and _refusal(r["why"])]
    robots = len(converted) - len(refused)
    equal = sum(r["ok"] or r["step"] == "build" for r in rows)  # compared equal, then built

    def share(n: int) -> str:
        return f"{100.0 * n / robots:.1f} %" if robots else "-"

    said = f"of the other {robots}, {equal} give a robot equal to the original ({share(equal)})"
    if building:
        said += f" and {good} of those a checked kit (the build; {share(good)})"
    if unbuilt:
        said += f"; {len(unbuilt)} equal ones not built (the table merges an earlier comparison)"
    lines = [
        f"## {title}",
        "",
        f"`{command}`",
        "",
        f"{len(rows)} files: {len(rows) - len(converted)} not converted by the converter, "
        f"{len(refused)} refused in one line by the import (several robots, no articulation); "
        f"{said}.",
        "",
        "| file | result | step | first difference or error |",
        "|---|---|---|---|",
    ]
    for r in rows:
        said = "equal, not built" if r in unbuilt else "ok" if r["ok"] else "FAIL"
        said = "refused" if r in refused else said
        lines.append(f"| {r['file']} | {said} | {r['step']} | {r['why']} |")
    return "\n".join(lines) + "\n"


def _refusal(why: str) -> bool:
    return "several robots" in why or "no articulation" in why


def save(md: Path, title: str, body: str) -> None:
    """Put `body` in `md` under `## title`, replacing that section."""
    text = md.read_text() if md.exists() else "# Import corpora\n"
    pattern = re.compile(rf"^## {re.escape(title)}\n.*?(?=^## |\Z)", re.S | re.M)
    text = (
        pattern.sub(lambda _: body + "\n", text)
        if pattern.search(text)
        else text.rstrip("\n") + "\n\n" + body
    )
    md.write_text(text)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("corpus", type=Path)
    parser.add_argument("--mjcf", action="store_true", help="MJCF files, not URDF")
    parser.add_argument("--only", action="append", default=[])
    parser.add_argument("--exclude", action="append", default=[])
    parser.add_argument("--venv", default=str(VENV))
    parser.add_argument("--out", type=Path, default=Path("/tmp/simkit-usd-corpus"))
    parser.add_argument("--build", action="store_true", help="also build each spec")
    parser.add_argument(
        "--reuse", action="store_true", help="reuse the USD an earlier run converted"
    )
    parser.add_argument("--limit", type=int, default=0)
    parser.add_argument("--timeout", type=float, default=600.0)
    parser.add_argument("--title", default=None)
    parser.add_argument("--md", type=Path, default=None, help="write the table here")
    args = parser.parse_args()
    found = robots(args.corpus, args.mjcf, args.only, args.exclude)
    if args.limit:
        found = found[: args.limit]
    rows = []
    for path in found:
        row = one(path, args.corpus, args.out, args)
        print(
            f"{'ok  ' if row['ok'] else 'FAIL'} {row['step']:8} {row['file']} {row['why']}",
            flush=True,
        )
        rows.append(row)
    title = args.title or f"USD via NVIDIA's converters: {args.corpus.name}"
    body = table(rows, title, "python scripts/usd_corpus.py " + " ".join(sys.argv[1:]))
    print(body)
    if args.md:
        save(args.md, title, body)


if __name__ == "__main__":
    main()
