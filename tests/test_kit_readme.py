"""Every Python snippet in a built kit's README runs, from inside the kit, without error."""

from __future__ import annotations

import re
import subprocess
import sys

import pytest

BLOCK = re.compile(r"```python\n(.*?)```", re.S)
#: the training frameworks' section: its snippets need simkit[train] (tests/test_training_readme.py)
TRAINING = re.compile(r"^## Training.*?(?=^## |\Z)", re.S | re.M)


@pytest.mark.parametrize("name", ["rosie_600", "rosie_1000", "rosie_1400", "asimov", "ecn_2r"])
def test_readme_python_snippets_run_inside_the_kit(kit_factory, name):
    kit = kit_factory(name).kit_dir
    blocks = BLOCK.findall(TRAINING.sub("", (kit / "README.md").read_text()))
    assert len(blocks) >= 2, "the README should carry the quickstart snippets"
    for code in blocks:
        proc = subprocess.run(
            [sys.executable, "-c", code], cwd=kit, capture_output=True, text=True, timeout=300
        )
        assert proc.returncode == 0, f"snippet failed:\n{code}\n{proc.stderr[-2000:]}"
        assert proc.stdout.strip(), f"snippet printed nothing:\n{code}"
