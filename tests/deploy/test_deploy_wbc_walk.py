"""The model-based whole-body controller walking over the robot path: `g1 sim-robot` and
`g1 deploy launch/sim2sim_wbc.yaml --yes` as two processes on lo, the WBC steering by the robot's own
estimate (no ground truth reaches the host), judged from the emulator's MuJoCo ground truth."""

from __future__ import annotations

import json
import math

import pytest
from deploy_test_helpers import ROOT, deploy_to_the_end, write_launch

# Not marked `timing` (not run a second time under .ci/run's busy load): with both cores spun by the load
# generator, the WBC's 250 Hz loop over DDS runs 10 % of its ticks more than 2 ms late (CI at 8d9c271: 196
# misses in 2036 ticks, p99 3.2 ms, damped at 25 overruns/s); it passes unloaded (every CI pass of stop 32).
# A faster WBC tick is the fix (issue 23). sim2sim_wbc.yaml runs the WBC at 100 Hz since stop 39: at 250 Hz
# it failed here even unloaded (3 of 5 runs, every attempt).

SIM2SIM_WBC = ROOT / "launch" / "sim2sim_wbc.yaml"


@pytest.mark.parametrize("variant, mode_machine", [("g1_29dof", "5"), ("g1_23dof", "4")])
def test_the_whole_body_controller_walks_the_emulated_robot_over_dds(tmp_path, partition, variant, mode_machine):
    """2 s standing, 0.4 m/s forward for 4 s, then standing: the pelvis (ground truth) moved forward by
    about what was commanded, stayed up, and the deploy ended in damping with no fault."""
    path = write_launch(tmp_path, {"backend": {"expected_variant": variant}, "duration_s": 9,
                                   "input": {"timeline": [{"duration_s": 2, "label": "stand"},
                                                          {"duration_s": 4, "vx_mps": 0.4, "label": "forward"},
                                                          {"duration_s": 3, "label": "stand"}]}},
                        base=SIM2SIM_WBC)
    _, wire = deploy_to_the_end(partition, path, tmp_path / "deploy.json", tmp_path,
                                emulator_flags=("--mode-machine", mode_machine, "--lower-gantry-on-policy",
                                                "--rt-priority", "0"),
                                waits=((r"zero torque: the robot is limp", 90),
                                       (r"control -> damping: control time over", 90)))
    report = json.loads((tmp_path / "deploy.json").read_text())
    assert report["sequence"] == ["zero_torque", "ramp", "hold", "control", "damping"]
    assert not report["fault"], report["end_reason"]
    assert "WholeBodyTracker" in report["chain"]["tracker"]
    lowered, damped = wire["gantry_lowered_base_pos_w_m"], wire["first_damping_base_pos_w_m"]
    assert lowered is not None and damped is not None
    dx, dy = damped[0] - lowered[0], damped[1] - lowered[1]
    print(f"\n{variant} WBC over DDS: walked {dx:+.2f} m forward, {dy:+.2f} m sideways (1.6 m commanded), "
          f"pelvis {damped[2]:.3f} m at damping; lowcmd {wire['lowcmd_rate_hz']:.0f} Hz")
    assert damped[2] > 0.65, "standing when control ended"
    assert 1.0 < dx < 2.0 and abs(dy) < 0.4 and math.hypot(dx, dy) > 1.0
    assert wire["bad_crc"] == 0 and wire["wrong_mode_machine"] == 0 and wire["last_command_is_damping"] is True
