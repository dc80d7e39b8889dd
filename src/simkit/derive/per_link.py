"""The slow per-link derive steps, cached and parallel: link solids and collision pieces.

Issue 3 ("Parallel work and progress"): CoACD runs one process per link with
`OMP_NUM_THREADS=1` (1.45x the throughput of threaded runs on 2 cores), `--jobs` workers
(default: the cores this process may use), a progress bar on a terminal and plain log lines
otherwise. Every result goes through the content-addressed cache (`cache.py`), so a warm
rebuild computes nothing here and never imports CoACD or trimesh.
"""

from __future__ import annotations

import os
import sys
import time
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path

import numpy as np

from simkit.errors import SpecError
from simkit.kitio.cache import Cache, decode_json, encode_json, make_key
from simkit.model.robot import Link, Mesh, Robot, Shape, canonical_triangles

Progress = Callable[[str], None]

SOLID_STEP, SOLID_VERSION = "link_solid", 1
#: 4: pieces whose manifold3d hull folds are qhull's exact hull (3292af1 changed that without a
#: new version, so caches from before kept folded pieces that fail `collision.convex`);
#: 5: every piece's triangles in the canonical order (a cache from before holds manifold3d's
#: varying order, and a cached build would differ from an uncached one)
COLLISION_STEP, COLLISION_VERSION = "collision", 5
HULL_STEP, HULL_VERSION = "given_hull", 1


def default_jobs() -> int:
    """Cores this process may run on."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # pragma: no cover - macOS, Windows
        return max(1, os.cpu_count() or 1)


# --- link solids ------------------------------------------------------------------------


def _solid_key(link: Link, base_dir: Path) -> str:
    from dataclasses import asdict

    from simkit.derive.solids import CIRCULAR_SEGMENTS, PARTS_RULE, SPHERE_SEGMENTS

    inputs = []
    for shape in link.shapes:
        if shape.kind == "mesh" and shape.file:
            path = base_dir / shape.file
            inputs.append(
                path.read_bytes() if path.is_file() else b"missing:" + shape.file.encode()
            )
    libraries = ("manifold3d", "trimesh") if inputs else ("manifold3d",)
    params = {
        "shapes": [asdict(s) for s in link.shapes],
        "segments": CIRCULAR_SEGMENTS,
        "sphere_segments": SPHERE_SEGMENTS,
    }
    if inputs:  # a mesh file's parts are united (solids.py): primitive links keep their keys
        params["mesh_parts"] = PARTS_RULE
    return make_key(SOLID_STEP, SOLID_VERSION, inputs, params, libraries)


def derive_solids(robot: Robot, base_dir: Path, cache: Cache) -> Robot:
    """Each link's visual solid from its primitives, through the cache (CSG is ~0.2 s a link
    and needs manifold3d, plus trimesh for mesh files)."""
    from simkit.derive.solids import link_solid

    links = []
    for link in robot.links:
        if not link.shapes:
            links.append(link)
            continue
        key = _solid_key(link, base_dir)
        found = cache.get(SOLID_STEP, key)
        if found is not None:
            solid = Mesh.of(found["vertices"], found["faces"])
        else:
            solid = link_solid(link.shapes, base_dir)
            cache.put(SOLID_STEP, key, {"vertices": solid.vertices, "faces": solid.faces})
        links.append(replace(link, solid=solid))
    links = [
        replace(
            link, given_hulls=tuple(_given_hull(s, base_dir, cache) for s in link.collision_shapes)
        )
        if link.collision_shapes
        else link
        for link in links
    ]
    return replace(robot, links=tuple(links))


def _given_hull(shape: Shape, base_dir: Path, cache: Cache) -> Mesh:
    """`_shape_hull` through the cache, keyed by the mesh file's bytes and the placement: a
    humanoid's 24 hulls (46,734 triangles) took 2.8 s of a 4.9 s warm rebuild."""
    from dataclasses import asdict

    if shape.kind != "mesh":
        return _shape_hull(shape, base_dir)
    path = base_dir / (shape.file or "")
    inputs = [path.read_bytes()] if path.is_file() else []
    key = make_key(HULL_STEP, HULL_VERSION, inputs, {"shape": asdict(shape)}, ("manifold3d",))
    found = cache.get(HULL_STEP, key) if inputs else None
    if found is not None:
        return Mesh.of(found["vertices"], found["faces"])
    hull = _shape_hull(shape, base_dir)
    cache.put(HULL_STEP, key, {"vertices": hull.vertices, "faces": hull.faces})
    return hull


