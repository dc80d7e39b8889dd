"""A home pose the kit's servos can hold against gravity (fixed bases; after home.py).

A URDF's effort limits need not carry its arms everywhere: a two-armed robot's shoulder
needs 56 N m against 50 N m with the arm stretched out level at 0, and a mobile
manipulator's shoulder lifts need 52 N m against 30 N m (the real robots have counterbalance
springs the URDFs leave out). At such a home the kit's position servo (kp = effort per
0.01 rad, force limited to the effort) sags far past the hold check's few tenths of a
degree. A servo holds within about 0.57 deg x (load / effort), so every actuated joint's
static gravity load should stay within `LIMIT` of its effort (the kit page's 80 % rule).

The load is the spec's own: masses, CoMs and axes through simkit's Newton-Euler
(model/rnea.py); a mimic follower without a servo of its own passes its load to its leader
(multiplier x load, as the MJCF's equality holds it). Where some joint is over `LIMIT`, the
joints over `AIM` and every non-mimic joint they carry move one at a time to the grid value
that lowers the summed excess over `AIM` most (the arm hangs, or folds), nearest the current
value on a tie, never at a limit, never bringing two links closer than the clearance (or
than at home, where they are closer there) on home.py's model with the visual pieces the
kit's collision covers (collide.covered_shapes). Where no such move is free, one other joint, above
them or below, may move too (a torso lift rises so a lowered arm clears the base).

Where no pose the search finds holds (a vertical lift carrying its load wherever it stands,
an effort far below what the arm weighs), the servo is estimated instead (`underpowered`):
a joint still over `LIMIT` at the home kept gets twice its static load as its effort, marked
estimated and reported on one line, so that the kit's hold checks agree with the report
(issue 32, class 6c). A URDF's effort that holds its home is never changed.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from simkit.importer.fixups import collide
from simkit.importer.fixups.scratch import compiled
from simkit.model.rnea import Tree

#: share of a joint's effort its static gravity load may take at home (kit page: 80 % rule)
LIMIT = 0.8
#: share the search aims below, so the held pose has margin (servo sag ~0.29 deg at 0.5)
AIM = 0.5
GRID = 24  # range divisions tried per joint
SWEEPS = 3  # moves per joint at most
ROOM = 4  # the best moves that may also move a joint above them, when none is free alone
GAIN = 0.005  # the least cost a move must save (no turns for a wrist roll's 0.1 %)
#: m: how much deeper a pair of pieces overlapping at the start may go (the hull of a visual
#: piece is coarse where it overlaps its neighbour already: an elbow's hulls went 0.1 mm
#: deeper as the elbow folds, while the kit's pieces, which follow the mesh, stay apart)
SLACK = 0.001


def _loads(robot, tree, q: np.ndarray) -> tuple[np.ndarray, list[int]]:
    """(|gravity load| / effort per actuated joint, their indices in spec order) at `q`;
    a servo-less mimic follower's load goes to its leader (times its multiplier)."""
    movable = robot.movable_joints
    index = {j.name: i for i, j in enumerate(movable)}
    tau = tree.rnea(q, np.zeros(len(q)), np.zeros(len(q)), True)
    held = tau.copy()
    for j in movable:
        if j.mimic is not None and not j.actuated and j.mimic[0] in index:
            held[index[j.mimic[0]]] += j.mimic[1] * tau[index[j.name]]
    acting = [i for i, j in enumerate(movable) if j.actuated and j.effort_peak]
    effort = np.array([movable[i].effort_peak for i in acting])
    return np.abs(held[acting]) / effort, acting


def _cost(ratios: np.ndarray) -> float:
    """The summed load share over `AIM` (0 when every joint is within it)."""
    return float(np.clip(ratios - AIM, 0.0, None).sum())


