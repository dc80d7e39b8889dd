"""The fix-ups an import applies to its draft after translating the URDF, in order.

Each step reads the draft's resolved robot, changes the draft only where it must (the URDF's
zero pose is kept unless links collide, a servo cannot hold it, or a floating base needs a
place to stand), and gives each change one report line with its reason:

0. `rotors`: each driven joint's estimated rotor inertia (armature), bounded by what the
   joint moves (rotors.py).
1. `base`: a floating robot drawn Y-up is turned to stand on its limbs (upright.py).
2. `home`: out of self-contact: any joint between touching links may move for a fixed base
   (home.py), then to where the servos hold it against gravity (gravity.py); a floating
   robot keeps its feet and comes to rest on the floor (stance.py); pairs the search leaves
   touching that already touch at the source's home are excluded (overlap.py).
3. `stand`: the floating base placed on the floor (standing.py), or where it comes to rest
   leaning on its frame (settle.py); a legged robot bolted at its root is raised so that its
   feet reach the floor.
4. `limits`: estimated position limits narrowed to the range free of self-contact
   (limits.py).
"""

from __future__ import annotations

from simkit.importer.draft import Draft
from simkit.importer.fixups import gravity, overlap, settle, stance, standing, upright
from simkit.importer.fixups import home as clear
from simkit.importer.fixups import limits as ranges
from simkit.importer.fixups.rotors import armature

#: links above which the fix-ups that compile a MuJoCo model of the robot (home's contact
#: and gravity searches, the floating rest, limits narrowing) are skipped, one report line
#: each: MuJoCo's XML reader refuses bodies nested about 500 deep, its compiler a tree deeper
#: than 1024, and its compile time grows with the square of the depth (docs/performance.md)
SEARCH_LINKS = 400


def searched(draft: Draft, what: str) -> bool:
    """Whether the robot is small enough for the MuJoCo searches (`SEARCH_LINKS`); if not,
    report that `what` is skipped."""
    links = len(draft.spec["links"])
    if links <= SEARCH_LINKS:
        return True
    draft.note(
        f"{what} skipped: {links} links, more than the {SEARCH_LINKS} the MuJoCo searches "
        "take (importer/fixups/steps.py SEARCH_LINKS)",
    )
    return False


def base(draft: Draft) -> None:
    """A Y-up floating robot lies on its side at the identity: turn its base."""
    if not draft.floating:
        return
    turned = upright.upright(draft.robot(), draft.source_noun)
    if turned is not None:
        draft.estimate_base(("rpy",), rpy=[float(f"{v:.6g}") for v in turned[0]])
        draft.note(turned[1])


def home(draft: Draft) -> None:
    """`home` out of self-contact; for a fixed base, also held against gravity."""
    if not searched(draft, "home out of self-contact and held against gravity"):
        return
    first = list((draft.spec.get("poses") or {}).get("home", []))
    _search_home(draft)
    if first:
        overlap.exclude(draft, first)


def _search_home(draft: Draft) -> None:
    """home.py's or stance.py's search, then the servos that hold it."""
    if draft.floating:  # stance.py: out of self-contact with the feet kept
        why = (
            "at the first guess (0, or mid-range outside the limits) links collide or the "
            "robot cannot rest on the floor"
        )
        draft.set_home(stance.free_home(draft.robot(), draft.stage), why)
        return
    why = "the links collide at the first guess (0, or mid-range outside the limits)"
    if draft.legged:  # bolted at the pelvis: the legs hang as they are, the arms move
        found = _bolted_home(draft) if clear.in_contact(draft.robot(), draft.stage) else None
    else:
        found = clear.free_home(draft.robot(), draft.stage)
        if found is None and clear.in_contact(draft.robot(), draft.stage):
            found = _bolted_home(draft)
    draft.set_home(found, why)
    held = gravity.held_home(draft.robot(), draft.stage)
    if held is not None:
        draft.set_home(held[:2], held[2])
    _servos_that_hold(draft)


def _servos_that_hold(draft: Draft) -> None:
    """A joint whose servo still cannot hold home against gravity gets an estimated one that
    does (gravity.underpowered), one report line each at the joint."""
    for name, load, effort, estimate in gravity.underpowered(draft.robot()):
        joint = next(j for j in draft.spec["joints"] if j["name"] == name)
        joint["effort_peak"] = float(f"{estimate:.3g}")
        joint["estimated"] = sorted({*joint.get("estimated", []), "effort_peak"})
        old = next((k for k, v in draft.renames.get("joints", {}).items() if v == name), name)
        draft.note(
            f"effort {effort:g} cannot hold home against gravity (its static load {load:.3g} "
            f"is {100 * load / effort:.0f} % of it; at most {100 * gravity.LIMIT:.0f} % holds): "
            f"{joint['effort_peak']:g}, twice the load (an estimated servo)",
            draft.where("joint", old),
        )
        draft.changed()


