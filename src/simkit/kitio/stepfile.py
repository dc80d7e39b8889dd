"""ISO 10303-21 text helpers: split the DATA section into entities and put the presentation
(colour) section into a canonical order.

Open CASCADE writes the geometry in a stable order, but it walks its colour styles through a
hash map keyed by memory addresses, so the STYLED_ITEM ... COLOUR_RGB tail comes out in a
different order from one run to the next. `canonical_tail` renumbers that tail by content
(a Merkle key per entity), which makes rebuilds byte-identical without changing meaning.
`canonical` also renumbers the assembly occurrences, whose ids come from a process counter.
"""

from __future__ import annotations

import hashlib
import re

ENTITY = re.compile(r"^#(\d+) = ", re.MULTILINE)
REF = re.compile(r"#(\d+)")
#: Entity types that start the presentation section OCCT writes after the geometry.
TAIL_START = ("MECHANICAL_DESIGN_GEOMETRIC_PRESENTATION_REPRESENTATION(", "STYLED_ITEM(")


def split(text: str) -> tuple[str, list[tuple[int, str]], str]:
    """(text before the first entity, [(id, body)], text after the last entity's `;`)."""
    start = text.index("DATA;") + len("DATA;\n")
    end = text.index("ENDSEC;", start)
    pieces = ENTITY.split(text[start:end])  # [before, id, body, id, body, ...], in C
    entities = [(int(pieces[i]), pieces[i + 1]) for i in range(1, len(pieces), 2)]
    return text[:start], entities, text[end:]


def entity_types(text: str) -> dict[int, str]:
    """Entity id -> type name (`PRODUCT`, `MANIFOLD_SOLID_BREP`, ...; '' for complex ones)."""
    _, entities, _ = split(text)
    return {eid: body.split("(", 1)[0].strip() for eid, body in entities}


def _keys(bodies: dict[int, str], tail: set[int]) -> dict[int, str]:
    """A content key per tail entity: its text with tail references replaced by their keys."""
    keys: dict[int, str] = {}
    for root in sorted(tail):
        stack = [root]
        while stack:
            eid = stack[-1]
            if eid in keys:
                stack.pop()
                continue
            todo = [r for r in map(int, REF.findall(bodies[eid])) if r in tail and r not in keys]
            if todo:
                stack.extend(todo)
                continue
            text = REF.sub(
                lambda m: keys[int(m.group(1))] if int(m.group(1)) in tail else m.group(0),
                bodies[eid],
            )
            keys[eid] = "@" + hashlib.sha256(text.encode()).hexdigest()[:16]
            stack.pop()
    return keys


NAUO = re.compile(r"NEXT_ASSEMBLY_USAGE_OCCURRENCE\('\d+'")


def canonical(text: str) -> str:
    """`text` with the colour tail in content order and the assembly occurrences numbered
    1, 2, ... in file order (OCCT numbers them from a counter that lives as long as the
    process, so a second export in one process would differ)."""
    count = iter(range(1, 1 << 30))
    text = NAUO.sub(lambda _m: f"NEXT_ASSEMBLY_USAGE_OCCURRENCE('{next(count)}'", text)
    return canonical_tail(text)


def canonical_tail(text: str) -> str:
    """`text` with the presentation tail renumbered in content order (see module doc)."""
    head, entities, foot = split(text)
    first = next((i for i, (_, body) in enumerate(entities) if body.startswith(TAIL_START)), None)
    if first is None:
        return text
    bodies = dict(entities)
    tail_ids = [eid for eid, _ in entities[first:]]
    tail = set(tail_ids)
    keys = _keys(bodies, tail)
    referenced = {int(r) for eid in tail_ids for r in REF.findall(bodies[eid])}
    roots = sorted((eid for eid in tail_ids if eid not in referenced), key=lambda e: keys[e])
    order: list[int] = []
    seen: set[int] = set()
    for root in roots:
        stack = [root]
        while stack:
            eid = stack.pop()
            if eid in seen:
                continue
            seen.add(eid)
            order.append(eid)
            children = [r for r in map(int, REF.findall(bodies[eid])) if r in tail]
            stack.extend(reversed(children))
    order += [eid for eid in tail_ids if eid not in seen]  # cycles: keep the written order
    renumber = {old: new for new, old in zip(sorted(tail_ids), order, strict=True)}

    def ref(match: re.Match) -> str:
        eid = int(match.group(1))
        return f"#{renumber.get(eid, eid)}"

    geometry = entities[:first]
    if tail.isdisjoint(map(int, REF.findall("".join(body for _, body in geometry)))):
        out = [f"#{eid} = {body}" for eid, body in geometry]  # the usual case: as written
    else:
        out = [f"#{eid} = {REF.sub(ref, body)}" for eid, body in geometry]
    moved = {renumber[eid]: REF.sub(ref, bodies[eid]) for eid in tail_ids}
    out += [f"#{eid} = {moved[eid]}" for eid in sorted(moved)]
    return head + "".join(out) + foot
