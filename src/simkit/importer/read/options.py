"""What a user allows the importer's reader to do (`simkit import` flags; issue 24).

Downloaded URDFs and xacros are untrusted: by default the reader reads no environment
variable, no file outside the robot's package folders, and evaluates xacro expressions with
a restricted evaluator (importer/read/safe_eval.py). Each permission is given by name.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

from simkit.errors import SpecError


@dataclass(frozen=True)
class ReadOptions:
    """`xacro_args`: (NAME, VALUE) for `$(arg NAME)` in .xacro and .urdf alike;
    `allow_env`: environment variables `$(env)`/`$(optenv)` may read; `allow_read`: folders
    outside the package root that meshes, includes and load_yaml may read; `trust_xacro`:
    full xacro (its Python evaluator, the environment, any file) for a trusted file;
    `variant`: a USD stage's Physics variant."""

    xacro_args: tuple[tuple[str, str], ...] = ()
    allow_env: tuple[str, ...] = ()
    allow_read: tuple[Path, ...] = ()
    trust_xacro: bool = False
    #: a USD stage's `Physics` variant to read (`--variant`; None: the stage's default)
    variant: str | None = None

    def args(self) -> dict[str, str]:
        """`--xacro-arg` values by name (the last one given wins), and the `--variant`."""
        return dict(self.xacro_args) | ({"variant": self.variant} if self.variant else {})


def parse_xacro_arg(text: str) -> tuple[str, str]:
    """`NAME:=VALUE` (roslaunch's form) as (NAME, VALUE); SpecError otherwise."""
    name, sep, value = text.partition(":=")
    if not sep or not re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]*", name):
        raise SpecError("--xacro-arg", None, "--xacro-arg", f"'{text}' is not NAME:=VALUE")
    return name, value