def _carried(robot, names: set[str]) -> list:
    """The joints named and every movable non-mimic joint below them, in spec order."""
    below, moved = set(names), {robot.joint(n).child for n in names}
    for joint in robot.joints:  # tree order: a parent's joint comes first
        if joint.parent in moved:
            below.add(joint.name)
            moved.add(joint.child)
    return [j for j in robot.movable_joints if j.name in below and j.mimic is None]


def _above(robot, names: set[str]) -> list:
    """The movable non-mimic joints that carry the joints named (not those), distal first."""
    parent = {j.child: j for j in robot.joints}
    out: dict[str, object] = {}
    for name in sorted(names):
        node = robot.joint(name).parent
        while node in parent:
            joint = parent[node]
            if joint.movable and joint.mimic is None and joint.name not in names:
                out.setdefault(joint.name, joint)
            node = joint.parent
    return list(out.values())


def _grid(joint, now: float) -> np.ndarray:
    """Values tried for one joint: its range in `GRID` steps, ends left out, nearest first."""
    lo, hi = (joint.lower, joint.upper) if joint.lower is not None else (-np.pi, np.pi)
    grid = np.linspace(lo, hi, GRID + 1)[1:-1]
    return np.array(sorted(grid, key=lambda v: abs(v - now)))


class Search:
    """The pose being searched: loads (Newton-Euler) and self-contact (MuJoCo) of trials."""

    def __init__(self, robot, base_dir: Path) -> None:
        self.robot = robot
        self.start, self.follow = collide.posed(robot)
        self.movable = self.robot.movable_joints
        self.index = {j.name: i for i, j in enumerate(self.movable)}
        self.tree = Tree.of(self.robot) if self.start is not None else None
        self.spec_dir = base_dir

    def open(self) -> None:
        """The collision model (collide.py's, with the visual pieces: covered_shapes) and the
        closest distance (m) of each pair of links near each other at the start."""
        always = collide.always_touching(self.robot, self.spec_dir, self.start, self.follow)
        xml = collide.model_xml(self.robot, self.spec_dir, always, shapes_of=collide.covered_shapes)
        self.model, self.data, self.adr = compiled(xml, self.movable)
        self.near = self._closest(self.start)

    def _closest(self, q: np.ndarray) -> dict[tuple[int, int], float]:
        """The smallest distance (m) per pair of geoms closer than the clearance at `q` (per
        geom, not per link: a link's visual piece overlapping at home must not let its
        collision piece sink in)."""
        collide.penetration(self.model, self.data, self.adr, q)
        out: dict[tuple[int, int], float] = {}
        for contact in self.data.contact[: self.data.ncon]:
            pair = (int(contact.geom[0]), int(contact.geom[1]))
            out[pair] = min(out.get(pair, np.inf), float(contact.dist))
        return out

    def free(self, q: np.ndarray) -> bool:
        """No pair of geoms closer than the clearance, or than at the start where they were
        closer already (the kit's collision pieces are not the search's), less `SLACK` for a
        pair overlapping there."""
        return all(self.allowed(pair, dist) for pair, dist in self._closest(q).items())

    def allowed(self, pair: tuple[int, int], dist: float) -> bool:
        near = self.near.get(pair, np.inf)
        return dist >= min(collide.CLEARANCE, near) - (SLACK if near < 0.0 else 1e-6)

    def loads(self, q: np.ndarray) -> np.ndarray:
        return _loads(self.robot, self.tree, q)[0]

    def cost(self, q: np.ndarray) -> float:
        return _cost(self.loads(q))

    def moved(self, q: np.ndarray, joint, value: float) -> np.ndarray | None:
        """`q` with `joint` at `value`, mimic joints following; None outside any limit."""
        trial = self.follow(np.where(np.arange(len(q)) == self.index[joint.name], value, q))
        return trial if collide.within_limits(self.movable, trial) else None

    def better(self, q: np.ndarray, best: float, joints: list) -> list[np.ndarray]:
        """Every one-joint move of `joints` with less cost than `best`: least cost first,
        then the smallest move."""
        found = []
        for joint in joints:
            for value in _grid(joint, q[self.index[joint.name]]):
                trial = self.moved(q, joint, value)
                if trial is not None and (cost := self.cost(trial)) < best - GAIN:
                    found.append((cost, float(np.abs(trial - q).sum()), trial))
        found.sort(key=lambda f: f[:2])
        return [t for _, _, t in found]

    def room(self, trial: np.ndarray, lift: list, best: float) -> np.ndarray | None:
        """`trial` with one joint of `lift` moved (nearest value first) so
        that it is free and still below `best`: a torso raised so a lowered arm clears the
        base. None when no such move exists."""
        for joint in lift:
            for value in _grid(joint, trial[self.index[joint.name]]):
                out = self.moved(trial, joint, value)
                if out is not None and self.cost(out) < best - GAIN and self.free(out):
                    return out
        return None


