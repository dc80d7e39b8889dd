"""Help texts name every format a command takes (issue 38): `simkit import --help`, `simkit
check --help` and README's command table name URDF, xacro, MJCF, SDFormat and USD, not "a
URDF" alone."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from click.testing import CliRunner

from simkit.cli import main

README = Path(__file__).resolve().parents[1] / "README.md"
FORMATS = ("URDF", "xacro", "MJCF", "SDF", "USD")  # "SDF" also matches "SDFormat"


@pytest.mark.parametrize("command", ["import", "check"])
def test_the_help_names_every_format_the_command_takes(command):
    result = CliRunner().invoke(main, [command, "--help"])
    assert result.exit_code == 0, result.output
    text = " ".join(result.output.split())  # click wraps lines
    for name in FORMATS:
        assert re.search(rf"\b{name}", text, re.IGNORECASE), (command, name, text)
    if command == "check":  # the option itself, not only the command's summary
        option = text[text.index("--source FILE") :]
        assert all(name.lower() in option.lower() for name in FORMATS), option


@pytest.mark.parametrize("command", ["import", "check"])
def test_readmes_command_table_names_every_format(command):
    (row,) = [
        line for line in README.read_text().splitlines() if line.startswith(f"| `simkit {command} ")
    ]
    head = row[: row.index("` |")]  # the usage cell: `simkit check KIT [-v] [--source ...]`
    for name in FORMATS:
        assert name.upper() in head.upper(), (command, name, head)
