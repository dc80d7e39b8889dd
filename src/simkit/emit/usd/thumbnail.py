"""The USD thumbnail (`.thumbs/256x256/NAME.usda.png` beside each interface layer, where
Omniverse and the SimReady rules RC.004 and SR.002 look): the robot's visual solids in the
home pose, in the spec's colours, drawn by this module. A software render (a z-buffer over the
solids' triangles, Lambert shading, drawn at twice the size and averaged down) and not MuJoCo's
offscreen render: an emitter reads no OpenGL driver, so the same spec gives the same PNG bytes
on every machine, a machine without EGL or OSMesa still builds the kit, and a solid cut into
other triangles (round-off in a spec) draws the same pixels."""

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


#: a triangle whose pixel box is at most TILE x TILE is rasterised with others in one array
TILE = 8
CHUNK = 20000  # triangles per array (memory: CHUNK x TILE^2 samples)


def _samples(xy: np.ndarray, depth: np.ndarray, first: int, tile: int):
    """(pixel x, pixel y, depth, triangle) of the pixel centres inside each triangle, from a
    tile x tile grid at the corner of its box (xy: (N, 3, 2) pixels; depth: (N, 3))."""
    lo = np.floor(xy.min(axis=1)).astype(np.int64)
    grid = np.stack(np.meshgrid(np.arange(tile), np.arange(tile), indexing="ij"), -1)
    px = lo[:, None, :] + grid.reshape(1, -1, 2)
    centre = px + 0.5
    a, b, c = xy[:, 0, None], xy[:, 1, None], xy[:, 2, None]

    def edge(p, q, r):
        return (q[..., 0] - p[..., 0]) * (r[..., 1] - p[..., 1]) - (q[..., 1] - p[..., 1]) * (
            r[..., 0] - p[..., 0]
        )

    area = edge(a, b, c)
    w0, w1, w2 = edge(b, c, centre), edge(c, a, centre), edge(a, b, centre)
    sign = np.where(area < 0, -1.0, 1.0)
    inside = (w0 * sign >= 0) & (w1 * sign >= 0) & (w2 * sign >= 0) & (np.abs(area) > 1e-12)
    safe = np.where(np.abs(area) > 1e-12, area, 1.0)
    z = (w0 * depth[:, 0, None] + w1 * depth[:, 1, None] + w2 * depth[:, 2, None]) / safe
    tri = np.broadcast_to(np.arange(first, first + len(xy))[:, None], inside.shape)
    return px[inside][:, 0], px[inside][:, 1], z[inside], tri[inside]


def _rasterise(xy: np.ndarray, depth: np.ndarray, size: int) -> np.ndarray:
    """The nearest triangle per pixel (-1: none), a z-buffer: the picture does not depend on
    the order of the triangles, so the same surface cut into other triangles draws the same."""
    span = np.ceil(xy.max(axis=1)) - np.floor(xy.min(axis=1))
    small = np.flatnonzero((span <= TILE).all(axis=1))
    parts = []
    for start in range(0, len(small), CHUNK):
        pick = small[start : start + CHUNK]
        x, y, z, tri = _samples(xy[pick], depth[pick], 0, TILE)
        parts.append((x, y, z, pick[tri]))
    for i in np.flatnonzero(~(span <= TILE).all(axis=1)):
        tile = int(span[i].max()) + 1
        parts.append(_samples(xy[i : i + 1], depth[i : i + 1], int(i), tile))
    x, y, z, tri = (np.concatenate(v) for v in zip(*parts, strict=True))
    keep = (x >= 0) & (y >= 0) & (x < size) & (y < size)
    pixel, z, tri = (y * size + x)[keep], z[keep], tri[keep]
    order = np.lexsort((tri, z, pixel))  # per pixel: nearest, then lowest triangle index
    pixel, tri = pixel[order], tri[order]
    first = np.ones(len(pixel), dtype=bool)
    first[1:] = pixel[1:] != pixel[:-1]
    out = np.full(size * size, -1, dtype=np.int64)
    out[pixel[first]] = tri[first]
    return out.reshape(size, size)


def thumbnail_pixels(robot: Robot) -> np.ndarray:
    """(SIZE, SIZE, 3) uint8 RGB."""
    from PIL import Image

    big = SIZE * SUPER
    canvas = np.empty((big, big, 3), dtype=np.uint8)
    canvas[:] = BACKGROUND
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
        colours = np.clip(rgb * shade[:, None] * 255.0, 0, 255).round().astype(np.uint8)
        xy = np.stack([tris @ right, -(tris @ up)], axis=-1)  # image y runs down
        lo, hi = xy.reshape(-1, 2).min(axis=0), xy.reshape(-1, 2).max(axis=0)
        scale = 0.9 * big / max(float((hi - lo).max()), 1e-9)
        xy = np.round((xy - (lo + hi) / 2) * scale + big / 2, 3)
        nearest = _rasterise(xy, np.round(tris @ view, 9), big)
        drawn = nearest >= 0
        canvas[drawn] = colours[nearest[drawn]]
    small = Image.fromarray(canvas, "RGB").resize((SIZE, SIZE), Image.Resampling.BOX)
    return np.asarray(small, dtype=np.uint8)


def thumbnail_png(robot: Robot) -> bytes:
    """The thumbnail's PNG bytes."""
    return png_bytes(thumbnail_pixels(robot))
