"""GLB emitter: the visual geometry as one glTF 2.0 binary, one node per link.

Kit page, "GLB": nodes follow the joint chain (base_footprint > base_link > link_1 ... link_6 >
tool0, a tree for trees); each link node sits on its joint origin, so rotating it about its
joint axis (in the node's extras) by the joint angle moves the robot; glTF is Y-up, so the root
node turns the kit's Z-up frames upright. Materials come from the spec's colours.

Layout follows the glTF 2.0 specification (Khronos, "GLB File Format Specification"): a 12-byte
header, a JSON chunk padded with spaces and a BIN chunk padded with zeros, both to 4 bytes.
Positions and normals are float32, indices uint16 or uint32. Normals (kitio/normals.py) are
smooth across curved surfaces and split at creases, so a vertex on an edge is written once
per face normal there. Byte-identical across builds: no clock, fixed order, `jsonout` numbers.

Node names are the URDF link names, exactly (issue 12). A loader may rename one on load: trimesh
turns a node called "world" (the ECN 2R's root link) into "world_1", its own root being "world".
"""

from __future__ import annotations

import json
import struct

import numpy as np

from simkit import __version__
from simkit.kitio import layout
from simkit.kitio.fmt import ZERO_BELOW, rounded
from simkit.kitio.normals import corner_normals, split_vertices
from simkit.model.kinematics import quat_wxyz, rpy_matrix
from simkit.model.robot import Joint, Robot

#: Z-up to Y-up: -90 degrees about x, as (x, y, z, w).
Y_UP = (-np.sqrt(0.5), 0.0, 0.0, np.sqrt(0.5))
ARRAY_BUFFER, ELEMENT_ARRAY_BUFFER = 34962, 34963
FLOAT, UNSIGNED_SHORT, UNSIGNED_INT = 5126, 5123, 5125
DEFAULT_MATERIAL = "default"
ROUGHNESS = 0.6  # estimate: the spec gives colours only


def _quat_xyzw(rpy) -> list[float] | None:
    w, x, y, z = quat_wxyz(rpy_matrix(rpy))
    return None if np.allclose((x, y, z), 0.0, atol=1e-15) else [x, y, z, w]


def _place(node: dict, xyz, rpy) -> dict:
    if any(abs(v) > 0 for v in xyz):
        node["translation"] = list(xyz)
    quat = _quat_xyzw(rpy)
    if quat is not None:
        node["rotation"] = quat
    return node


def _joint_extras(joint: Joint) -> dict:
    """The joint that places this link node: name, type, axis (node frame), limits, links."""
    extras: dict = {
        "name": joint.name,
        "type": joint.type,
        "parent": joint.parent,
        "child": joint.child,
    }
    if joint.movable:
        extras["axis"] = list(joint.axis)
        for key in ("lower", "upper", "max_velocity", "effort_peak"):
            value = getattr(joint, key)
            if value is not None:
                extras[key] = value
    return extras


class _Buffer:
    """The BIN chunk: each buffer view starts on a 4-byte boundary."""

    def __init__(self) -> None:
        self.data = bytearray()
        self.views: list[dict] = []
        self.accessors: list[dict] = []

    def add(
        self, array: np.ndarray, target: int, component: int, kind: str, bounds: bool = False
    ) -> int:
        self.data.extend(b"\0" * (-len(self.data) % 4))
        raw = np.ascontiguousarray(array).tobytes()
        self.views.append(
            {"buffer": 0, "byteOffset": len(self.data), "byteLength": len(raw), "target": target}
        )
        self.data.extend(raw)
        accessor = {
            "bufferView": len(self.views) - 1,
            "componentType": component,
            "count": int(array.shape[0] if kind != "SCALAR" else array.size),
            "type": kind,
        }
        if bounds:
            accessor["min"] = [float(v) for v in array.min(axis=0)]
            accessor["max"] = [float(v) for v in array.max(axis=0)]
        self.accessors.append(accessor)
        return len(self.accessors) - 1


def _materials(robot: Robot) -> tuple[list[dict], dict[str, int]]:
    used = {link.material for link in robot.links if link.solid is not None}
    colours = dict(robot.materials)
    names = [name for name, _rgba in robot.materials if name in used]
    if any(m is None or m not in colours for m in used):
        names.append(DEFAULT_MATERIAL)
    out = []
    for name in names:
        rgba = list(robot.material_rgba(None if name == DEFAULT_MATERIAL else name))
        material = {
            "name": name,
            "pbrMetallicRoughness": {
                "baseColorFactor": rgba,
                "metallicFactor": 0.0,
                "roughnessFactor": ROUGHNESS,
            },
        }
        if rgba[3] < 1.0:
            material["alphaMode"] = "BLEND"
        out.append(material)
    index = {name: i for i, name in enumerate(names)}
    return out, index


