"""The one Jinja environment of every text emitter (README, examples, ROS 2 files, training):
templates from the packaged `templates/` folder, strict about undefined values, and every
value through its language's escape filter (emit/escape.py)."""

from __future__ import annotations

from functools import cache

import jinja2

from simkit.kitio.resources import data_dir


@cache
def environment() -> jinja2.Environment:
    """The template environment shared by every text emitter."""
    from simkit.emit.escape import FILTERS

    env = jinja2.Environment(
        loader=jinja2.FileSystemLoader(str(data_dir("templates"))),
        undefined=jinja2.StrictUndefined,
        keep_trailing_newline=True,
        trim_blocks=True,
        lstrip_blocks=True,
        autoescape=False,
    )
    env.filters.update(FILTERS)  # every value goes through its language's filter (escape.py)
    return env