def held_home(robot, base_dir: Path) -> tuple[list[float], list[str], str] | None:
    """(home, changes `joint: a -> b`, why) when some joint's gravity load at the spec's home
    is over `LIMIT` of its effort and a pose with less excess and no more self-contact was
    found; None otherwise."""
    search = Search(robot, base_dir)
    start = search.start
    if start is None:
        return None
    ratios = search.loads(start)
    if not len(ratios) or ratios.max() <= LIMIT:
        return None
    search.open()
    acting = _loads(search.robot, search.tree, start)[1]
    q, best = start.copy(), _cost(ratios)
    for _ in range(SWEEPS * len(search.movable)):
        over = {search.movable[acting[k]].name for k in np.flatnonzero(search.loads(q) > AIM)}
        carried = _carried(search.robot, over)
        lift = _above(search.robot, over) + carried
        found = search.better(q, best, carried)
        move = next((t for t in found if search.free(t)), None)
        for trial in found[:ROOM] if move is None else ():
            if (move := search.room(trial, lift, best)) is not None:
                break
        if move is None:
            break
        q, best = move, search.cost(move)
        if best == 0.0:
            break
    if np.array_equal(q, start):
        return None
    return _result(search, start, q, ratios, acting)


def _result(search, start, q, ratios, acting) -> tuple[list[float], list[str], str]:
    """The found home rounded as the spec writes it, its changes and the report's reason."""
    worst = int(np.argmax(ratios))
    why = (
        f"the servos cannot hold it against gravity ({search.movable[acting[worst]].name} "
        f"carries {100 * ratios[worst]:.0f} % of its effort, the spec's masses through "
        f"Newton-Euler; at most {100 * LIMIT:.0f} % holds); the highest share is "
        f"{100 * search.loads(q).max():.0f} % after"
    )
    changes = [
        f"{j.name}: {start[i]:.4g} -> {q[i]:.4g}"
        for i, j in enumerate(search.movable)
        if abs(q[i] - start[i]) > 1e-12
    ]
    return [float(f"{v:.6g}") for v in q], changes, why


def underpowered(robot) -> list[tuple[str, float, float, float]]:
    """(joint, static gravity load N m or N, its effort, the estimated effort) of each
    actuated joint whose load at the spec's home is over `LIMIT` of its effort; the estimate
    is the load over `AIM` (twice the load), rounded up to three significant digits."""
    start = collide.posed(robot)[0]
    if start is None:
        return []
    ratios, acting = _loads(robot, Tree.of(robot), start)
    out = []
    for ratio, i in zip(ratios, acting, strict=True):
        if ratio > LIMIT:
            joint = robot.movable_joints[i]
            load = float(ratio * joint.effort_peak)
            step = 10.0 ** (math.floor(math.log10(load / AIM)) - 2)  # three digits, rounded up
            out.append(
                (joint.name, load, float(joint.effort_peak), math.ceil(load / AIM / step) * step)
            )
    return out