def _clean(value):
    """JSON-ready data with every float through the one formatter (as `jsonout`)."""
    if isinstance(value, dict):
        return {k: _clean(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_clean(v) for v in value]
    if isinstance(value, (float, np.floating)):
        return rounded(float(value))
    if isinstance(value, np.integer):
        return int(value)
    return value


def document(robot: Robot) -> tuple[dict, bytes]:
    """The glTF JSON and the BIN chunk of a robot."""
    buf = _Buffer()
    materials, material_index = _materials(robot)
    meshes: list[dict] = []
    nodes: list[dict] = [
        {
            "name": f"{robot.name}_y_up",
            "rotation": list(Y_UP),
            "extras": {"note": "turns the kit's Z-up frames into glTF's Y-up"},
        },
    ]
    # A floating base has no URDF link for the world (urdf.py): its base link hangs on the Y-up
    # node directly, so the GLB's nodes are exactly the URDF's links (issue 12).
    if robot.floating_joint is None:
        nodes[0]["children"] = [1]
        nodes.append({"name": robot.root, "children": []})
    else:
        nodes[0]["children"] = []
    index = {robot.root: len(nodes) - 1}

    def attach(parent: str, node: dict) -> None:
        nodes.append(node)
        index[node["name"]] = len(nodes) - 1
        nodes[index[parent]].setdefault("children", []).append(len(nodes) - 1)

    for joint in robot.joints:  # tree order: a parent's node exists before its children's
        link = robot.link(joint.child)
        node = _place({"name": link.name}, joint.xyz, joint.rpy)
        if link.solid is not None:
            positions, normals, faces = split_vertices(
                link.solid.vertices,
                link.solid.faces,
                corner_normals(link.solid.vertices, link.solid.faces),
            )
            positions = positions.astype("<f4")
            # round-off below fmt's zero threshold is written as 0 in min/max: match the data
            positions = np.where(np.abs(positions) < ZERO_BELOW, 0, positions).astype("<f4")
            small = len(positions) < 65536
            indices = faces.astype("<u2" if small else "<u4").ravel()
            pos = buf.add(positions, ARRAY_BUFFER, FLOAT, "VEC3", bounds=True)
            nrm = buf.add(normals.astype("<f4"), ARRAY_BUFFER, FLOAT, "VEC3")
            idx = buf.add(
                indices, ELEMENT_ARRAY_BUFFER, UNSIGNED_SHORT if small else UNSIGNED_INT, "SCALAR"
            )
            material = link.material if link.material in material_index else DEFAULT_MATERIAL
            meshes.append(
                {
                    "name": link.name,
                    "primitives": [
                        {
                            "attributes": {"POSITION": pos, "NORMAL": nrm},
                            "indices": idx,
                            "material": material_index[material],
                            "mode": 4,
                        }
                    ],
                }
            )
            node["mesh"] = len(meshes) - 1
        node["extras"] = {"joint": _joint_extras(joint)}
        attach(joint.parent, node)
    for frame in robot.frames:
        attach(
            frame.parent,
            _place({"name": frame.name, "extras": {"frame": frame.name}}, frame.xyz, frame.rpy),
        )
    for node in nodes:
        if node.get("children") == []:
            del node["children"]
    buf.data.extend(b"\0" * (-len(buf.data) % 4))
    doc = {
        "asset": {"version": "2.0", "generator": f"simkit {__version__}"},
        "scene": 0,
        "scenes": [{"name": robot.name, "nodes": [0]}],
        "nodes": nodes,
        "meshes": meshes,
        "materials": materials,
        "accessors": buf.accessors,
        "bufferViews": buf.views,
        "buffers": [{"byteLength": len(buf.data)}],
        "extras": {"robot": robot.name, "units": "m", "source": robot.spec_file},
    }
    return _clean(doc), bytes(buf.data)


def to_glb(doc: dict, binary: bytes) -> bytes:
    """Assemble a GLB container (glTF 2.0, "GLB File Format Specification")."""
    text = json.dumps(doc, separators=(",", ":"), ensure_ascii=False).encode("utf-8")
    text += b" " * (-len(text) % 4)
    binary += b"\0" * (-len(binary) % 4)
    total = 12 + 8 + len(text) + 8 + len(binary)
    return (
        struct.pack("<4sII", b"glTF", 2, total)
        + struct.pack("<I4s", len(text), b"JSON")
        + text
        + struct.pack("<I4s", len(binary), b"BIN\0")
        + binary
    )


def emit(robot: Robot) -> dict[str, bytes]:
    """`glb/NAME.glb`."""
    return {layout.glb(robot.name): to_glb(*document(robot))}
