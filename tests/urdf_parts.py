"""Small URDFs the issue-32 importer tests write: box links (0.05 x 0.05 x 0.2 m, 1 kg) on
revolute joints, written whole into a test's folder."""

from __future__ import annotations

from pathlib import Path

BOX = '<geometry><box size="0.05 0.05 0.2"/></geometry>'
LIMIT = 'lower="-1" upper="1" effort="20" velocity="2"'


def link(name: str, mass: str = "1", gap: str = "") -> str:
    """A box link whose box rises 0.1 m from its origin; `gap` goes between its elements
    (whitespace: two copies that differ only there have the same content)."""
    return (
        f'<link name="{name}">{gap}<inertial><mass value="{mass}"/><inertia ixx="0.004" '
        f'iyy="0.004" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial>{gap}'
        f'<visual><origin xyz="0 0 0.1"/>{BOX}</visual>{gap}'
        f'<collision><origin xyz="0 0 0.1"/>{BOX}</collision>{gap}</link>'
    )


def joint(name: str, parent: str, child: str, kind: str = "revolute", limit: str = LIMIT) -> str:
    """A joint 0.2 m above its parent's origin, turned 0.5 rad about z, about x."""
    limits = f"<limit {limit}/>" if kind != "fixed" else ""
    return (
        f'<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>'
        f'<origin xyz="0 0 0.2" rpy="0 0 0.5"/><axis xyz="1 0 0"/>{limits}</joint>'
    )


def write(folder: Path, name: str, *body: str, robot: str | None = None) -> Path:
    """`folder/NAME.urdf` holding `body` (one element a line); `robot`: the robot's name
    attribute (default NAME; "" for none)."""
    robot = name if robot is None else robot
    attribute = f' name="{robot}"' if robot else ""
    urdf = folder / f"{name}.urdf"
    urdf.write_text(
        f'<?xml version="1.0"?>\n<robot{attribute}>\n' + "\n".join(body) + "\n</robot>\n"
    )
    return urdf