def _shape_hull(shape: Shape, base_dir: Path) -> Mesh:
    """The convex hull of one `given` collision shape, placed in the link frame (m). Binary
    STL files are read without trimesh; any mesh may be open (only its hull is used)."""
    import manifold3d as mf

    from simkit.derive.solids import primitive_solid, to_mesh
    from simkit.kitio.stl import from_stl
    from simkit.model.kinematics import rpy_matrix

    if shape.kind != "mesh":
        return to_mesh(primitive_solid(shape).hull())
    path = base_dir / (shape.file or "")
    if not path.is_file():
        raise SpecError(str(base_dir), None, "collision_shapes.file", f"not found: {shape.file}")
    points = from_stl(path.read_bytes()).vertices * shape.scale
    points = points @ rpy_matrix(shape.rpy).T + np.asarray(shape.xyz)
    return canonical_faces(to_mesh(mf.Manifold.hull_points(np.asarray(points, np.float64))))


def canonical_faces(mesh: Mesh) -> Mesh:
    """The same mesh with its triangles in one fixed order (`canonical_triangles`): a hull's
    varying order changed the cache key of every later step (the first rebuild of an
    imported robot missed) and the collision STL bytes."""
    return Mesh.of(mesh.vertices, canonical_triangles(mesh.faces))


# --- collision --------------------------------------------------------------------------


def _description(given: bool = False) -> dict:
    from simkit.derive import collision

    out = {
        "methods": {
            "convex": "a union of convex primitives: each primitive's own convex mesh, exact; "
            f"above {collision.MAX_PIECES} pieces, the pair whose merged hull adds the least "
            "volume is merged, repeatedly",
            "coacd": "CoACD on a coarse manifold copy of the solid (manifold3d simplify, "
            f"{collision.COARSE_TOLERANCE} m), then every visual vertex and face centre outside "
            "the hulls is added to the hull it lies least far outside",
            "primitives": "the spec's collision primitives, written as primitives",
            "mesh": "the visual mesh (engines collide with its convex hull)",
        },
        "coacd_parameters": collision.COACD_PARAMS,
        "hull_volume_ratio": "volume of the union of the pieces / volume of the visual solid",
        "hull_volume_sum_ratio": "sum of the pieces' volumes / volume of the visual solid",
        "coverage": "share of the visual solid's volume inside the pieces",
        "visual_to_collision_max_m": "largest distance from the visual surface (vertices and "
        "face centres) to the surface of the pieces' union",
    }
    if given:
        out["methods"]["given"] = (
            "the spec's collision_shapes (an imported URDF's collision geometry): one convex hull "
            "each, merged as `convex` above the limit, then grown like `coacd` to cover the visual"
        )
    return out


def _collision_key(link: Link, seed: int) -> str:
    from simkit.derive import collision

    inputs = (
        [] if link.solid is None else [link.solid.vertices.tobytes(), link.solid.faces.tobytes()]
    )
    inputs += [h.vertices.tobytes() for h in link.given_hulls]
    return make_key(
        COLLISION_STEP,
        COLLISION_VERSION,
        inputs,
        collision.key_params(link, seed),
        ("coacd", "manifold3d", "numpy"),
    )


def _pack(pieces: tuple[Mesh, ...], report: dict) -> dict[str, np.ndarray]:
    verts = [p.vertices for p in pieces]
    faces = [p.faces for p in pieces]
    return {
        "vertices": np.concatenate(verts) if verts else np.zeros((0, 3)),
        "faces": np.concatenate(faces) if faces else np.zeros((0, 3), np.int64),
        "counts": np.array(
            [[len(v), len(f)] for v, f in zip(verts, faces, strict=True)], np.int64
        ).reshape(-1, 2),
        "report": encode_json(report),
    }


def _unpack(arrays: dict[str, np.ndarray]) -> tuple[tuple[Mesh, ...], dict]:
    pieces, v0, f0 = [], 0, 0
    for nv, nf in arrays["counts"]:
        pieces.append(Mesh.of(arrays["vertices"][v0 : v0 + nv], arrays["faces"][f0 : f0 + nf]))
        v0, f0 = v0 + int(nv), f0 + int(nf)
    return tuple(pieces), decode_json(arrays["report"])  # type: ignore[return-value]


