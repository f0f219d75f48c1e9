"""The loop's walk is the one the reference code produced: 0.5 s standing, then 1 s walking and
turning, against tests/loop/data/walk_reference.npz (written by the code of commit da5b7cd, before
the loop-overhead work of issue 11, with this file run as a script; re-recorded for issue 17, whose
velocity correction waits 1 s before integrating and holds uncommanded axes: with the earlier
corrector swapped back in, that code still reproduced the da5b7cd run within these tolerances,
so only the correction changed the walk; re-recorded at stop 46, when the bare floor got Coulomb
friction (g1_control/sim/scene.py grip_physics): with that switched off, the code reproduced the
previous recording within these tolerances). Only float rounding may differ:
it grows through the contacts, so the tolerances sit far below anything a behaviour change gives
(a changed motor-law integration misses them by three orders of magnitude)."""

import sys
from pathlib import Path

import numpy as np
import pytest

from g1_control.launch.builder import build_loop, make_sim_backend
from g1_control.launch.schema import LaunchFile, Segment

REFERENCE = Path(__file__).resolve().parent / "data" / "walk_reference.npz"
FIELDS = ("t_s", "q_rad", "base_pos_m", "base_quat_wxyz", "q_target_rad", "tau_nm", "velocity_est", "policy_command")


def walk_log() -> dict[str, np.ndarray]:
    launch = LaunchFile(name="walk_reference")
    launch.input.timeline = [Segment(0.5, label="stand"), Segment(1.0, vx_mps=0.5, wz_radps=0.3, label="walk")]
    launch.output.video = "off"
    loop = build_loop(launch, backend=make_sim_backend(launch))
    loop.reset()
    loop.run(1.5)
    assert not loop.fell
    log = loop.log.arrays()
    return {name: log[name] for name in FIELDS}


@pytest.mark.slow
def test_walk_matches_the_reference_run():
    ref = np.load(REFERENCE)
    log = walk_log()
    assert np.ptp(ref["base_pos_m"][:, 0]) > 0.15  # the reference walked
    np.testing.assert_array_equal(log["t_s"], ref["t_s"])
    tolerances = {"q_rad": 1e-5, "q_target_rad": 1e-4, "base_pos_m": 1e-6, "base_quat_wxyz": 1e-6,
                  "tau_nm": 1e-2, "velocity_est": 1e-4, "policy_command": 1e-5}
    for name, atol in tolerances.items():
        np.testing.assert_allclose(log[name], ref[name], rtol=0, atol=atol, err_msg=name)


if __name__ == "__main__":  # regenerate: python tests/loop/test_loop_walk_reference.py (from the reference code)
    np.savez_compressed(sys.argv[1] if len(sys.argv) > 1 else REFERENCE, **walk_log())