def _bolted_home(draft: Draft) -> tuple[list[float], list[str]] | None:
    """Where one joint at a time cannot part the links (a humanoid bolted at the pelvis, its
    hands inside its thighs): the stance search with the legs kept as they hang (stance.py),
    then home.py's clearance search from there; the changes from the first guess."""
    found = stance.free_home(draft.robot(), draft.stage, rest=False)
    if found is None:
        return None
    first = list(draft.spec["poses"]["home"])
    draft.spec["poses"]["home"] = found[0]
    draft.changed()
    pose = found[0]
    for every in (False, True):  # then pairs the search took for always touching (the kit
        polished = clear.free_home(draft.robot(), draft.stage, every)  # samples more)
        if polished is not None:
            pose = draft.spec["poses"]["home"] = polished[0]
            draft.changed()
    draft.spec["poses"]["home"] = first
    draft.changed()
    names = [j["name"] for j in draft.movable()]
    moved = zip(names, first, pose, strict=True)
    changes = [f"{n}: {a:.4g} -> {b:.4g}" for n, a, b in moved if a != b]
    return (pose, changes) if changes else None


def stand(draft: Draft) -> None:
    """Raise a floating base so that the robot stands on the floor at home, then start it
    where it comes to rest when it tips onto its frame (a flying arm)."""
    if not draft.floating and not draft.legged:
        return
    height = standing.standing_height(draft.robot(), draft.stage)
    if height is None:
        return
    if not draft.floating:  # bolted at the pelvis: raised so that its feet reach the floor
        if height > 0.0:
            draft.estimate_base(("xyz",), xyz=[0.0, 0.0, float(f"{height:.6f}")])
            draft.note_change(
                f"fixed base bolted {height:.6f} m up: the legs' lowest point at home on the "
                "floor, as the robot stands",
            )
        return
    draft.estimate_base(("xyz",), xyz=[0.0, 0.0, float(f"{height:.6f}")])
    draft.note_change(
        f"floating base placed {height:.6f} m up: its lowest point at home on the floor",
    )
    _settle(draft)


def _settle(draft: Draft) -> None:
    """The free joint where the robot comes to rest at home when that is tilted onto its
    frame (settle.py), and the home its servos hold that rest with."""
    if not searched(draft, "the rest on the frame"):
        return
    found = settle.rest_pose(draft.robot(), draft.stage)
    if found is None:
        return
    pose, rest, why = found
    spec = draft.spec
    if pose != spec["poses"]["home"]:
        moved = ", ".join(
            f"{j['name']}: {a:.4g} -> {b:.4g}"
            for j, a, b in zip(draft.movable(), spec["poses"]["home"], pose, strict=True)
            if a != b
        )
        why = f"home: the rest with the least servo load; {moved} rad or m; " + why
        spec["poses"]["home"] = pose
    draft.estimate_base(
        ("xyz", "rpy"),
        xyz=[round(v, 4) + 0.0 for v in rest.xyz],
        rpy=[round(v, 4) + 0.0 for v in rest.rpy],
    )
    draft.note(why)


def limits(draft: Draft) -> None:
    """Estimated position limits narrowed to the joint's range free of self-contact from
    home (limits.py), one report line per joint."""
    if not searched(draft, "estimated limits narrowed to the range free of self-contact"):
        return
    found = ranges.narrowed(draft.robot(), draft.stage)
    if not found:
        return
    for joint in draft.spec["joints"]:
        if joint["name"] in found:
            old = (joint["lower"], joint["upper"])
            joint["lower"], joint["upper"] = found[joint["name"]]
            draft.note(
                f"estimated limits {old[0]:.4g} .. {old[1]:.4g} narrowed to "
                f"{joint['lower']:.4g} .. {joint['upper']:.4g}, the range the joint turns "
                "from home without self-contact",
                draft.where("joint", joint["name"]),
            )
    draft.changed()


def rotors(draft: Draft) -> None:
    """Estimated armature per driven joint (rotors.armature)."""
    armature(draft)


#: the fix-ups, in the order they run
STEPS = (rotors, base, home, stand, limits)
