"""USD emitter: the robot as an Isaac Sim robot asset (UsdPhysics articulation, PhysX variant,
Isaac robot schema) for Isaac Sim, Isaac Lab, Newton and other USD consumers.

Files (Z up, metres, kilograms; each layer has a default prim; docs/usd.md):

- `usd/NAME/NAME.usda`: the Isaac Sim robot asset's interface layer (interface.py), in a
  folder named as the robot, as Isaac Sim's asset library lays robots out;
- `usd/NAME.usda`: the entry point users open, the same interface layer over the same
  payloads (only its payload paths differ), so kits before this layout open as they did;
- `usd/NAME/payloads/base.usda`: the hierarchy, `/NAME/LINK` Xforms at q = 0 (base.py);
- `usd/NAME/payloads/geometries.usd`, `instances.usda`, `materials.usda`: meshes, the links'
  visuals and colliders, the materials (geometry.py);
- `usd/NAME/payloads/physics.usda`, `physx.usda`, `mujoco.usda`: UsdPhysics, the PhysX and
  the MuJoCo additions (physics.py, physx.py, mujoco.py, robot_schema.py);
- `.thumbs/256x256/<layer>.png` beside both interface layers: the thumbnail (thumbnail.py).

Layers are built in memory and serialised with `Sdf.Layer.ExportToString`, so the text holds no
file names, timestamps or absolute paths; numbers are rounded as `fmt.num` prints them, so the
same model gives the same bytes.
"""

from __future__ import annotations

import posixpath

from simkit.emit.usd.base import base_text
from simkit.emit.usd.common import axis_frame, place, prim_name
from simkit.emit.usd.geometry import geometries_text, instances_text, materials_text
from simkit.emit.usd.interface import DEFAULT_VARIANT, VARIANT_SET, VARIANTS, interface_text
from simkit.emit.usd.mujoco import mujoco_text
from simkit.emit.usd.physics import physics_text
from simkit.emit.usd.physx import physx_text
from simkit.emit.usd.thumbnail import thumbnail_png
from simkit.errors import SimkitError
from simkit.kitio import layout
from simkit.kitio.kitread import MAX_ENTRY
from simkit.model.inertia import principal_axes
from simkit.model.robot import Robot

__all__ = [
    "DEFAULT_VARIANT",
    "FORMATS",
    "VARIANTS",
    "VARIANT_SET",
    "axis_frame",
    "emit",
    "emit_binary",
    "emitter",
    "layers",
    "place",
    "prim_name",
    "principal_axes",
    "stage_text",
]

FORMATS = ("usda", "usdc")
#: the meshes, in text (`.usd` reads both encodings), or a crate with `--usd-format usdc`
GEOMETRIES = "geometries.usd"
#: bytes: a geometry text longer than this is written as a crate (about a third of the text),
#: so a robot of many dense meshes stays under the kit's 64 MiB per-file cap
#: (kitio/kitread.py MAX_ENTRY) instead of failing its build; half the cap, so the choice
#: does not flip between two nearly equal builds near the cap
TEXT_GEOMETRY_MAX = MAX_ENTRY // 2


def layers(robot: Robot) -> dict[str, str]:
    """Payload file name -> `.usda` text."""
    return {
        "base.usda": base_text(robot),
        GEOMETRIES: geometries_text(robot),
        "instances.usda": instances_text(robot),
        "materials.usda": materials_text(robot),
        "physics.usda": physics_text(robot),
        "physx.usda": physx_text(robot),
        "mujoco.usda": mujoco_text(robot),
    }


def _usdc_bytes(text: str) -> bytes:
    """Binary crate bytes of a `.usda` text. pxr writes crate files only to disk, so this
    goes through a private temporary folder that is removed again."""
    import tempfile
    from pathlib import Path

    from pxr import Sdf

    layer = Sdf.Layer.CreateAnonymous(".usda")
    layer.ImportFromString(text)
    with tempfile.TemporaryDirectory(prefix="simkit-usdc-") as tmp:
        target = Path(tmp) / "stage.usdc"
        layer.Export(str(target))
        return target.read_bytes()


def emit(robot: Robot, binary: bool = False) -> dict[str, bytes]:
    """The entry layer `usd/NAME.usda` (or `.usdc` with `binary=True`), the Isaac asset's
    interface layer `usd/NAME/NAME.usda`, their payload layers and thumbnails."""
    files: dict[str, bytes] = {}
    thumbnail = thumbnail_png(robot)
    for path in (layout.usd(robot.name, binary), layout.usd_asset(robot.name, binary)):
        folder = posixpath.relpath(layout.usd_payload(robot.name, ""), posixpath.dirname(path))
        text = interface_text(robot, f"./{folder}")
        files[path] = _usdc_bytes(text) if binary else text.encode()
        files[layout.usd_thumbnail(path)] = thumbnail
    for name, text in layers(robot).items():
        crate = name == GEOMETRIES and (binary or len(text) > TEXT_GEOMETRY_MAX)
        files[layout.usd_payload(robot.name, name)] = _usdc_bytes(text) if crate else text.encode()
    return dict(sorted(files.items()))


def emit_binary(robot: Robot) -> dict[str, bytes]:
    """The same asset as `emit`, with the entry layer and the geometry in USD's binary crate
    format."""
    return emit(robot, binary=True)


def emitter(usd_format: str = "usda"):
    """The USD emitter for `usda` (text, the default) or `usdc` (binary)."""
    if usd_format not in FORMATS:
        raise SimkitError(f"unknown USD format '{usd_format}' (expected one of {FORMATS})")
    return emit if usd_format == "usda" else emit_binary


def stage_text(robot: Robot, variant: str = DEFAULT_VARIANT) -> str:
    """The composed stage in one `.usda` text (the variant's payloads flattened in): for
    tests and tools that want the whole robot in memory. Writes the files to a private
    temporary folder that is removed again."""
    import tempfile
    from pathlib import Path

    from pxr import Usd

    with tempfile.TemporaryDirectory(prefix="simkit-usd-") as tmp:
        for rel, data in emit(robot).items():
            target = Path(tmp) / rel
            target.parent.mkdir(parents=True, exist_ok=True)
            target.write_bytes(data)
        stage = Usd.Stage.Open(str(Path(tmp) / layout.usd(robot.name)))
        top = stage.GetDefaultPrim()
        top.GetVariantSet(VARIANT_SET).SetVariantSelection(variant)
        return stage.Flatten().ExportToString()
