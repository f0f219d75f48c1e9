"""`g1 hands status|grasp` against the emulated Dex3-1 hands on lo (own partition), judged by the
emulator's ground truth."""

from __future__ import annotations

import json
import os
import uuid

import numpy as np
import pytest

from g1_control.cli.main import main
from g1_control.robot import dex3


@pytest.fixture
def emulated(request):
    from g1_control.sim.dex3_hands import Dex3HandsEmulator

    partition = f"g1hands-{os.getpid()}-{uuid.uuid4().hex[:8]}"
    sides = getattr(request, "param", dex3.SIDES)
    emulator = Dex3HandsEmulator("lo", 1, partition=partition, sides=sides).start()
    yield emulator, partition
    emulator.close()


def test_grasp_closes_on_the_object_within_the_limit_and_releases(emulated, capsys):
    emulator, partition = emulated
    contact = emulator.hold_object("left", closure=0.4)
    rc = main(["hands", "grasp", "--side", "left", "--torque-limit", "0.4", "--hold-s", "0.3", "--json",
               "--partition", partition])
    out = json.loads(capsys.readouterr().out)
    assert rc == 0 and out["tripped"] is None and out["done_s"] is not None
    closing = dex3.hand_limits("left").closing_sign != 0
    stops = [f["stop"] for f in out["fingers"].values()]
    assert [s for s, c in zip(stops, closing) if c] == ["touched"] * 6
    truth = emulator.truth("left")
    assert np.max(truth.max_contact_tau_nm) <= 0.4  # never squeezed past the limit
    assert np.all(np.abs(truth.q_rad[closing] - contact[closing]) < 0.05)
    assert truth.last_command is not None and truth.last_command.is_damping  # released on exit


@pytest.mark.parametrize("emulated", [("left",)], indirect=True)
def test_status_names_a_silent_hand(emulated, capsys):
    _, partition = emulated
    assert main(["hands", "status", "--seconds", "0.2", "--partition", partition]) == 1
    assert "no HandState_ from the right Dex3-1 hand within 1.0 s on rt/dex3/right/state" in capsys.readouterr().err


def test_a_torque_limit_above_the_motors_is_refused(emulated, capsys):
    _, partition = emulated
    assert main(["hands", "grasp", "--side", "right", "--torque-limit", "3", "--partition", partition]) == 1
    assert "torque_limit_nm must be in (0, 1.4] N m" in capsys.readouterr().err


def test_grasp_against_g1_sim_robot_with_hands_in_another_process(capsys):
    """`g1 sim-robot --hands dex3 --hand-object 0.5` as its own process, `g1 hands grasp` here."""
    import subprocess
    import sys
    from pathlib import Path

    root = Path(__file__).resolve().parents[2]
    partition = f"g1hands-{os.getpid()}-{uuid.uuid4().hex[:8]}"
    proc = subprocess.Popen(
        [sys.executable, "-m", "g1_control.cli.main", "sim-robot", "--physics", "mock", "--hands", "dex3",
         "--hand-object", "0.5", "--partition", partition, "--seconds", "12", "--rt-priority", "0"],
        cwd=root, env={**os.environ, "PYTHONPATH": str(root)}, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
        text=True)
    try:
        assert proc.stdout.readline().strip() == "ready"
        rc = main(["hands", "grasp", "--side", "right", "--torque-limit", "0.5", "--hold-s", "0.3", "--json",
                   "--partition", partition])
        out = json.loads(capsys.readouterr().out)
        _, err = proc.communicate(timeout=30)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert rc == 0 and out["tripped"] is None
    closing = dex3.hand_limits("right").closing_sign != 0
    assert [f["stop"] for f, c in zip(out["fingers"].values(), closing) if c] == ["touched"] * 6
    assert out["peak_measured_tau_nm"] <= 0.5
    assert "Dex3-1 hands" in err and " HandCmd_ applied" in err and " 0 HandCmd_ applied" not in err
