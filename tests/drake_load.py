"""A kit's URDF or SDF in Drake (tests/test_drake.py, tests/test_drake_hull.py)."""

from __future__ import annotations

import json
from pathlib import Path

from simkit.check.readers.tree import read_urdf


def load_kit(kit: Path, fmt: str):
    """(plant, model instance, context, scene graph inspector, file) of the kit's URDF or
    SDF in a MultibodyPlant with SceneGraph. A fixed-base URDF's root link is welded to the
    world (SDF welds it itself; a URDF root named `world` is Drake's world)."""
    from pydrake.multibody.parsing import Parser
    from pydrake.multibody.plant import AddMultibodyPlantSceneGraph
    from pydrake.systems.framework import DiagramBuilder

    doc = json.loads((kit / "robot.json").read_text())
    path = kit / fmt / f"{doc['name']}.{fmt}"
    builder = DiagramBuilder()
    plant, scene_graph = AddMultibodyPlantSceneGraph(builder, time_step=0.0)
    (instance,) = Parser(plant).AddModels(str(path))
    if fmt == "urdf" and not doc.get("floating_base"):
        root = read_urdf(path).root
        if root != "world":
            plant.WeldFrames(plant.world_frame(), plant.GetFrameByName(root, instance))
    plant.Finalize()
    diagram = builder.Build()
    context = plant.GetMyContextFromRoot(diagram.CreateDefaultContext())
    return plant, instance, context, scene_graph.model_inspector(), path
