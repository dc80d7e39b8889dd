"""An MJCF's contact excludes (`<contact><exclude body1 body2>`) carried into the spec.

The source's authors let such pairs overlap (a thumb's base inside the palm), so a kit that
collided them would fail its own contact checks and hold the robot apart where the source
does not. The spec's `contact_excludes` carries them, and every kit format that can filter a
pair gets them (MJCF `<exclude>`, USD filtered pairs, SRDF `User` pairs). Names are the
kit's (after names.make_legal). A pair joined by a joint in the kit is excluded there
already (MuJoCo's parent filter in the source); a pair whose body is no kit link (outside
the robot's tree) is listed in `source_differences` with its reason.
"""

from __future__ import annotations

from simkit.importer.formats.mjcf.reader import MjcfSource
from simkit.importer.formats.mjcf.tree import name_of


def carry(spec: dict, source: MjcfSource, renames: dict) -> list[tuple[str, str]]:
    """Set `spec["contact_excludes"]` (sorted pairs of link names) from the compiled
    model's excludes; returns (what, reason) of each one the kit cannot carry."""
    model = source.model
    links = {link["name"] for link in spec["links"]}
    jointed = {frozenset((j["parent"], j["child"])) for j in spec["joints"]}
    renamed = renames.get("links", {})
    pairs: set[tuple[str, str]] = set()
    listed = []
    for e in range(int(model.nexclude)):
        sig = int(model.exclude_signature[e])
        names = [name_of(model, "body", i) for i in (sig >> 16, sig & 0xFFFF)]
        a, b = sorted(renamed.get(n, n) for n in names)
        if frozenset((a, b)) in jointed:
            continue  # the kit excludes links joined by a joint itself
        if a in links and b in links and a != b:
            pairs.add((a, b))
        else:
            why = "a body of the pair is no link of the kit's robot"
            listed.append((f"contact_excludes.{name_of(model, 'exclude', e)}", why))
    if pairs:
        spec["contact_excludes"] = [list(p) for p in sorted(pairs)]
    return listed
