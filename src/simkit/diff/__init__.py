"""`simkit diff OLD NEW`: what changed between two kits, for a pull request review.

One module per concern: `kit` reads the two kits, `walk` walks them (robot.json, files,
collision pieces), `mesh` compares each mesh as a placed piece (rigid, scaled or changed
shape; surface distances from `surface`), `step` the STEP solids, `scene` the GLB and USD
files, `tolerance` holds one tolerance per quantity (the checks' own) and the rule that shows
every number at it, `report` the changes and their JSON, `markdown` the Markdown and the
table cells the HTML report (review/diff_html.py) shares.
"""

from __future__ import annotations

from simkit.diff.kit import load_kit, materialize, unpacked
from simkit.diff.report import Change, Report
from simkit.diff.walk import diff_files, diff_kits

__all__ = ["Change", "Report", "diff_files", "diff_kits", "load_kit", "materialize", "unpacked"]
