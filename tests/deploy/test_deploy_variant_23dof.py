"""g1 deploy on the 23-DoF G1 (mode_machine 4): the emulator builds and reports it over DDS on lo,
and the preflight accepts it with the model-based controller, whose dry run simulates that robot."""

from __future__ import annotations

import pytest
from deploy_test_helpers import FAST, ROOT, deploy_to_the_end, preflight_only, write_launch

pytestmark = pytest.mark.timing

SIM2SIM_23DOF = ROOT / "launch" / "sim2sim_23dof.yaml"


@pytest.fixture
def robot_23dof(partition):
    """The MuJoCo 23-DoF G1 behind the robot's DDS protocol (built-in controller active), in this process."""
    from g1_control.sim.emulator import RobotEmulator
    from g1_control.sim.mujoco_backend import MujocoBackend, MujocoConfig

    emulator = RobotEmulator(MujocoBackend(MujocoConfig(variant="g1_23dof")), "lo", 1, partition=partition).start()
    yield emulator
    emulator.close()


def _results(report) -> dict[str, dict]:
    return {r["name"]: r for r in report.preflight}


def test_the_23dof_robot_passes_the_preflight_with_the_model_based_controller(tmp_path, partition, robot_23dof):
    report, refused, text = preflight_only(write_launch(tmp_path, FAST, base=SIM2SIM_23DOF), partition)
    assert refused is None, text
    results = _results(report)
    assert results["variant"]["status"] == "pass"
    assert results["variant"]["reason"] == "mode_machine 4 (g1_23dof, 23 DoF)"  # as read from LowState_ on lo
    assert results["policy"]["reason"] == ("tracker.type wbc: no learned policy; the model-based controller runs the "
                                           "g1_23dof model (23 joints)")
    assert results["joint_limits"]["reason"].startswith("23 joints inside their limits")
    dry = results["dry_run"]
    assert dry["status"] == "pass" and "the model-based controller on the g1_23dof G1" in dry["reason"], text
    assert robot_23dof.endpoint.counters.commands_applied == 0, "a preflight sends nothing to the robot"


def test_a_29dof_launch_file_is_refused_on_the_23dof_robot(tmp_path, partition, robot_23dof):
    report, refused, _ = preflight_only(write_launch(tmp_path, FAST), partition)
    assert refused is not None
    assert _results(report)["variant"]["reason"].startswith(
        "the robot reports mode_machine 4 (g1_23dof, 23 DoF) but the launch file expects g1_29dof")


def test_the_shipped_29dof_policy_is_refused_for_the_23dof_robot(tmp_path, partition, robot_23dof):
    path = write_launch(tmp_path, {**FAST, "tracker": {"type": "policy", "policy": "holosoma_loco_ppo"},
                                   "generator": {"type": "velocity"}, "rates": {"tracker_hz": 50, "lowlevel_hz": 50}},
                        base=SIM2SIM_23DOF)
    report, refused, _ = preflight_only(path, partition)
    assert refused is not None
    results = _results(report)
    assert results["policy"]["status"] == "fail"
    assert "is for the g1_29dof G1 but backend.expected_variant is g1_23dof" in results["policy"]["reason"]
    assert results["dry_run"]["status"] == "not run"


def test_g1_deploy_runs_the_23dof_sim_robot_over_dds_with_the_model_based_controller(tmp_path, partition):
    """`g1 sim-robot --mode-machine 4` and `g1 deploy launch/sim2sim_23dof.yaml --yes` as separate
    processes: the whole state machine, the WBC holding the 23-DoF robot off its gantry, damping at the end."""
    import json

    _, wire = deploy_to_the_end(partition, SIM2SIM_23DOF, tmp_path / "deploy.json", tmp_path,
                                   emulator_flags=("--mode-machine", "4", "--lower-gantry-on-policy", "--rt-priority", "0"),
                                   deploy_flags=("--duration", "5"),
                                   waits=((r"zero torque: the robot is limp", 90),
                                          (r"control -> damping: control time over", 60)))
    report = json.loads((tmp_path / "deploy.json").read_text())
    assert report["sequence"] == ["zero_torque", "ramp", "hold", "control", "damping"]
    assert {r["name"]: r["reason"] for r in report["preflight"]}["variant"] == "mode_machine 4 (g1_23dof, 23 DoF)"
    assert "WholeBodyTracker" in report["chain"]["tracker"]
    # ground truth from the emulator's MuJoCo: off the gantry under the WBC, still standing when damping began
    lowered, damped = wire["gantry_lowered_base_pos_w_m"], wire["first_damping_base_pos_w_m"]
    assert lowered is not None and damped is not None
    control_s = wire["first_damping_time_s"] - wire["gantry_lowered_at_s"]
    drift_m = ((damped[0] - lowered[0]) ** 2 + (damped[1] - lowered[1]) ** 2) ** 0.5
    print(f"\n23-DoF sim2sim: {control_s:.2f} s of WBC control off the gantry, pelvis {lowered[2]:.3f} -> "
          f"{damped[2]:.3f} m, drift {drift_m:.3f} m; lowcmd {wire['lowcmd_rate_hz']:.0f} Hz")
    assert control_s > 4.0
    assert damped[2] > 0.65 and drift_m < 0.1, "stood on its own feet until damping"
    assert wire["wrong_mode_machine"] == 0 and wire["bad_crc"] == 0, "every LowCmd_ echoed mode_machine 4"
    assert wire["last_command_is_damping"] is True
