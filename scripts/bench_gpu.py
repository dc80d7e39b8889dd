"""Batched simulation of kits' GPU scenes in MJX (JAX) and MuJoCo Warp (issue 30).

Two modes:

- `python scripts/bench_gpu.py KIT ... [--worlds 4096 8192] [--steps 100]`: steps per second
  of each kit's `mjcf/NAME_mjx.xml` (and `--main` also its main MJCF), with MJX's own humanoid
  from the mujoco-mjx wheel in the same run as the reference, plus the first rollout's time
  (compilation included). MuJoCo Warp runs too where `mujoco_warp` is installed
  (`pip install 'simkit[gpu]'`). One JSON line per model and backend; `--markdown` prints
  docs/performance.md's GPU table.
- `python scripts/bench_gpu.py --probe KIT ...`: the CPU check tests/test_mjx.py runs (JAX on
  the CPU): `mjx.put_model`, contact slots per world against robot.json's budget, a jitted
  rollout of a small batch without NaN, and agreement with C MuJoCo on the same scene.

The devices are JAX's default (a GPU where JAX has one) and Warp's default.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path

import numpy as np

#: seconds simulated by the agreement probe, and the start's joint offsets (rad or m)
PROBE_STEPS = 100
PROBE_OFFSET = 0.02
PROBE_BATCH = 8
#: XLA flags of the probes: the backend's optimisation level 0 and XLA:CPU's older emitters
#: in place of its fusion emitters. A probe is a check on the CPU whose time is the compiling
#: of one rollout (its 800 steps take under a second): with these, Asimov's probe takes 44 s
#: of CPU instead of 75 s, ecn_2r's compilation 5.5 s instead of 21 s, and the numbers stay
#: (Asimov's agreement with C MuJoCo 1.2454e-5 against 1.2461e-5). The benchmark keeps XLA's
#: defaults: there the steps count. tests/conftest.py gives the kit's MJX demo the same flags.
PROBE_XLA_FLAGS = "--xla_backend_optimization_level=0 --xla_cpu_use_fusion_emitters=false"


def humanoid() -> Path:
    """MJX's benchmark humanoid, shipped in the mujoco-mjx wheel."""
    from mujoco import mjx

    return Path(mjx.__file__).parent / "test_data" / "humanoid" / "humanoid.xml"


def gpu_scene(kit: Path) -> Path:
    """The kit's GPU scene, from robot.json."""
    doc = json.loads((kit / "robot.json").read_text(encoding="utf-8"))
    return kit / doc["files"]["mjcf_mjx"]


def start_state(model, seed: int = 0):
    """MjData at the first keyframe (or qpos0), joints offset by up to `PROBE_OFFSET` within
    their ranges (seeded), servos holding the keyframe."""
    import mujoco

    data = mujoco.MjData(model)
    if model.nkey:
        mujoco.mj_resetDataKeyframe(model, data, 0)
    rng = np.random.default_rng(seed)
    for j in range(model.njnt):
        if model.jnt_type[j] in (mujoco.mjtJoint.mjJNT_HINGE, mujoco.mjtJoint.mjJNT_SLIDE):
            adr = model.jnt_qposadr[j]
            value = data.qpos[adr] + rng.uniform(-PROBE_OFFSET, PROBE_OFFSET)
            if model.jnt_limited[j]:
                value = np.clip(value, *model.jnt_range[j])
            data.qpos[adr] = value
    mujoco.mj_forward(model, data)
    return data


def mjx_rollout(model, steps: int):
    """A jitted function: a batch of MJX states -> the batch after `steps` steps."""
    import jax
    from mujoco import mjx

    mx = mjx.put_model(model)

    def rollout(d):
        return jax.lax.scan(lambda d, _: (mjx.step(mx, d), None), d, None, length=steps)[0]

    return mx, jax.jit(jax.vmap(rollout))


def batch_of(model, data, worlds: int):
    """`worlds` copies of `data` as one batched MJX state."""
    import jax
    import jax.numpy as jp
    from mujoco import mjx

    one = mjx.put_data(model, data)
    return jax.tree_util.tree_map(lambda x: jp.broadcast_to(x, (worlds, *x.shape)), one)


