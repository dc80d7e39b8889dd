"""ros2_control and Gazebo for robots whose spec has a `ros2_control:` section.

What the ECN report (002_e760a3794accbbd5.txt) added to its URDF and package by hand, section 4
steps 2-3 and section 5 step 1, in their ROS 2 / gz sim form:

- URDF (`urdf_elements`, appended by emit/urdf.py): `<gazebo reference>` material tags per
  link (Gazebo classic ignores URDF colours); the gz_ros2_control system plugin; a
  `<ros2_control>` block with gz_ros2_control/GazeboSimSystem, the command and state
  interfaces of every actuated joint; a transmission per joint whose mechanicalReduction is
  the drive's gear ratio (URDF transmission spec: the reduction belongs to the actuator; as
  the report notes, Gazebo does not use it).
- `config/controllers.yaml`: joint_state_broadcaster, one PID position controller per joint
  (pid_controller commanding effort, the report's gains) and one effort controller per joint.
- `launch/gazebo.launch.py`: gz sim, robot_state_publisher, spawn, the controllers of the
  chosen mode (`control:=position|effort`, as the report's launch argument).
"""

from __future__ import annotations

import xml.etree.ElementTree as ET

from simkit.derive.ros2_control import controller_base, controllers, joints
from simkit.emit.templating import environment
from simkit.kitio import layout
from simkit.kitio.fmt import num
from simkit.kitio.xmlwriter import sub
from simkit.model.robot import Joint, Robot

#: ROS 1 hardware interface names of the URDF transmission spec, per command interface.
HARDWARE_INTERFACES = {
    "position": "hardware_interface/PositionJointInterface",
    "velocity": "hardware_interface/VelocityJointInterface",
    "effort": "hardware_interface/EffortJointInterface",
}
TRANSMISSION = "transmission_interface/SimpleTransmission"
JOINT_STATE_BROADCASTER = "joint_state_broadcaster"


def _placeholder(robot: Robot) -> str:
    """The `<parameters>` path the URDF carries; gazebo.launch.py swaps in the installed path
    (xacro would resolve the same `$(find ...)` form)."""
    return f"$(find {layout.kit_dir_name(robot.name)})/{layout.CONTROLLERS_YAML}"


def _home(robot: Robot) -> dict[str, float]:
    q = dict(robot.poses).get("home")
    names = [j.name for j in robot.movable_joints]
    return dict(zip(names, q, strict=True)) if q is not None else {}


def urdf_elements(robot: Robot) -> list[ET.Element]:
    """Elements appended to the URDF's <robot>; none without a `ros2_control:` section."""
    rc = robot.ros2_control
    if rc is None:
        return []
    out: list[ET.Element] = []
    for link, material in sorted(
        rc.gazebo_materials.items(), key=lambda kv: [lk.name for lk in robot.links].index(kv[0])
    ):
        gazebo = ET.Element("gazebo", reference=link)
        sub(gazebo, "material").text = material
        out.append(gazebo)
    gazebo = ET.Element("gazebo")
    plugin = sub(gazebo, "plugin", filename=rc.gazebo_plugin, name=rc.gazebo_plugin_name)
    sub(plugin, "parameters").text = _placeholder(robot)
    out.append(gazebo)
    control = ET.Element("ros2_control", name="GazeboSimSystem", type="system")
    sub(sub(control, "hardware"), "plugin").text = rc.hardware_plugin
    home = _home(robot)
    for joint in joints(robot):
        el = sub(control, "joint", name=joint.name)
        for interface in rc.command_interfaces:
            command = sub(el, "command_interface", name=interface)
            bounds = _bounds(joint, interface)
            if bounds is not None:
                sub(command, "param", name="min").text = num(bounds[0])
                sub(command, "param", name="max").text = num(bounds[1])
        for interface in rc.state_interfaces:
            state = sub(el, "state_interface", name=interface)
            if interface == "position" and joint.name in home:
                sub(state, "param", name="initial_value").text = num(home[joint.name])
    out.append(control)
    for joint in joints(robot):
        out.append(_transmission(robot, joint))
    return out


def _bounds(joint: Joint, interface: str) -> tuple[float, float] | None:
    """Command limits: joint range (rad), speed (rad/s), the drive's peak torque (N m)."""
    if interface == "position" and joint.lower is not None and joint.type != "continuous":
        return joint.lower, joint.upper
    if interface == "velocity" and joint.max_velocity is not None:
        return -joint.max_velocity, joint.max_velocity
    torque = joint.drive_peak_torque_at_joint or joint.effort_peak
    if interface == "effort" and torque is not None:
        return -torque, torque
    return None


def _transmission(robot: Robot, joint: Joint) -> ET.Element:
    rc = robot.ros2_control
    el = ET.Element("transmission", name=f"{joint.name}_transmission")
    sub(el, "type").text = TRANSMISSION
    jel = sub(el, "joint", name=joint.name)
    for interface in rc.command_interfaces:
        sub(jel, "hardwareInterface").text = HARDWARE_INTERFACES[interface]
    actuator = sub(el, "actuator", name=f"{joint.name}_actuator")
    ratio = joint.drive.gear_ratio if joint.drive is not None else 1.0
    sub(actuator, "mechanicalReduction").text = num(ratio)
    return el


def _double(value: float) -> str:
    """A YAML number ROS 2 reads as a double (typed parameters reject `200` for a double):
    `fmt.num` with a decimal point always present."""
    text = num(value)
    mantissa, _, exponent = text.partition("e")
    if "." not in mantissa:
        mantissa += ".0"
    return mantissa + ("e" + exponent if exponent else "")


def _context(robot: Robot) -> dict:
    rc = robot.ros2_control
    pid = rc.position_pid
    by_mode = controllers(robot)
    return {
        "spec": robot.spec_file,
        "title": robot.title,
        "robot": robot.name,
        "package": layout.kit_dir_name(robot.name),
        "urdf": layout.urdf(robot.name),
        "controllers_yaml": layout.CONTROLLERS_YAML,
        "placeholder": _placeholder(robot),
        "update_rate": str(rc.update_rate),
        "broadcaster": JOINT_STATE_BROADCASTER,
        "joints": [
            {
                "name": j.name,
                "position": f"{controller_base(j.name)}_position_controller",
                "effort": f"{controller_base(j.name)}_effort_controller",
            }
            for j in joints(robot)
        ],
        "pid": None
        if pid is None
        else {
            "p": _double(pid.p),
            "i": _double(pid.i),
            "d": _double(pid.d),
            "i_clamp_max": _double(pid.i_clamp),
            "i_clamp_min": _double(-pid.i_clamp),
            "antiwindup": "true" if pid.antiwindup else "false",
        },
        "effort_controllers": rc.effort_controllers,
        "modes": {mode: names for mode, names in by_mode.items() if names},
        "default_control": rc.default_control,
    }


def emit(robot: Robot) -> dict[str, bytes]:
    """`config/controllers.yaml` and `launch/gazebo.launch.py`; nothing without the section."""
    if robot.ros2_control is None:
        return {}
    env, ctx = environment(), _context(robot)
    return {
        layout.CONTROLLERS_YAML: env.get_template("ros2/controllers.yaml.j2").render(ctx).encode(),
        layout.GAZEBO_LAUNCH: env.get_template("ros2/gazebo.launch.py.j2").render(ctx).encode(),
    }
