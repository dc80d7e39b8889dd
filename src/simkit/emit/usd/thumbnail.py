"""The USD thumbnail (`usd/.thumbs/256x256/NAME.usda.png`, where Omniverse and the SimReady
rules RC.004 and SR.002 look): the robot's visual solids in the home pose, in the spec's
colours, drawn by this module. A software painter's render (faces far to near, Lambert shading,
drawn at twice the size and averaged down) and not MuJoCo's offscreen render: an emitter reads
no OpenGL driver, so the same spec gives the same PNG bytes on every machine, and a machine
without EGL or OSMesa still builds the kit."""

from __future__ import annotations

import numpy as np

from simkit.kitio.png import png_bytes
from simkit.model.kinematics import forward
from simkit.model.robot import Robot

SIZE = 256
SUPER = 2  # drawn at SUPER x SIZE, then box-filtered down: smooth edges
BACKGROUND = (38, 40, 46)
#: the view direction of `simkit render`'s default camera (MuJoCo's free camera convention:
#: azimuth 135 deg, elevation -20 deg), rad
AZIMUTH, ELEVATION = np.radians(135.0), np.radians(-20.0)
AMBIENT = 0.35


def _camera() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(right, up, view): view points from the camera into the scene, Z up."""
    ce, se = np.cos(ELEVATION), np.sin(ELEVATION)
    view = np.array([ce * np.cos(AZIMUTH), ce * np.sin(AZIMUTH), se])
    right = np.cross(view, [0.0, 0.0, 1.0])
    right /= np.linalg.norm(right)
    return right, np.cross(right, view), view


def _triangles(robot: Robot) -> tuple[np.ndarray, np.ndarray]:
    """(triangles (N, 3, 3) in the root frame at home, RGB (N, 3) in 0..1)."""
    names = dict(robot.poses)
    poses = forward(robot, names.get("home"))
    tris, rgb = [], []
    for link in robot.links:
        if link.solid is None:
            continue
        pose = poses[link.name]
        points = link.solid.vertices @ pose[:3, :3].T + pose[:3, 3]
        tris.append(points[link.solid.faces])
        colour = np.asarray(robot.material_rgba(link.material)[:3], dtype=float)
        rgb.append(np.broadcast_to(colour, (len(link.solid.faces), 3)))
    if not tris:
        return np.zeros((0, 3, 3)), np.zeros((0, 3))
    return np.concatenate(tris), np.concatenate(rgb)


def thumbnail_pixels(robot: Robot) -> np.ndarray:
    """(SIZE, SIZE, 3) uint8 RGB."""
    from PIL import Image, ImageDraw

    big = SIZE * SUPER
    image = Image.new("RGB", (big, big), BACKGROUND)
    tris, rgb = _triangles(robot)
    if len(tris):
        right, up, view = _camera()
        normals = np.cross(tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0])
        normals /= np.maximum(np.linalg.norm(normals, axis=1, keepdims=True), 1e-30)
        front = normals @ view < 0  # closed solids: faces turned away are hidden
        tris, rgb, normals = tris[front], rgb[front], normals[front]
        light = -view + np.array([0.0, 0.0, 0.6])
        light /= np.linalg.norm(light)
        shade = AMBIENT + (1 - AMBIENT) * np.clip(normals @ light, 0.0, 1.0)
        colours = np.clip(rgb * shade[:, None] * 255.0, 0, 255).round().astype(int)
        xy = np.stack([tris @ right, -(tris @ up)], axis=-1)  # image y runs down
        lo, hi = xy.reshape(-1, 2).min(axis=0), xy.reshape(-1, 2).max(axis=0)
        scale = 0.9 * big / max(float((hi - lo).max()), 1e-9)
        xy = np.round((xy - (lo + hi) / 2) * scale + big / 2, 3)
        order = np.argsort(-(tris @ view).mean(axis=1), kind="stable")  # far to near
        draw = ImageDraw.Draw(image)
        for i in order:
            draw.polygon([tuple(p) for p in xy[i]], fill=tuple(colours[i]))
    small = image.resize((SIZE, SIZE), Image.Resampling.BOX)
    return np.asarray(small, dtype=np.uint8)


def thumbnail_png(robot: Robot) -> bytes:
    """The thumbnail's PNG bytes."""
    return png_bytes(thumbnail_pixels(robot))
