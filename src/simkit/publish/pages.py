"""The site's HTML: `index.html` (the gallery) and `<asset_dir>/index.html` (one page per kit).

Every value comes from the index entry of the kit (registry.facts, sizes and hashes) and its
robot.json and README; every string is escaped (`html.escape`; JSON in a `<script>` element
with `<`, `>` and `&` as `\\u` escapes), so a robot named `<script>` shows as text. The page
skeletons are templates/site/*.html (`$name` placeholders); no timestamps, sorted input: the
same kits give the same bytes. Pages link only inside the site.
"""

from __future__ import annotations

import json
from html import escape
from string import Template

from simkit.kitio import fmt, layout
from simkit.kitio.resources import data_dir
from simkit.publish.markdown import section, to_html

#: the viewer's shared files, one copy per site (see site.py)
VIEWER = "viewer"


def _t(name: str) -> Template:
    return Template((data_dir("templates") / "site" / name).read_text())


def e(value) -> str:
    """Escaped text (None as an empty string)."""
    return "" if value is None else escape(str(value), quote=True)


def script_json(value) -> str:
    """JSON that is safe inside `<script type="application/json">`."""
    text = json.dumps(value, sort_keys=True, separators=(",", ":"))
    return text.replace("&", "\\u0026").replace("<", "\\u003c").replace(">", "\\u003e")


def size(n: int) -> str:
    """Bytes for people: 1.2 MB, 340 kB, 12 B (decimal units)."""
    for unit, scale in (("MB", 1e6), ("kB", 1e3)):
        if n >= scale:
            return f"{n / scale:.1f} {unit}"
    return f"{n} B"


def _num(value, unit: str = "") -> str:
    if isinstance(value, bool) or value is None:
        return e(value)
    if isinstance(value, int | float):
        return e(fmt.num(value) + (f" {unit}" if unit else ""))
    if isinstance(value, list) and all(isinstance(v, int | float) for v in value):
        return e("(" + ", ".join(fmt.num(v) for v in value) + ")" + (f" {unit}" if unit else ""))
    return e(value)


def _checks_line(kit: dict) -> str:
    checks = kit["checks"]
    passed = sum(g["passed"] for g in checks.values())
    total = sum(g["total"] for g in checks.values())
    return f"{passed} of {total} checks passed" if total else "not checked"


def gallery(index: dict) -> str:
    """index.html: one card per kit."""
    cards = []
    for kit in index["kits"]:
        folder = kit["folder"]
        picture = (
            f'<img src="{e(folder + kit["thumbnail"])}" alt="{e(kit["title"])}" '
            'width="256" height="256">'
            if kit.get("thumbnail")
            else ""
        )
        facts = [
            ("DoF", e(kit["dof"])),
            ("Mass", _num(kit.get("mass"), "kg")),
            ("Reach", _num(kit.get("reach"), "m")),
            ("Category", e(kit["category"])),
            ("Licence", e(kit.get("licence"))),
            ("Download", f'<a href="{e(kit["zip"]["path"])}">{e(size(kit["zip"]["size"]))}</a>'),
            ("Checks", e(_checks_line(kit))),
        ]
        rows = "".join(f"<dt>{k}</dt><dd>{v}</dd>" for k, v in facts if v)
        cards.append(
            f'<article class="card" data-kit="{e(kit["name"])}"><a href="{e(folder)}index.html">'
            f"{picture}<h2>{e(kit['title'])}</h2></a><dl>{rows}</dl></article>"
        )
    return _t("gallery.html").substitute(count=len(index["kits"]), cards="\n".join(cards))


def _table(head: list[str], rows: list[list[str]]) -> str:
    """A table of already-escaped cells."""
    th = "".join(f"<th>{h}</th>" for h in head)
    body = "".join("<tr>" + "".join(f"<td>{c}</td>" for c in row) + "</tr>" for row in rows)
    return f"<table><thead><tr>{th}</tr></thead><tbody>{body}</tbody></table>"


def _joints(doc: dict) -> str:
    rows = []
    for j in doc.get("joints", []):
        rows.append(
            [
                f"<code>{e(j['name'])}</code>",
                e(j.get("type")),
                e(j.get("parent")),
                e(j.get("child")),
                _num(j.get("axis")),
                _num(j.get("lower_deg")),
                _num(j.get("upper_deg")),
                _num(j.get("max_velocity_deg_s")),
                _num(j.get("effort_peak")),
                _num(j.get("effort_continuous")),
            ]
        )
    head = ["Joint", "Type", "Parent", "Child", "Axis", "Lower (deg)", "Upper (deg)"]
    head += ["Max speed (deg/s)", "Effort peak (N m)", "Effort continuous (N m)"]
    return _table(head, rows)


