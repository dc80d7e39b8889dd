"""Load a kit's written MJCF and URDF in MuJoCo (shared by the simulate and check stages)."""

from __future__ import annotations

import re
import tempfile
from pathlib import Path


def load_mjcf_file(path: Path):
    """The MJCF at `path`, compiled (mesh paths relative to the file, as MuJoCo reads them)."""
    import mujoco

    return mujoco.MjModel.from_xml_path(str(path))


def load_urdf_file(urdf: Path):
    """Compile the URDF at `urdf` in MuJoCo (`load_urdf_text`)."""
    return load_urdf_text(urdf.read_text(encoding="utf-8"), urdf)


def load_urdf_text(text: str, urdf: Path):
    """Compile URDF `text` whose mesh paths are relative to the file `urdf`, keeping fixed
    frames as bodies (MuJoCo's URDF reader strips directories unless told not to)."""
    import mujoco

    ext = '<mujoco><compiler strippath="false" fusestatic="false" discardvisual="true"/></mujoco>'
    text = re.sub(r"(<robot\b[^>]*>)", r"\1" + ext, text, count=1)
    # mesh paths made absolute, so the copy can live outside the kit (which may be read-only)
    text = re.sub(
        r'filename="([^"]+)"',
        lambda m: f'filename="{(urdf.parent / m.group(1)).resolve().as_posix()}"',
        text,
    )
    with tempfile.TemporaryDirectory(prefix="simkit-urdf-") as tmp:
        copy = Path(tmp) / urdf.name
        copy.write_text(text, encoding="utf-8")
        return mujoco.MjModel.from_xml_path(str(copy))
