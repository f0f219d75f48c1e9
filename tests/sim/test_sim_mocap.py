"""SimulatedMocap / SimulatedPerception (sim/mocap.py), in simulated time: poses sampled at rate_hz,
released latency_s later stamped when measured, dropped as often as asked, noise as set; boxes seen in
the robot's heading frame."""

from __future__ import annotations

import math

import numpy as np
import pytest

from g1_control.sim.mocap import MocapConfig, SimulatedMocap, SimulatedPerception


def test_poses_arrive_late_stamped_when_measured_with_the_dropouts_and_noise_asked_for():
    mocap = SimulatedMocap(MocapConfig(rate_hz=100.0, noise_m=0.01, latency_s=0.1, dropout=0.2, seed=1))
    out = []
    for k in range(5000):  # 10 s at 500 Hz, the robot at x = t
        t = k * 0.002
        for stamp, pos, _quat in mocap.sample(t, np.array([t, 0.0, 0.75]), np.array([1.0, 0.0, 0.0, 0.0])):
            out.append((t, stamp, pos))
    assert mocap.measured == pytest.approx(1000, abs=2)
    assert mocap.dropped / mocap.measured == pytest.approx(0.2, abs=0.04)
    assert 0 <= mocap.measured - mocap.dropped - len(out) <= 10  # the last 0.1 s still in flight
    delays = np.array([t - stamp for t, stamp, _ in out])
    assert delays.min() >= 0.1 - 1e-9 and delays.max() < 0.1 + 0.002 + 1e-9
    errors = np.array([pos[0] - stamp for _, stamp, pos in out])  # truth at the stamp: x = stamp
    assert errors.std() == pytest.approx(0.01, rel=0.15) and abs(errors.mean()) < 0.002


def test_perception_sees_a_box_in_the_robots_heading_frame():
    seen = SimulatedPerception(MocapConfig(rate_hz=10.0))
    facing_y = np.array([math.cos(math.pi / 4), 0.0, 0.0, math.sin(math.pi / 4)])
    [(stamp, objects)] = seen.sample(0.0, np.array([1.0, 1.0, 0.75]), facing_y,
                                     {"box": (np.array([1.0, 2.0, 0.85]), np.array([1.0, 0.0, 0.0, 0.0]))})
    position, quat = objects["box"]
    assert stamp == 0.0 and position == pytest.approx([1.0, 0.0, 0.10])  # 1 m straight ahead, 10 cm up
    assert quat == pytest.approx(np.array([math.cos(-math.pi / 4), 0.0, 0.0, math.sin(-math.pi / 4)]))


def test_bad_settings_are_refused():
    with pytest.raises(ValueError, match="mocap dropout: 1.0 is outside"):
        SimulatedMocap(MocapConfig(dropout=1.0))
    with pytest.raises(ValueError, match="mocap latency_s: must be >= 0"):
        SimulatedMocap(MocapConfig(latency_s=-0.1))