def _frames(doc: dict) -> str:
    rows = []
    for name, frame in sorted((doc.get("frames") or {}).items()):
        rows.append(
            [
                f"<code>{e(name)}</code>",
                e(frame.get("parent")),
                _num(frame.get("xyz"), "m"),
                _num(frame.get("rpy"), "rad"),
                e(frame.get("role")),
            ]
        )
    return _table(["Frame", "Parent", "Position", "Roll, pitch, yaw", "Note"], rows)


def _numbers(doc: dict) -> str:
    published = sorted((doc.get("published") or {}).items())
    rows = [[f"<code>{e(k)}</code>", _num(v)] for k, v in published]
    mass = doc.get("mass")
    if isinstance(mass, dict):
        rows += [[f"<code>mass.{e(k)}</code>", _num(v, "kg")] for k, v in sorted(mass.items())]
    return _table(["robot.json", "Value"], rows) if rows else "<p>none published</p>"


def _contents(kit: dict) -> str:
    """Top-level files and folders with sizes, and every file (URL, size, sha256)."""
    top = len(kit["top_folder"])
    groups: dict[str, list[dict]] = {}
    for f in kit["files"]:
        rel = f["path"][top:]
        groups.setdefault(rel.split("/")[0] + ("/" if "/" in rel else ""), []).append(f)
    rows = [
        [f"<code>{e(name)}</code>", e(len(files)), e(size(sum(f["size"] for f in files)))]
        for name, files in sorted(groups.items())
    ]
    every = [
        [
            f'<a href="{e(f["url"][len(kit["folder"]) :])}"><code>{e(f["path"][top:])}</code></a>',
            e(size(f["size"])),
            f'<code class="sha">{e(f["sha256"])}</code>',
        ]
        for f in kit["files"]
    ]
    return (
        _table(["In the kit", "Files", "Size"], rows)
        + f"<details><summary>Every file ({len(every)}), each at its own URL</summary>"
        + _table(["File", "Size", "sha256"], every)
        + "</details>"
    )


def _checks(kit: dict) -> str:
    rows = [
        [e(fmt_), e(f"{g['passed']} of {g['total']}"), e(", ".join(g["tools"]))]
        for fmt_, g in kit["checks"].items()
    ]
    return _table(["Format", "Passed", "Loaded by"], rows) if rows else "<p>not checked</p>"


def _pictures(kit: dict, pictures: dict[str, str]) -> str:
    if not pictures:
        return "<p>none</p>"
    figs = [
        f'<figure><img src="{e(url)}" alt="{e(pose)}"><figcaption>{e(pose)}</figcaption></figure>'
        for pose, url in pictures.items()  # robot.json's pose order
    ]
    return '<div class="pictures">' + "".join(figs) + "</div>"


def kit_page(kit: dict, doc: dict, readme: str, pictures: dict[str, str]) -> str:
    """`<asset_dir>/index.html` for one kit (`pictures`: pose -> URL relative to the page)."""
    zip_ = kit["zip"]
    viewer = {"base": "./", "files": [f["url"][len(kit["folder"]) :] for f in kit["files"]]}
    return _t("kit.html").substitute(
        title=e(kit["title"]),
        description=e(doc.get("description", "")),
        viewer="../" + VIEWER + "/",
        kit_json=script_json(viewer),
        zip_url=e("../" + zip_["path"]),
        zip_name=e(zip_["path"]),
        zip_size=e(size(zip_["size"])),
        zip_sha=e(zip_["sha256"]),
        top=e(kit["top_folder"]),
        facts=e(f"{kit['dof']} DoF, {kit['category']}, licence {kit.get('licence') or 'none'}"),
        contents=_contents(kit),
        conventions=to_html(section(readme, "Frames and conventions")),
        frames=_frames(doc),
        joints=_joints(doc),
        numbers=_numbers(doc),
        pictures=_pictures(kit, pictures),
        quickstart=to_html(section(readme, "Quickstart")),
        checks=_checks(kit),
        checks_line=e(_checks_line(kit)),
        readme=e(layout.README),
    )
