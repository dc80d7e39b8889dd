"""The kept source of an MJCF import: the model file as read, byte for byte
(`NAME.source.xml`), and every other file it read (includes, meshes, textures) as
`NAME.source.assets/SHA256.EXT`, their digests in the spec's `source` (`assets`: path
relative to the model's folder -> SHA-256). The source check (check/source_mjcf.py) lays
them out again and compiles them in MuJoCo, or reads them beside a given MODEL.xml.
"""

from __future__ import annotations

import hashlib
from pathlib import PurePosixPath

from simkit.errors import SpecError
from simkit.importer.fixups import collide, settle
from simkit.importer.read.mjcf import MjcfSource


def source_name(spec: dict) -> str:
    """The kept MJCF's file name, beside the spec."""
    return f"{spec['name']}.source.xml"


def keep(draft, source: MjcfSource) -> dict:
    """Write the kept files into the staging folder; the spec's `source` entry."""
    name = source_name(draft.spec)
    main = source.files[_main_key(source)]
    (draft.stage / name).write_bytes(main)
    assets: dict[str, str] = {}
    folder = draft.stage / f"{draft.spec['name']}.source.assets"
    for rel, data in sorted(source.files.items()):
        if rel == _main_key(source):
            continue
        digest = hashlib.sha256(data).hexdigest()
        assets[rel] = digest
        folder.mkdir(exist_ok=True)
        (folder / f"{digest}{PurePosixPath(rel).suffix.lower()}").write_bytes(data)
    entry = {"file": name, "sha256": hashlib.sha256(main).hexdigest()}
    if assets:
        entry["assets"] = assets
    return entry


def _main_key(source: MjcfSource) -> str:
    return source.path.name


#: m the base may sink while the kit's servos hold home (check/legged.py's drift tolerance)
DRIFT = 0.02


def refuse_falling(draft, source: MjcfSource) -> None:
    """One line when a floating MJCF robot does not stand on the kit's servos: its base,
    started on the floor at home, sinks more than `DRIFT` in the import's settle run
    (fixups/settle.py: its collision geometry, real masses, servos as the kit's). An RL
    model made to fall (a humanoid on round feet) would fail the kit's standing check. The
    line names the construct: a free base that needs active balance (and, where the MJCF
    drives its joints by torque `<motor>`s, says so), at the free joint's line."""
    if not draft.floating:
        return
    robot = draft.robot()
    start, follow = collide.posed(robot)
    if start is None:
        return
    settler = settle.Settler(robot, draft.stage, start, follow)
    height, rest = settler.height(start), settler.run(start)
    if height - rest.xyz[2] > DRIFT:
        model = source.model
        free = [j for j in range(model.njnt) if model.jnt_type[j] == 0]
        motors = any(
            model.actuator_gaintype[a] == 0 and model.actuator_biastype[a] == 0
            for a in range(model.nu)
        )
        why = "torque <motor>s drive its joints; " if motors else ""
        raise SpecError(
            str(source.path), source.lines.get(("jnt", free[0])) if free else None, "freejoint",
            f"a free base that needs active balance: on a kit's position servos at home it "
            f"sinks {height - rest.xyz[2]:.2f} m in {settle.SECONDS:g} s ({why}a kit carries "
            "no balance controller)",
        )  # fmt: skip
