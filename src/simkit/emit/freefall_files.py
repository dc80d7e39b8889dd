"""Validation products: the free-fall trajectories (freefall.py) as CSV and as a PNG plot.

Nothing is simulated here; the derive step did that. The plot is drawn with matplotlib's Agg
canvas (no pyplot state, no display) and saved without the `Software` metadata entry, so the
same trajectories give the same bytes (PNG itself carries no timestamp).
"""

from __future__ import annotations

import contextlib
import io
import os
import shutil
import sys
import tempfile
from collections.abc import Iterator
from pathlib import Path

from simkit.kitio import layout
from simkit.kitio.cache import default_dir
from simkit.kitio.fmt import num
from simkit.model.robot import Robot, SimReports

STYLE = {  # side -> (label, matplotlib line style): three curves on top of each other
    "independent": ("independent (RNEA + solve_ivp)", {"color": "0.6", "linewidth": 5.0}),
    "mjcf": ("MuJoCo, MJCF", {"color": "tab:blue", "linewidth": 1.8, "linestyle": "--"}),
    "urdf": ("MuJoCo, URDF", {"color": "tab:red", "linewidth": 1.2, "linestyle": ":"}),
}
PLOTTED_RUN = "friction"  # the spec's model as written, friction included


def csv_text(data: dict) -> str:
    """Header `t,<run>.<side>.<joint>,...`, one row per sample (s, rad)."""
    columns = [
        (run, side, k, joint)
        for run, sides in data["trajectories"].items()
        for side in sides
        for k, joint in enumerate(data["joints"])
    ]
    lines = ["t," + ",".join(f"{run}.{side}.{joint}" for run, side, _, joint in columns)]
    for i, t in enumerate(data["t"]):
        values = [num(data["trajectories"][run][side][i, k]) for run, side, k, _ in columns]
        lines.append(",".join([num(t), *values]))
    return "\n".join(lines) + "\n"


def plot_png(robot: Robot, data: dict) -> bytes:
    """One panel per joint: the three simulations of the plotted run superimposed."""
    with matplotlib_home():
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        from matplotlib.figure import Figure

    joints, sides = data["joints"], data["trajectories"][PLOTTED_RUN]
    fig = Figure(figsize=(8.0, 2.4 * len(joints) + 1.4), dpi=100)
    FigureCanvasAgg(fig)
    axes = fig.subplots(len(joints), 1, sharex=True, squeeze=False)[:, 0]
    for k, (ax, joint) in enumerate(zip(axes, joints, strict=True)):
        for side, (label, style) in STYLE.items():
            ax.plot(data["t"], sides[side][:, k], label=label, **style)
        ax.set_ylabel(f"{joint} (rad)")
        ax.grid(True, linewidth=0.4)
    axes[-1].set_xlabel("time after release (s)")
    axes[0].legend(loc="upper right", fontsize=8)
    figs = data["figures"]
    lines = [
        f"{robot.title}: free fall from rest, {num(data['t'][-1], 3)} s ({PLOTTED_RUN} run shown)",
        "joint-angle RMS difference (rad), MJCF vs indep. / URDF vs indep. / MJCF vs URDF:",
        "; ".join(
            f"{run} " + " / ".join(num(figs[run][pair]["rms"], 2) for pair in figs[run])
            for run in figs
        )
        + f"; bound {num(data['tolerance_rms'], 3)}",
    ]
    fig.suptitle("\n".join(lines), fontsize=9)
    fig.tight_layout()
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", metadata={"Software": None})
    return buffer.getvalue()


@contextlib.contextmanager
def matplotlib_home() -> Iterator[None]:
    """Import matplotlib with MPLCONFIGDIR in simkit's cache folder (`matplotlib/`: its font
    list) where that folder exists, else in a temporary folder removed afterwards (about
    0.5 s to rebuild the font list): by default it writes
    ~/.config/matplotlib and ~/.cache/matplotlib, and a build writes nothing outside --out
    but simkit's cache. A user's own MPLCONFIGDIR, or matplotlib already imported, is kept."""
    if "MPLCONFIGDIR" in os.environ or "matplotlib" in sys.modules:
        yield
        return
    scratch = None
    try:  # never create the cache folder for this alone (--no-cache, --cache-dir elsewhere)
        home = default_dir() / "matplotlib"
        if not home.parent.is_dir():
            raise FileNotFoundError(home.parent)
        home.mkdir(exist_ok=True)
    except OSError:  # no cache folder, or an unwritable one
        home = scratch = Path(tempfile.mkdtemp(prefix="simkit-matplotlib-"))
    os.environ["MPLCONFIGDIR"] = str(home)
    try:
        import matplotlib  # noqa: F401  (reads MPLCONFIGDIR once, on import)

        yield
    finally:
        os.environ.pop("MPLCONFIGDIR", None)
        if scratch is not None:
            shutil.rmtree(scratch, ignore_errors=True)


def emit(robot: Robot, reports: SimReports) -> dict[str, bytes]:
    """`validation/freefall.csv` and `validation/freefall.png` for a spec with `freefall:`."""
    if reports.freefall is None:
        return {}
    data = reports.freefall["data"]
    return {
        layout.freefall_csv(): csv_text(data).encode("utf-8"),
        layout.freefall_plot(): plot_png(robot, data),
    }
