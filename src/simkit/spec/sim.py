"""Optional spec sections for simulator integration and validation.

- `links[].inertia_decision`: an explicit, recorded decision to keep a reported inertia tensor
  that is not physical (the ECN 2R report's link_0, 002_e760a3794accbbd5.txt Appendix 1, breaks
  the triangle inequality). Without one, such a tensor is a spec error.
- `ros2_control:`: the Gazebo / ros2_control additions the ECN report made by hand (section 4
  and 5): URDF `<ros2_control>` block, transmissions, Gazebo colours, controllers.yaml and a
  Gazebo launch file.
- `freefall:`: the report's fidelity test (section 4, step 4): release from rest at a named pose
  with gravity and compare MuJoCo (MJCF and URDF) with an independent integration.
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import Annotated, Literal

from pydantic import BaseModel, ConfigDict, Field

# Own base types (not imported from spec.py, which imports this module).
PositiveFloat = Annotated[float, Field(gt=0)]
NonNegFloat = Annotated[float, Field(ge=0)]
PositiveInt = Annotated[int, Field(gt=0)]
Problem = tuple[tuple, str]

Interface = Literal["position", "velocity", "effort"]


class Strict(BaseModel):
    """Base: frozen, no unknown keys, finite floats only (as spec.Strict)."""

    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)


class InertiaDecisionSpec(Strict):
    """Keep a link's reported inertia although it is not physical, on purpose.

    `exclude_from_dynamics`: the link is welded to a fixed root (the world), so its inertia
    cannot change any motion; `balance`: any link. Either way the URDF and MJCF carry a
    balanced replacement (every principal moment set to their mean, MuJoCo's
    `compiler/balanceinertia` rule) with the reported mass and CoM, and robot.json records the
    reported tensor, the emitted one, the problem and `reason`.
    """

    action: Literal["exclude_from_dynamics", "balance"]
    reason: Annotated[str, Field(min_length=1)]


class PidGainsSpec(Strict):
    """PID gains of a position controller that commands effort (N m/rad, N m/(rad s), N m s/rad);
    `i_clamp` bounds the integral term symmetrically (N m)."""

    p: NonNegFloat
    i: NonNegFloat = 0.0
    d: NonNegFloat = 0.0
    i_clamp: NonNegFloat = 0.0
    antiwindup: bool = True


class Ros2ControlSpec(Strict):
    """ros2_control in Gazebo (gz_ros2_control) for every actuated joint.

    `gazebo_materials` maps link names to Gazebo material names (the report's
    `<gazebo reference=...><material>` tags, section 4 step 2)."""

    hardware_plugin: str = "gz_ros2_control/GazeboSimSystem"
    gazebo_plugin: str = "gz_ros2_control-system"
    gazebo_plugin_name: str = "gz_ros2_control::GazeboSimROS2ControlPlugin"
    command_interfaces: tuple[Interface, ...] = ("position", "effort")
    state_interfaces: tuple[Interface, ...] = ("position", "velocity", "effort")
    update_rate: PositiveInt = 1000  # Hz, controller_manager
    position_pid: PidGainsSpec | None = None
    effort_controllers: bool = True
    default_control: Literal["position", "effort"] = "position"
    gazebo_materials: dict[str, str] = Field(default_factory=dict)
    estimated: tuple[str, ...] = ()


class FreefallSpec(Strict):
    """Release from rest at named pose `pose` with gravity for `duration` s; the joint-angle
    RMS difference between every pair of the three simulations must stay below
    `tolerance_rms` (rad)."""

    pose: str
    duration: PositiveFloat = 2.0
    tolerance_rms: PositiveFloat = 1e-3


def welded_to_root(spec, link: str) -> bool:
    """True when every joint between the (non-floating) root and `link` is fixed."""
    if spec.floating_base:
        return False
    parent = {j.child: j for j in spec.joints}
    node = link
    while node in parent:
        if parent[node].type != "fixed":
            return False
        node = parent[node].parent
    return node == spec.root


def problems(spec, inertia_problem) -> Iterator[Problem]:
    """Cross-references of the sections above. `inertia_problem` is validate's plausibility
    test (passed in to avoid an import cycle)."""
    links = {link.name for link in spec.links}
    for i, link in enumerate(spec.links):
        decision = link.inertia_decision
        if decision is None:
            continue
        if link.inertia is None:
            yield ("links", i, "inertia_decision"), "an inertia_decision needs the link's inertia"
        elif inertia_problem(link.inertia) is None:
            yield (
                ("links", i, "inertia_decision"),
                ("the inertia is physical; remove the inertia_decision"),
            )
        elif link.inertia.ixx + link.inertia.iyy + link.inertia.izz <= 0:
            yield ("links", i, "inertia_decision"), "no balanced replacement: the trace is not > 0"
        if decision.action == "exclude_from_dynamics" and not welded_to_root(spec, link.name):
            yield (
                ("links", i, "inertia_decision", "action"),
                (
                    f"'{link.name}' moves (it is not welded to the root '{spec.root}' by fixed "
                    "joints), so its inertia cannot be excluded from the dynamics"
                ),
            )
    rc = spec.ros2_control
    if rc is not None:
        for name in rc.gazebo_materials:
            if name not in links:
                yield ("ros2_control", "gazebo_materials", name), f"unknown link '{name}'"
        if rc.position_pid is not None and "effort" not in rc.command_interfaces:
            yield (
                ("ros2_control", "position_pid"),
                ("PID position controllers command effort: add 'effort' to command_interfaces"),
            )
        if rc.effort_controllers and "effort" not in rc.command_interfaces:
            yield (
                ("ros2_control", "effort_controllers"),
                ("effort controllers need 'effort' in command_interfaces"),
            )
        if rc.default_control == "position" and rc.position_pid is None:
            yield ("ros2_control", "default_control"), "default 'position' needs position_pid"
        if rc.default_control == "effort" and not rc.effort_controllers:
            yield ("ros2_control", "default_control"), "default 'effort' needs effort_controllers"
        allowed = set(Ros2ControlSpec.model_fields) - {"estimated"}
        for k, field in enumerate(rc.estimated):
            if field not in allowed:
                yield ("ros2_control", "estimated", k), f"'{field}' is not a ros2_control field"
    ff = spec.freefall
    if ff is not None and ff.pose not in {**spec.poses, **spec.poses_deg}:
        yield ("freefall", "pose"), f"unknown pose '{ff.pose}'"
    if ff is not None and spec.floating_base:
        # rnea.py integrates the joints of a fixed-base tree; a free base would fall away in
        # MuJoCo while the independent side holds it, a meaningless comparison
        yield (
            ("freefall",),
            "the free-fall validation needs a fixed base (the report's arm is welded to the "
            "world); remove `freefall:` or `floating_base`",
        )
