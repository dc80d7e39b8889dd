"""The GPU scene's cap on explicit pairs (issue 42, class 9): over the cap, the self pairs in
contact at a named pose stay, then those in contact in the most sampled configurations, and
one line says how many were cut; under it nothing changes."""

from __future__ import annotations

from simkit.derive.gpu_budget import capped_pairs

PAIRS = [["a", "b"], ["a", "c"], ["b", "d"], ["c", "d"]]
#: (depth, pairs in contact) per sampled configuration: (c, d) three times, (a, c) twice
CONTACTS = [
    (0.0, {("c", "d"), ("a", "c")}),
    (0.0, {("c", "d"), ("a", "c")}),
    (0.0, {("c", "d"), ("b", "d")}),
]


def test_over_the_cap_the_held_then_the_most_often_touching_pairs_stay():
    kept, note = capped_pairs(PAIRS, {("a", "b")}, CONTACTS, 3)
    assert kept == [["a", "b"], ["a", "c"], ["c", "d"]]
    assert note.startswith("self-collision cut to 3 of 4 pairs") and "\n" not in note


def test_pairs_held_at_a_named_pose_stay_even_past_the_cap():
    kept, _ = capped_pairs(PAIRS, {("a", "b"), ("b", "d")}, CONTACTS, -5)
    assert kept == [["a", "b"], ["b", "d"]]


def test_under_the_cap_nothing_changes():
    assert capped_pairs(PAIRS, set(), CONTACTS, 4) == (PAIRS, None)