def contact_slots(mx) -> int:
    """Contact slots per world MJX allocates for a model."""
    from mujoco import mjx

    data = mjx.make_data(mx)
    impl = getattr(data, "_impl", data)
    return int(impl.contact.dist.shape[0])


def probe(kit: Path) -> dict:
    """The CPU check of one kit's GPU scene (see the module docstring)."""
    import jax
    import mujoco

    path = gpu_scene(kit)
    model = mujoco.MjModel.from_xml_path(str(path))
    budget = json.loads((kit / "robot.json").read_text())["gpu_scene"]["contact_slots"]
    data = start_state(model)
    started = time.perf_counter()
    mx, rollout = mjx_rollout(model, PROBE_STEPS)
    out = rollout(batch_of(model, data, PROBE_BATCH))
    jax.block_until_ready(out)
    compile_s = time.perf_counter() - started
    reference = mujoco.MjData(model)
    reference.qpos[:], reference.qvel[:], reference.ctrl[:] = data.qpos, data.qvel, data.ctrl
    for _ in range(PROBE_STEPS):
        mujoco.mj_step(model, reference)
    qpos = np.asarray(out.qpos)
    return {
        "kit": kit.name,
        "file": path.relative_to(kit).as_posix(),
        "contact_slots": contact_slots(mx),
        "budget": budget,
        "nan": bool(np.isnan(qpos).any() or np.isnan(np.asarray(out.qvel)).any()),
        "first_rollout_s": round(compile_s, 1),
        "agreement": float(np.max(np.abs(qpos[0] - reference.qpos))),
        "steps": PROBE_STEPS,
        "x64": bool(jax.config.jax_enable_x64),
    }


def mjx_rate(path: Path, worlds: int, steps: int) -> dict:
    """MJX steps per second (worlds x steps / wall time of the second rollout)."""
    import jax
    import mujoco

    model = mujoco.MjModel.from_xml_path(str(path))
    mx, rollout = mjx_rollout(model, steps)
    state = batch_of(model, start_state(model), worlds)
    started = time.perf_counter()
    jax.block_until_ready(rollout(state))
    first = time.perf_counter() - started
    started = time.perf_counter()
    jax.block_until_ready(rollout(state))
    wall = time.perf_counter() - started
    return {
        "backend": "mjx",
        "device": str(jax.devices()[0]),
        "worlds": worlds,
        "steps_per_s": worlds * steps / wall,
        "first_rollout_s": first,
        "contact_slots": contact_slots(mx),
    }


def numeric(model, name: str) -> int | None:
    """The model's custom numeric `name`, or None."""
    import mujoco

    index = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_NUMERIC, name)
    return None if index < 0 else int(model.numeric_data[model.numeric_adr[index]])


def warp_sizes(model) -> dict[str, int]:
    """The file's own sizes for MuJoCo Warp (contacts and constraint rows per world): the
    custom numerics `warp_nconmax` / `warp_njmax` (a GPU scene writes them there so that C
    MuJoCo sizes its own arena), else `<size nconmax njmax>`; Warp's defaults where neither."""
    out = {k: numeric(model, f"warp_{k}") for k in ("nconmax", "njmax")}
    for k in out:
        if out[k] is None and getattr(model, k) >= 0:
            out[k] = int(getattr(model, k))
    return {k: v for k, v in out.items() if v is not None}


def warp_rate(path: Path, worlds: int, steps: int) -> dict | None:
    """MuJoCo Warp steps per second, or None where mujoco_warp is not installed."""
    try:
        import mujoco_warp as mjw
        import warp as wp
    except ImportError:
        return None
    import mujoco

    model = mujoco.MjModel.from_xml_path(str(path))
    data = start_state(model)
    m = mjw.put_model(model)
    d = mjw.put_data(model, data, nworld=worlds, **warp_sizes(model))
    started = time.perf_counter()
    mjw.step(m, d)
    wp.synchronize()
    first = time.perf_counter() - started
    started = time.perf_counter()
    for _ in range(steps):
        mjw.step(m, d)
    wp.synchronize()
    wall = time.perf_counter() - started
    return {
        "backend": "mujoco_warp",
        "device": str(wp.get_device()),
        "worlds": worlds,
        "steps_per_s": worlds * steps / wall,
        "first_rollout_s": first,
        "nan": bool(np.isnan(d.qpos.numpy()).any()),
    }


