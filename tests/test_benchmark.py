"""The benchmark pick-and-place cycle (kit page, 000_5f76ade803e16979.txt, "Benchmark
cycle"): the 1 kg trajectory files, their limits and TCP points, and the MJCF torque check."""

from __future__ import annotations

import csv
import json
import math
import shutil

import numpy as np
import pytest

from simkit.check.kit import Kit
from simkit.check.motion import check_benchmark
from simkit.derive import benchmark


@pytest.fixture(scope="module")
def kit(rosie_1000) -> Kit:
    return Kit.open(rosie_1000.kit_dir)


def _samples(kit: Kit) -> tuple[list[str], np.ndarray]:
    path = kit.path(kit.doc["benchmarks"]["trajectory_files"]["cycle_1kg"]["csv"])
    assert path.name == f"{kit.name}_cycle_1kg.csv"
    with path.open(encoding="utf-8", newline="") as handle:
        rows = list(csv.reader(handle))
    return rows[0], np.array(rows[1:], dtype=float)


@pytest.fixture(scope="module")
def samples(kit) -> tuple[list[str], np.ndarray]:
    return _samples(kit)


#: Kit page, "Benchmark cycle": low points 50 mm above base_link, 75.5 mm on the Rosie 1400.
LOW_POINTS = {"rosie_600": 0.050, "rosie_1000": 0.050, "rosie_1400": 0.0755}


@pytest.mark.parametrize("name", sorted(LOW_POINTS))
def test_path_points_follow_the_page(kit_factory, name):
    kit = Kit.open(kit_factory(name).kit_dir)
    path = kit.doc["benchmarks"]["path"]
    points = path["tcp_points_base_link_m"]
    a_low, a_high, b_high, b_low = (np.array(points[n]) for n in benchmark.POINTS)
    assert np.linalg.norm(b_low - a_low) == pytest.approx(0.305)  # along y
    assert (a_low + b_low)[:2] / 2 == pytest.approx([0.350, 0.0])  # 350 mm out on +x
    assert a_low[2] == b_low[2] == pytest.approx(LOW_POINTS[name])  # above base_link
    assert a_high - a_low == pytest.approx([0, 0, 0.025])
    assert b_high - b_low == pytest.approx([0, 0, 0.025])
    assert path["sequence"] == ["A_low", "A_high", "B_high", "B_low", "B_high", "A_high", "A_low"]
    assert kit.doc["benchmarks"]["tcp"]["xyz"] == [0, 0, 0.05]
    assert np.linalg.norm(b_low - a_low) == pytest.approx(abs(b_low[1] - a_low[1]))  # along y
    # tool straight down with its heading kept, reached by the trajectory's own q (robot.json FK)
    bench = kit.doc["benchmarks"]
    _, data = _samples(kit)
    ends = np.rint(np.cumsum([0.0, *bench["segment_times"]["cycle_1kg"]]) / 0.001).astype(int)
    for row in ends:
        rotation = kit.fk(data[row, 1:7])[:3, :3]
        assert np.abs(rotation - np.diag([1.0, -1.0, -1.0])).max() < 1e-9
    for cycle in ("cycle_1kg", "cycle_rated"):
        payload = bench["payload"][cycle]
        x, y, z = payload["com_xyz"]  # 100 mm along the tool axis, 50 mm off it
        assert z == pytest.approx(0.100) and math.hypot(x, y) == pytest.approx(0.050)
        assert payload["inertia_diag"] == pytest.approx([payload["mass"] * 0.1**2 / 6] * 3)
    assert bench["payload"]["cycle_1kg"]["mass"] == 1
    assert bench["payload"]["cycle_rated"]["mass"] == kit.doc["payload"]["rated"]
    check = bench["kit_model_check"]
    assert 0 < max(check["fraction"]) <= 1


def test_csv_at_1ms_within_speed_and_acceleration(kit, samples):
    header, data = samples
    bench = kit.doc["benchmarks"]
    names = [j["name"] for j in kit.joints]
    assert header == (
        ["t"]
        + [f"{k}_{n}" for k in ("q", "qd", "qdd") for n in names]
        + ["tcp_x", "tcp_y", "tcp_z"]
    )
    t = data[:, 0]
    assert np.diff(t) == pytest.approx(np.full(len(t) - 1, 0.001), abs=1e-12)
    assert t[-1] == pytest.approx(bench["cycle_time"]["cycle_1kg"])
    qd, qdd = data[:, 7:13], data[:, 13:19]
    vmax = np.array([j["max_velocity"] for j in kit.joints])
    amax = np.array(bench["acceleration"]["cycle_1kg"]["rad_s2"])
    assert np.all(np.abs(qd) <= vmax * (1 + 1e-9))
    assert np.all(np.abs(qdd) <= amax * (1 + 1e-9))
    assert np.abs(qd).max(axis=0) @ (1 / vmax) > 0  # it moves
    # the slowest joint of the long moves cruises near max_velocity
    assert (np.abs(qd) / vmax).max() > 0.95
    # velocity is the integral of acceleration (trapezoids), position of velocity
    assert np.cumsum(qdd[:-1], axis=0)[-1] * 0.001 == pytest.approx(np.zeros(6), abs=1e-6)
    assert np.abs(np.diff(data[:, 1:7], axis=0) - (qd[:-1] + qd[1:]) / 2 * 0.001).max() < 1e-4


