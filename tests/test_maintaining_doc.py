"""docs/maintaining.md runs as written (issue 38): every command of its fenced `bash` blocks
and every `$ ` command of its `console` blocks, in order, in a temporary folder holding a copy
of robots/rosie_600.yaml; a console block's shown output must appear (`...` stands for any
text), and a command whose shown output is a `simkit: error:` must fail."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

import simkit

REPO = Path(__file__).resolve().parents[1]
DOC = REPO / "docs" / "maintaining.md"
BLOCK = re.compile(r"^```(bash|console)\n(.*?)^```", re.M | re.S)


def steps(text: str) -> list[tuple[str, list[str]]]:
    """(command, output lines shown for it) in the doc's order."""
    out: list[tuple[str, list[str]]] = []
    for kind, body in BLOCK.findall(text):
        for line in body.splitlines():
            if kind == "bash" and line.strip() and not line.lstrip().startswith("#"):
                out.append((line, []))
            elif kind == "console" and line.startswith("$ "):
                out.append((line[2:], []))
            elif kind == "console" and line.strip():
                out[-1][1].append(line)
    return out


def _shown(line: str) -> re.Pattern:
    return re.compile(".*".join(re.escape(part) for part in line.split("...")))


def test_the_doc_covers_the_whole_loop():
    commands = [command for command, _ in steps(DOC.read_text())]
    for needed in ("--accept-published", "simkit diff ", "simkit publish ", "sed -i "):
        assert any(needed in command for command in commands), needed
    assert not any(re.search(r"\brobots/\S+\.yaml\b", c) and "cp " not in c for c in commands)


@pytest.mark.slow
def test_every_command_runs_as_shown(tmp_path):
    (tmp_path / "robots").mkdir()
    spec = (REPO / "robots" / "rosie_600.yaml").read_text()
    (tmp_path / "robots" / "rosie_600.yaml").write_text(spec)
    bin_dir = tmp_path / "bin"
    bin_dir.mkdir()
    wrapper = bin_dir / "simkit"  # the simkit under test, whatever is installed
    wrapper.write_text(f'#!/bin/sh\nexec "{sys.executable}" -m simkit.cli "$@"\n')
    wrapper.chmod(0o755)
    env = {
        **os.environ,
        "PATH": f"{bin_dir}{os.pathsep}{os.environ.get('PATH', '')}",
        "PYTHONPATH": str(Path(simkit.__file__).resolve().parents[1]),
    }
    for command, shown in steps(DOC.read_text()):
        run = subprocess.run(
            command,
            shell=True,
            executable="/bin/bash",
            cwd=tmp_path,
            env=env,
            capture_output=True,
            text=True,
            timeout=900,
        )
        output = (run.stdout + run.stderr).splitlines()
        failing = any(line.startswith("simkit: error:") for line in shown)
        assert (run.returncode != 0) == failing, (command, run.returncode, run.stderr[-2000:])
        for line in shown:
            assert any(_shown(line).fullmatch(got.rstrip()) for got in output), (
                command,
                line,
                output[:40],
            )
    assert (tmp_path / "robots" / "rosie_600.yaml").read_text() == spec  # robots/ untouched
    assert (tmp_path / "site" / "index.json").is_file()
