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
