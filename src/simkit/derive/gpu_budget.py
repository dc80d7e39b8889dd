"""What a GPU scene may carry (issue 42, class 9): a cap on explicit pairs, and the line a kit
writes instead of a GPU scene where a robot cannot have one.

A 74-joint imported humanoid with 146 collision geoms had 1,489 self pairs in contact in some
sampled configuration. Its GPU scene asked for 5,956 contact slots and 23,898 constraint rows
a world: C MuJoCo could not allocate the file's arena, and no batch of thousands of worlds
holds that. Self-collision matters where the robot is held (the named poses) and where it
meets itself most often; the rest stays in the main MJCF, which collides every pair.
"""

from __future__ import annotations

from collections import Counter


def capped_pairs(
    pairs: list[list[str]], named: set, contacts: list[tuple[float, set]], room: int
) -> tuple[list[list[str]], str | None]:
    """At most `room` of `pairs` (sorted name pairs): every pair in `named` (in contact at a
    named pose), then the pairs in contact in the most sampled configurations of `contacts`
    ((depth, pairs) per configuration), ties by name. Returns (kept pairs, sorted; the line
    robot.json says, or None when nothing was cut)."""
    if len(pairs) <= room:
        return pairs, None
    seen = Counter(p for _, touching in contacts for p in touching)
    ranked = sorted(pairs, key=lambda p: (tuple(p) not in named, -seen[tuple(p)], p))
    kept = sorted(ranked[: max(room, 0, sum(1 for p in pairs if tuple(p) in named))])
    note = (
        f"self-collision cut to {len(kept)} of {len(pairs)} pairs in the GPU scene (those in "
        "contact at a named pose, then the most often in contact in the samples): the main "
        "MJCF collides them all"
    )
    return kept, note


def no_scene(reason: str) -> dict:
    """The plan of a kit without a GPU scene: one line saying why (robot.json `gpu_scene`,
    the README); the build goes on."""
    return {"none": f"no GPU scene: {reason}"}
