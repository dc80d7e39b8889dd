"""Fuzzed specs (issue 13), validation only (fast tier): a structured or raw-YAML mutation
of a small valid spec either validates or is refused with one `FILE:LINE: field: message`
line per problem. Never another exception. `scripts/fuzz_specs.py` is the long run, with builds."""

from __future__ import annotations

import copy
import re
from pathlib import Path

import yaml
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from simkit.errors import SpecError
from simkit.spec.validate import load_spec

SPEC = Path(__file__).resolve().parent / "specs" / "planar_2r.yaml"
TEXT = SPEC.read_text()
DATA = yaml.safe_load(TEXT)
LINE = re.compile(r"^\S[^\n]*?(:\d+)?: [^\n]+: [^\n]+$")

HOSTILE_TEXT = [
    "",
    "../../x",
    'a"""b',
    "a\nb",
    "x" * 300,
    "tool0_joint",
    "link_1_collision_00",
    "LINK_1",
    "joint-1",
    "on",
    "null",
    "\u200b",
    "<x/>",
    "é",
]
SCALARS = st.one_of(
    st.none(),
    st.booleans(),
    st.integers(min_value=-(10**30), max_value=10**30),
    st.floats(allow_nan=True, allow_infinity=True),
    st.sampled_from([0, -1, 1e-12, 1e12, 1e308, 360, 36000, 1e9]),
    st.sampled_from(HOSTILE_TEXT),
    st.text(max_size=20),
)
VALUES = st.recursive(
    SCALARS,
    lambda inner: st.one_of(
        st.lists(inner, max_size=4), st.dictionaries(st.text(max_size=8), inner, max_size=3)
    ),
    max_leaves=8,
)
SNIPPETS = [
    "<<: *a",
    "&a ",
    "*a",
    "!!python/object:os.system ",
    "!foo ",
    "\x00",
    "[" * 60,
    "{",
    "- ",
    ": ",
    "\t",
    "'",
    '"',
    "%YAML 1.1\n",
    "---\n",
    "~",
    "? ",
    "1e999",
]


def _paths(value: object, prefix: tuple = ()) -> list[tuple]:
    out = [prefix]
    if isinstance(value, dict):
        for key, item in value.items():
            out += _paths(item, (*prefix, key))
    elif isinstance(value, list):
        for i, item in enumerate(value):
            out += _paths(item, (*prefix, i))
    return out


PATHS = [p for p in _paths(DATA) if p]


def _mutate(data: dict, path: tuple, action: str, value: object) -> dict:
    out = copy.deepcopy(data)
    parent = out
    for part in path[:-1]:
        parent = parent[part]
    last = path[-1]
    if action == "delete":
        del parent[last]
    elif action == "add" and isinstance(parent, dict):
        parent[f"{last}_x"] = value
    elif action == "copy" and isinstance(parent, list):
        parent.append(copy.deepcopy(parent[last]))
    else:
        parent[last] = value
    return out


def _outcome(path: Path) -> str:
    """'valid' or the refusal line; any other exception fails the test."""
    try:
        load_spec(path)
    except SpecError as exc:
        text = str(exc)  # one line per problem (spec/validate.py), each FILE:LINE: field: ...
        lines = [line for line in text.splitlines() if not line.startswith("(and ")]
        assert lines and all(LINE.match(line) for line in lines), text
        assert all(line.startswith(str(path)) for line in lines), text
        return text
    return "valid"


@settings(
    max_examples=100, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(
    path=st.sampled_from(PATHS),
    action=st.sampled_from(["set", "set", "delete", "add", "copy"]),
    value=VALUES,
)
def test_structured_mutation_is_valid_or_one_line(tmp_path, path, action, value):
    spec = tmp_path / "fuzz.yaml"
    spec.write_text(yaml.safe_dump(_mutate(DATA, path, action, value), allow_unicode=True))
    _outcome(spec)


@settings(
    max_examples=100, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(
    edits=st.lists(
        st.tuples(
            st.integers(min_value=0, max_value=len(TEXT)),
            st.integers(min_value=0, max_value=40),
            st.one_of(st.sampled_from(SNIPPETS), st.text(max_size=6)),
        ),
        min_size=1,
        max_size=3,
    )
)
def test_raw_yaml_mutation_is_valid_or_one_line(tmp_path, edits):
    text = TEXT
    for at, cut, insert in edits:
        at = min(at, len(text))
        text = text[:at] + insert + text[at + cut :]
    spec = tmp_path / "fuzz.yaml"
    spec.write_bytes(text.encode("utf-8", "surrogatepass"))
    _outcome(spec)


def test_the_unmutated_spec_is_valid(tmp_path):
    spec = tmp_path / "fuzz.yaml"
    spec.write_text(yaml.safe_dump(DATA))
    assert _outcome(spec) == "valid"