def _init_worker() -> None:
    """Pool workers: one OpenMP thread each, set before CoACD is first imported."""
    os.environ["OMP_NUM_THREADS"] = "1"


def _collision_job(link: Link, seed: int) -> tuple[tuple[Mesh, ...], dict, int, float]:
    """Worker side: pieces, report, CoACD runs done, seconds taken."""
    from simkit.derive import collision

    start, runs = time.perf_counter(), collision.COACD_RUNS
    pieces, report = collision.link_collision(link, seed)
    return pieces, report, collision.COACD_RUNS - runs, time.perf_counter() - start


class _Reporter:
    """A rich progress bar on a terminal, one log line per finished link otherwise."""

    def __init__(self, total: int, progress: Progress | None) -> None:
        self.say = progress
        self.bar = None
        if progress is not None and total and sys.stderr.isatty():
            from rich.console import Console
            from rich.progress import BarColumn, MofNCompleteColumn, Progress, TimeElapsedColumn

            self.bar = Progress(
                "collision",
                BarColumn(),
                MofNCompleteColumn(),
                TimeElapsedColumn(),
                console=Console(stderr=True),
                transient=True,
            )
            self.task = self.bar.add_task("collision", total=total)
            self.bar.start()

    def done(self, link: str, report: dict, seconds: float) -> None:
        if self.bar is not None:
            self.bar.advance(self.task)
        elif self.say is not None:
            self.say(
                f"collision {link}: {report.get('method')}, {report.get('pieces')} pieces, "
                f"{seconds:.1f} s"
            )

    def close(self) -> None:
        if self.bar is not None:
            self.bar.stop()


def derive_collision(
    robot: Robot, cache: Cache, jobs: int | None = None, progress: Progress | None = None
) -> Robot:
    """Collision pieces and quality reports for every link. Cache misses that need CoACD run
    in a process pool (when there are two or more and `jobs` > 1); the rest run here."""
    from simkit.derive import collision

    results: dict[str, tuple[tuple[Mesh, ...], dict]] = {}
    misses: list[tuple[Link, str]] = []
    for link in robot.links:
        key = _collision_key(link, robot.seed)
        found = cache.get(COLLISION_STEP, key)
        if found is not None:
            results[link.name] = _unpack(found)
        else:
            misses.append((link, key))
    slow = [(link, key) for link, key in misses if collision.method_of(link) == "coacd"]
    fast = [(link, key) for link, key in misses if collision.method_of(link) != "coacd"]
    jobs = default_jobs() if jobs is None else max(1, jobs)
    reporter = _Reporter(len(misses), progress)
    pool = None
    try:
        futures = {}
        here = fast + slow
        if len(slow) > 1 and jobs > 1:
            import multiprocessing
            from concurrent.futures import ProcessPoolExecutor

            pool = ProcessPoolExecutor(
                max_workers=min(jobs, len(slow)),
                initializer=_init_worker,
                mp_context=multiprocessing.get_context("spawn"),
            )
            futures = {
                link.name: (pool.submit(_collision_job, link, robot.seed), key)
                for link, key in slow
            }
            here = fast
        for link, key in here:  # runs here while the pool works on the CoACD links
            pieces, report, _runs, seconds = _collision_job(link, robot.seed)
            _store(cache, key, results, link.name, pieces, report)
            reporter.done(link.name, report, seconds)
        for name, (future, key) in futures.items():
            pieces, report, runs, seconds = future.result()
            collision.COACD_RUNS += runs
            _store(cache, key, results, name, pieces, report)
            reporter.done(name, report, seconds)
    finally:
        if pool is not None:
            pool.shutdown(cancel_futures=True)
        reporter.close()
    links = tuple(
        replace(link, collision=results[link.name][0], collision_report=results[link.name][1])
        for link in robot.links
    )
    geometry = [{"name": link.name, "collision": link.collision_report} for link in links]
    uses_coacd = any(link.collision_report.get("method") == "coacd" for link in links)
    seeds = {**robot.products.seeds, **({"coacd": robot.seed} if uses_coacd else {})}
    products = replace(
        robot.products,
        geometry_links=geometry,
        geometry_collision=_description(given=any(link.given_hulls for link in links)),
        seeds=seeds,
    )
    return replace(robot, links=links, products=products)


def _store(
    cache: Cache, key: str, results: dict, name: str, pieces: tuple[Mesh, ...], report: dict
) -> None:
    cache.put(COLLISION_STEP, key, _pack(pieces, report))
    results[name] = (pieces, report)