def test_tcp_passes_through_the_six_points(kit, samples):
    _, data = samples
    bench = kit.doc["benchmarks"]
    ends = np.rint(np.cumsum([0.0, *bench["segment_times"]["cycle_1kg"]]) / 0.001).astype(int)
    points = bench["path"]["tcp_points_base_link_m"]
    offset = np.array([0, 0, 0.05, 1.0])
    for row, name in zip(ends, bench["path"]["sequence"], strict=True):
        assert np.abs(data[row, 19:22] - points[name]).max() < 1e-4
        tcp = (kit.fk(data[row, 1:7]) @ offset)[:3]  # from robot.json FK, not the column
        assert np.abs(tcp - points[name]).max() < 1e-4
        assert np.abs(data[row, 7:13]).max() == 0  # at rest


def test_segments_take_the_slowest_joints_time(kit):
    bench = kit.doc["benchmarks"]
    poses = dict(zip(benchmark.POINTS, bench["path"]["joint_poses"]["q"], strict=True))
    acc = bench["acceleration"]["cycle_1kg"]["rad_s2"]
    vmax = [j["max_velocity"] for j in kit.joints]
    sequence = bench["path"]["sequence"]
    for a, b, duration in zip(
        sequence[:-1], sequence[1:], bench["segment_times"]["cycle_1kg"], strict=True
    ):
        slowest = max(
            benchmark.trapezoid_time(abs(y - x), ac, v)
            for x, y, ac, v in zip(poses[a], poses[b], acc, vmax, strict=True)
        )
        assert slowest <= duration < slowest + 0.001
    assert bench["cycle_time"]["cycle_rated"] >= bench["cycle_time"]["cycle_1kg"]


def test_trapezoid_helpers():
    assert benchmark.trapezoid_time(1.0, 2.0, 10.0) == pytest.approx(2 * math.sqrt(0.5))
    assert benchmark.trapezoid_time(4.0, 2.0, 1.0) == pytest.approx(4.0 + 0.5)
    v = benchmark.cruise_speed(4.0, 2.0, 5.0)
    assert v * 5.0 - v * v / 2.0 == pytest.approx(4.0)


def test_kit_model_check_within_forcerange(kit):
    check = kit.doc["benchmarks"]["kit_model_check"]
    fractions = np.array(check["fraction"])
    assert np.all(fractions > 0) and np.all(fractions <= 1)
    assert fractions == pytest.approx(np.array(check["max_torque"]) / check["forcerange"])
    assert check["forcerange"] == [a["forcerange"] for a in kit.doc["actuators"]]
    findings = {f.check: f for f in check_benchmark(kit)}
    assert findings["benchmark.kit_model_check"].ok  # recomputed from the written MJCF
    # a heavier payload needs more torque somewhere
    rated = kit.doc["benchmarks"]["rated_cycle_torque"]
    assert np.any(np.array(rated["max_torque"]) > check["max_torque"])


def test_json_trajectory_matches_csv(kit, samples):
    _, data = samples
    files = kit.doc["benchmarks"]["trajectory_files"]["cycle_1kg"]
    doc = json.loads(kit.path(files["json"]).read_text(encoding="utf-8"))
    assert doc["dt"] == 0.001 and len(doc["segments"]) == 6
    assert np.array_equal(np.asarray(doc["q"]), data[:, 1:7])
    assert np.array_equal(np.asarray(doc["tcp"]), data[:, 19:22])


def test_check_catches_columns_that_do_not_describe_one_motion(kit, tmp_path):
    """Every other sample dropped (the motion played twice as fast) keeps the qd and qdd
    columns within their bounds, but q no longer integrates qd and qd changes twice as fast
    as the benchmark acceleration allows: the check must fail."""
    copy = tmp_path / "kit"
    shutil.copytree(kit.root, copy)
    path = copy / kit.doc["benchmarks"]["trajectory_files"]["cycle_1kg"]["csv"]
    lines = path.read_text(encoding="utf-8").splitlines()
    rows = [line.split(",") for line in lines[1::2]]
    for k, row in enumerate(rows):
        row[0] = f"{k * 0.001:.3f}"
    path.write_text("\n".join([lines[0], *(",".join(r) for r in rows)]) + "\n")
    findings = {f.check: f for f in check_benchmark(Kit.open(copy))}
    assert findings["benchmark.max_velocity"].ok and findings["benchmark.acceleration"].ok
    assert findings["benchmark.dt"].ok
    assert not findings["benchmark.q_integrates_qd"].ok
    assert not findings["benchmark.qd_change"].ok
    # shorter than its segment table: a failed finding, not an IndexError
    assert not findings["benchmark.tcp_points"].ok
    original = {f.check: f for f in check_benchmark(kit)}
    assert original["benchmark.q_integrates_qd"].ok and original["benchmark.qd_change"].ok
