"""Escaping for every language a template writes, registered as Jinja filters.

Templates never paste raw text: a value goes through the filter of the language around it.

- `py`: a Python literal (`repr`), for strings in code;
- `pydoc`: text inside a `\"\"\"` docstring (backslashes, quotes and control characters escaped);
- `comment`: text after `#` on one line (YAML, CMake, Python comments);
- `yaml`: one YAML flow scalar, written by the YAML emitter (so `on`, `null`, `1e3` or
  `a: b` stay strings);
- `xml`: XML character data and attribute values (`&`, `<`, `>`, quotes).
"""

from __future__ import annotations

from xml.sax.saxutils import escape as _xml_escape


def py(value: object) -> str:
    """A Python literal that evaluates to `value` (str, number, bool, None): `repr`, with
    double quotes for a string that holds no quote (the house style of the templates)."""
    text = repr(value)
    if isinstance(value, str) and text.startswith("'") and not {"'", '"'} & set(value):
        return f'"{text[1:-1]}"'
    return text


def pydoc(value: object) -> str:
    """`value` as text that reads the same inside a non-raw triple-quoted Python string."""
    out = []
    for ch in str(value):
        if ch == "\\":
            out.append("\\\\")
        elif ch == '"':
            out.append('\\"')
        elif ch == "\n" or ch.isprintable():
            out.append(ch)
        else:
            out.append(repr(ch)[1:-1])
    return "".join(out)


def comment(value: object) -> str:
    """`value` on one comment line: line breaks and control characters as escapes."""
    return "".join(ch if ch.isprintable() else repr(ch)[1:-1] for ch in str(value))


def yaml_scalar(value: object) -> str:
    """One YAML flow scalar for `value`, as the YAML emitter quotes it."""
    import yaml

    text = yaml.safe_dump(value, default_flow_style=True, width=1 << 30, allow_unicode=True)
    text = text.removesuffix("\n").removesuffix("\n...")
    if "\n" in text:  # a multi-line scalar: one double-quoted line (JSON strings are YAML)
        import json

        return json.dumps(value)
    return text


def xml(value: object) -> str:
    """XML text or attribute content."""
    return _xml_escape(str(value), {'"': "&quot;", "'": "&apos;"})


def xml_comment(value: object) -> str:
    """Text inside `<!-- -->`: no `--` (XML forbids it there), no trailing `-`."""
    from simkit.kitio.xmlwriter import comment_text

    return comment_text(str(value))


FILTERS = {
    "py": py,
    "pydoc": pydoc,
    "comment": comment,
    "yaml": yaml_scalar,
    "xml": xml,
    "xml_comment": xml_comment,
}
