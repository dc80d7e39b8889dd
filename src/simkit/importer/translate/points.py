"""Contact points: a URDF `<collision>` sphere of radius 0 (the "minimal contact" idiom,
four at each corner of a foot) is a point the robot touches the world with. A spec has no
point contact and MuJoCo no zero-size geom, so each becomes a small collision sphere centred
on the point, its radius estimated from the link's points (issue 42, class 1)."""

from __future__ import annotations

import itertools
import math

from simkit.importer.diagnostics import Report
from simkit.importer.read.model import At
from simkit.importer.read.source import Source

#: the radius is this fraction of the largest distance between the link's contact points
#: (a foot's diagonal): 0.2 m of foot gives 10 mm, small beside the foot, large enough for
#: a stable contact at the kit's 2 ms step
SPAN_FRACTION = 0.05
#: m: the smallest radius (a link with one point, or points closer than 0.1 m); five times
#: the spec's 1 mm minimum primitive size (translate/geometry.py MIN_SIZE)
FLOOR = 5e-3


def is_point(shape: dict) -> bool:
    """A spec primitive read from a zero-radius sphere (radius 0, see geometry.shape_of)."""
    return shape.get("shape") == "sphere" and shape.get("radius") == 0.0


def radius_of(points: list[dict]) -> tuple[float, float]:
    """(radius m, span m) for one link's contact points: SPAN_FRACTION x the largest
    distance between two of them (link frame), at least FLOOR."""
    where = [tuple(p.get("xyz", (0.0, 0.0, 0.0))) for p in points]
    span = max((math.dist(a, b) for a, b in itertools.combinations(where, 2)), default=0.0)
    return max(FLOOR, round(SPAN_FRACTION * span, 6)), span


def grown(source: Source, link: At, collisions: list[dict], report: Report) -> bool:
    """Give the link's contact points their radius in place, with one report line at `link`
    (where the link is in the source); True if there were any (the link's
    `collision_primitives` is then estimated)."""
    points = [c for c in collisions if is_point(c)]
    if not points:
        return False
    radius, span = radius_of(points)
    for point in points:
        point["radius"] = radius
    report.estimated(
        source,
        link,
        f"{len(points)} zero-radius collision sphere(s), contact points: spheres of radius "
        f"{radius:g} m centred on them ({SPAN_FRACTION:g} x the {span:.3g} m between the "
        f"link's points, at least {FLOOR:g} m)",
    )
    return True
