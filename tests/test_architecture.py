"""The one-way rule (docs/architecture.md): no import cycles anywhere in simkit, and the
stage packages exist as documented. import-linter's layer contract runs in .ci/run."""

from __future__ import annotations

import grimp

STAGES = ("kitio", "spec", "model", "derive", "emit", "simulate", "check")


def test_import_graph_has_no_cycles():
    graph = grimp.build_graph("simkit")
    cycles = []
    for module in sorted(graph.modules):
        for imported in sorted(graph.find_modules_directly_imported_by(module)):
            if graph.chain_exists(importer=imported, imported=module):
                cycles.append((module, imported))
    assert not cycles, f"import cycles: {cycles[:5]}"


def test_every_stage_is_a_package():
    graph = grimp.build_graph("simkit")
    for stage in STAGES:
        assert f"simkit.{stage}" in graph.modules
    assert "simkit.pipeline" in graph.modules


def _private(name: str) -> bool:
    return name.startswith("_") and not (name.startswith("__") and name.endswith("__"))


def test_no_module_uses_another_modules_private_names():
    """Project rule: no `_private` name crosses a module boundary, neither imported
    (`from simkit.x import _name`) nor reached through a module (`x._name`)."""
    import ast
    from pathlib import Path

    import simkit

    found = []
    for path in sorted(Path(simkit.__file__).parent.rglob("*.py")):
        tree = ast.parse(path.read_text(encoding="utf-8"))
        imported: set[str] = set()
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom) and (node.module or "").startswith("simkit"):
                for alias in node.names:
                    if _private(alias.name):
                        found.append(f"{path.name}:{node.lineno} {alias.name}")
                    imported.add(alias.asname or alias.name)
            elif isinstance(node, ast.Import):
                for alias in node.names:
                    if alias.name.startswith("simkit"):
                        imported.add(alias.asname or alias.name.split(".")[0])
        for node in ast.walk(tree):
            if (
                isinstance(node, ast.Attribute)
                and _private(node.attr)
                and isinstance(node.value, ast.Name)
                and node.value.id in imported
            ):
                found.append(f"{path.name}:{node.lineno} {node.value.id}.{node.attr}")
    assert not found, f"private names used across modules: {found}"