def warp_probe(kit: Path, steps: int = 10) -> dict:
    """MuJoCo Warp on the kit's GPU scene (Warp's default device, the CPU without a GPU):
    `steps` steps of 2 worlds with the file's own nconmax and njmax."""
    import mujoco
    import mujoco_warp as mjw
    import warp as wp

    model = mujoco.MjModel.from_xml_path(str(gpu_scene(kit)))
    m = mjw.put_model(model)
    d = mjw.put_data(model, start_state(model), nworld=2, **warp_sizes(model))
    for _ in range(steps):
        mjw.step(m, d)
    wp.synchronize()
    return {
        "kit": kit.name,
        "device": str(wp.get_device()),
        "nan": bool(np.isnan(d.qpos.numpy()).any()),
        "nefc": int(d.nefc.numpy().max()),
        "njmax": warp_sizes(model)["njmax"],
    }


def bench(models: dict[str, Path], worlds: list[int], steps: int) -> list[dict]:
    rows = []
    for name, path in models.items():
        for n in worlds:
            for measure in (mjx_rate, warp_rate):
                row = measure(path, n, steps)
                if row is not None:
                    rows.append({"model": name, **row})
                    print(json.dumps(rows[-1]), flush=True)
    return rows


def markdown(rows: list[dict]) -> str:
    """The GPU table: steps/s and the ratio to MJX's humanoid at the same world count."""
    ref = {(r["backend"], r["worlds"]): r["steps_per_s"] for r in rows if r["model"] == "humanoid"}
    lines = [
        "| model | backend | device | worlds | steps/s | ratio to humanoid | first rollout (s) |",
        "|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        ratio = r["steps_per_s"] / ref[(r["backend"], r["worlds"])]
        lines.append(
            f"| {r['model']} | {r['backend']} | {r['device']} | {r['worlds']} | "
            f"{r['steps_per_s'] / 1e6:.3f} M | {ratio:.2f} | {r['first_rollout_s']:.1f} |"
        )
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("kits", nargs="+", type=Path, help="kit folders (NAME_description)")
    parser.add_argument("--probe", action="store_true", help="the CPU check, one JSON line a kit")
    parser.add_argument("--warp-probe", action="store_true", help="MuJoCo Warp, 10 steps a kit")
    parser.add_argument("--worlds", nargs="+", type=int, default=[4096, 8192])
    parser.add_argument("--steps", type=int, default=100)
    parser.add_argument("--main", action="store_true", help="also each kit's main MJCF")
    parser.add_argument("--markdown", action="store_true", help="print the table at the end")
    args = parser.parse_args(argv)
    if args.probe or args.warp_probe:
        if args.probe:  # before JAX is imported: XLA reads its flags once
            os.environ["XLA_FLAGS"] = f"{PROBE_XLA_FLAGS} {os.environ.get('XLA_FLAGS', '')}"
        for kit in args.kits:
            print(json.dumps(probe(kit) if args.probe else warp_probe(kit)), flush=True)
        return 0
    models = {"humanoid": humanoid()}
    for kit in args.kits:
        models[gpu_scene(kit).stem] = gpu_scene(kit)
        if args.main:
            doc = json.loads((kit / "robot.json").read_text(encoding="utf-8"))
            main_file = kit / doc["files"].get("mjcf_scene", doc["files"]["mjcf"])
            models[main_file.stem] = main_file
    rows = bench(models, args.worlds, args.steps)
    if args.markdown:
        print(markdown(rows))
    return 0


if __name__ == "__main__":
    sys.exit(main())
