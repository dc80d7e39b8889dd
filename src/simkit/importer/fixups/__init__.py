"""Fix-ups: the pose and mass steps an import applies to its draft after translating it.

Each step (steps.py, `STEPS` in order) reads only the draft: its spec and the robot resolved
from it (`Draft.robot()`), never the source document; it reports through the draft
(`Draft.note`, at the element `Draft.where` names). The searches measure the robot on
scratch MuJoCo models (scratch.py).
"""

from __future__ import annotations

from simkit.importer.fixups.steps import SEARCH_LINKS, STEPS

__all__ = ["SEARCH_LINKS", "STEPS"]
