"""Every path inside a kit comes from here, so no two outputs can disagree about a path.

Paths are POSIX, relative to the kit folder `NAME_description/`.
"""

from __future__ import annotations

import posixpath


def kit_dir_name(robot: str) -> str:
    """`rosie_1000` -> `rosie_1000_description` (also the ROS 2 package name)."""
    return f"{robot}_description"


def zip_name(robot: str) -> str:
    """`rosie_1000` -> `rosie-1000-sim-kit.zip`, as the kit page's download link."""
    return f"{robot.replace('_', '-')}-sim-kit.zip"


README = "README.md"
LICENSE = "LICENSE.txt"
ROBOT_JSON = "robot.json"
IK_CASES = "ik_cases.json"


def urdf(robot: str) -> str:
    return f"urdf/{robot}.urdf"


def mjcf(robot: str) -> str:
    return f"mjcf/{robot}.xml"


def mjcf_scene(robot: str) -> str:
    return f"mjcf/{robot}_scene.xml"


def mjcf_mjx(robot: str) -> str:
    """The GPU scene for MJX and MuJoCo Warp (emit/mjcf_mjx.py)."""
    return f"mjcf/{robot}_mjx.xml"


def srdf(robot: str) -> str:
    return f"srdf/{robot}.srdf"


def glb(robot: str) -> str:
    return f"glb/{robot}.glb"


def usd(robot: str, binary: bool = False) -> str:
    """The USD entry point users open: an interface layer over the Isaac asset's payloads."""
    return f"usd/{robot}.{'usdc' if binary else 'usda'}"


def usd_asset(robot: str, binary: bool = False) -> str:
    """The Isaac Sim robot asset's interface layer, `usd/NAME/NAME.usda`: the folder is named
    as the file, as Isaac Sim's asset library and the SimReady naming rule (RC.003) ask."""
    return f"usd/{robot}/{robot}.{'usdc' if binary else 'usda'}"


def usd_payload(robot: str, layer: str) -> str:
    """`base.usda` -> `usd/NAME/payloads/base.usda`: named as Isaac Sim's asset structure and
    the SimReady composition rule (ISA.001) name them, beside the asset's interface layer."""
    return f"usd/{robot}/payloads/{layer}"


def usd_thumbnail(usd_file: str) -> str:
    """`usd/NAME.usda` -> `usd/.thumbs/256x256/NAME.usda.png`: the thumbnail of a USD layer,
    where Omniverse and the SimReady rules look for it."""
    folder, name = posixpath.split(usd_file)
    return posixpath.join(folder, ".thumbs", "256x256", f"{name}.png")


def visual_mesh(link: str) -> str:
    return f"meshes/visual/{link}.stl"


def collision_mesh(link: str, index: int) -> str:
    """A convex collision piece, OBJ (kitio/obj.py): Drake's SceneGraph needs OBJ for hulls."""
    return f"meshes/collision/{link}_{index:02d}.obj"


def benchmark(robot: str, ext: str) -> str:
    return f"benchmark/{robot}_cycle_1kg.{ext}"


PACKAGE_XML = "package.xml"
CMAKELISTS = "CMakeLists.txt"
DISPLAY_LAUNCH = "launch/display.launch.py"
INDEX_JSON = "index.json"


def rviz(robot: str) -> str:
    return f"rviz/{robot}.rviz"


def example(name: str) -> str:
    """`mujoco_demo.py` -> `examples/mujoco_demo.py`."""
    return f"examples/{name}"


#: The training files (emit/training.py, issue 41): a MuJoCo Playground environment, an mjlab
#: entity config and an Isaac Lab articulation config, beside each other in `training/`.
TRAINING_DIR = "training"
PLAYGROUND_ENV = f"{TRAINING_DIR}/playground_env.py"
MJLAB_CFG = f"{TRAINING_DIR}/mjlab_cfg.py"
ISAACLAB_CFG = f"{TRAINING_DIR}/isaaclab_cfg.py"


def asset_dir(robot: str, declared: str | None = None) -> str:
    """Folder of a kit's files under the download site's /assets/sim/ (the kit page's
    `<model>`, e.g. `1000`), the spec's `asset_dir` or else the robot name."""
    return declared or robot


#: ros2_control (emit/ros2_control.py): controller settings and the Gazebo launch file.
CONTROLLERS_YAML = "config/controllers.yaml"
GAZEBO_LAUNCH = "launch/gazebo.launch.py"


def freefall_csv() -> str:
    """Free-fall trajectories (freefall.py), one column per run, simulation and joint."""
    return "validation/freefall.csv"


def freefall_plot() -> str:
    return "validation/freefall.png"


def relative(from_file: str, to_file: str) -> str:
    """Path of `to_file` as seen from the folder of `from_file` (e.g. `../meshes/...`)."""
    return posixpath.relpath(to_file, posixpath.dirname(from_file) or ".")


def sdf(robot: str) -> str:
    """The SDFormat 1.9 model (emit/sdf.py), for Gazebo and Drake."""
    return f"sdf/{robot}.sdf"


def step(robot: str) -> str:
    """The STEP AP214 assembly (emit/step.py), millimetres, origin base_link."""
    return f"step/{robot}.step"
