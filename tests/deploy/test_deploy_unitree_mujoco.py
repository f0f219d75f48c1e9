"""g1 deploy's preflight against Unitree's MuJoCo simulator, played by the emulator in its
unitree_mujoco mode over real DDS on loopback (lo, domain 1, a partition per test): LowState_ with
crc, tick and mode_machine 0 at 200 Hz, no motion service. Without backend.simulator the preflight
refuses it and says what it is; with it, it passes and the table names what was accepted. A robot
whose tick never advances (CRCs valid) is refused by name."""

from __future__ import annotations

import pytest
from deploy_test_helpers import FAST, preflight_only, write_launch

pytestmark = pytest.mark.timing

SIMULATOR = {"backend": {"simulator": "unitree_mujoco"}}


def _status(report) -> dict[str, str]:
    return {r["name"]: ("overridden" if r["overridden"] else r["status"]) for r in report.preflight}


def _reason(report, name: str) -> str:
    return next(r["reason"] for r in report.preflight if r["name"] == name)


@pytest.fixture
def emulator(partition):
    from g1_control.sim.emulator import RobotEmulator
    from g1_control.sim.mock_robot import MockG1

    made = []

    def make(mode: str = "unitree_mujoco"):
        robot = RobotEmulator(MockG1(), "lo", 1, partition=partition, mode=mode)
        made.append(robot)
        return robot

    yield make
    for robot in made:
        robot.close()


def _merge(*changes: dict) -> dict:
    out: dict = {}
    for change in changes:
        for key, value in change.items():
            out[key] = {**out.get(key, {}), **value} if isinstance(value, dict) else value
    return out


def test_unitree_mujoco_without_the_profile_is_refused_with_a_hint_naming_it(tmp_path, partition, emulator):
    emulator().start()
    path = write_launch(tmp_path, _merge(FAST, {"backend": {"connect_timeout_s": 0.5}}))
    report, refused, _ = preflight_only(path, partition)
    assert refused is not None and _status(report)["state_stream"] == "fail"
    reason = _reason(report, "state_stream")
    assert "no valid LowState from the robot within 0.5 s" in reason and "samples had a bad CRC" in reason
    assert ("hint: the LowState_ on loopback carries crc, tick and mode_machine all 0, as Unitree's MuJoCo "
            "simulator (unitree_mujoco) publishes it: not a robot. To run against it, set backend.simulator: "
            "unitree_mujoco") in reason


def test_with_the_profile_the_preflight_passes_and_its_table_names_the_simulator_traits(tmp_path, partition,
                                                                                        emulator):
    robot = emulator().start()
    path = write_launch(tmp_path, _merge(FAST, SIMULATOR))
    report, refused, text = preflight_only(path, partition)
    assert refused is None, text
    status = _status(report)
    assert status.pop("battery") == "skip" and status.pop("motion_service") == "skip", text
    assert set(status.values()) == {"pass"}, text
    assert _reason(report, "motion_service") == ("backend.simulator unitree_mujoco: a simulator runs no motion service; "
                                                 "nothing is released")
    stream = _reason(report, "state_stream")
    rate = float(stream.split(" Hz")[0])
    # the simulator's 200 Hz, accepted below the robot's 400 (over the 0.3 s window a loaded host's catch-up
    # burst read 240 Hz: CI's timing pass, stop 41)
    assert 150 <= rate < 400, stream
    assert ("backend.simulator unitree_mujoco (200 Hz, robot needs 400): crc 0 accepted unchecked, tick 0 counted "
            "by the host, mode_machine 0 read as 5") in stream
    assert _reason(report, "variant") == ("mode_machine 5 (g1_29dof, 29 DoF) (left 0 by unitree_mujoco: the launch "
                                          "file's expected_variant assumed)")
    assert "no motion service: nothing is released" in _reason(report, "interface")
    assert robot.endpoint.counters.commands_applied == 0


def test_the_profile_still_refuses_a_wrong_crc(tmp_path, partition, emulator):
    robot = emulator(mode="robot")
    robot.endpoint.corrupt_state_crc = True  # non-zero and wrong: a broken robot, not a simulator
    robot.start()
    path = write_launch(tmp_path, _merge(FAST, SIMULATOR, {"backend": {"connect_timeout_s": 0.5}}))
    report, refused, _ = preflight_only(path, partition)
    assert refused is not None and "samples had a bad CRC" in _reason(report, "state_stream")


def test_a_state_stream_whose_tick_never_advances_fails_the_preflight_by_name(tmp_path, partition, emulator):
    robot = emulator(mode="robot")
    robot.endpoint.freeze_state = True  # the same sample again and again: CRC valid, tick frozen
    robot.start()
    report, refused, text = preflight_only(write_launch(tmp_path, FAST), partition)
    assert refused is not None and _status(report)["state_stream"] == "fail", text
    reason = _reason(report, "state_stream")
    assert "0 bad CRC" in reason and "tick frozen: " in reason and "every one with tick 0" in reason
    assert "hint" not in reason  # mode_machine 5: a robot, not the simulator


def test_the_profile_is_for_loopback_only_and_must_be_known(tmp_path):
    from g1_control.errors import LaunchFileError
    from g1_control.launch.schema import load_launch

    with pytest.raises(LaunchFileError, match=r"backend.simulator: unitree_mujoco is allowed on loopback only \(type "
                       r"unitree_dds, interface lo\); got type unitree_dds, interface eth0: a robot must fill crc"):
        load_launch(write_launch(tmp_path, {"backend": {"simulator": "unitree_mujoco", "interface": "eth0"}}))
    with pytest.raises(LaunchFileError, match="backend.simulator: 'gazebo' is not a simulator profile; known: "
                       "unitree_mujoco"):
        load_launch(write_launch(tmp_path, {"backend": {"simulator": "gazebo"}}))


def test_deploy_walks_against_the_emulator_playing_unitree_mujoco(tmp_path, partition):
    """`g1 sim-robot --mode unitree_mujoco` and `g1 deploy launch/sim2sim_unitree_mujoco.yaml --yes` as two
    processes: the preflight table names the simulator's traits, then the robot walks (ground truth:
    the emulator's base position) and ends in damping."""
    import json

    from test_deploy_sim2sim import Emulator

    from g1_control.tools.soak import G1Process
    from tests.paths import LAUNCH_DIR

    robot = Emulator(partition, "--mode", "unitree_mujoco", "--lower-gantry-on-policy")
    host = None
    try:
        report_path = tmp_path / "deploy.json"
        host = G1Process("deploy", str(LAUNCH_DIR / "sim2sim_unitree_mujoco.yaml"), "--yes", "--partition", partition,
                         "--duration", "6", "--json", str(report_path), "--out", str(tmp_path))
        host.wait_for(r"zero torque: the robot is limp", 120)
        table = "\n".join(host.seen)
        assert "backend.simulator unitree_mujoco (200 Hz, robot needs 400): crc 0 accepted unchecked, tick 0 " \
               "counted by the host, mode_machine 0 read as 5" in table
        assert "no motion service: nothing is released" in table
        assert "releasing the robot's built-in motion service" not in table
        host.wait_for(r"control -> damping: control time over", 60)
        assert host.proc.wait(timeout=30) == 0, host.stderr
        report = json.loads(report_path.read_text())
        wire = robot.ask("report")
    finally:
        if host is not None:
            host.kill()
        robot.close()
    assert report["sequence"] == ["zero_torque", "ramp", "hold", "control", "damping"] and not report["fault"]
    assert report["released_modes"] == []
    lowered, damped = wire["gantry_lowered_base_pos_w_m"], wire["first_damping_base_pos_w_m"]
    walked_m = damped[0] - lowered[0]
    control_s = wire["first_damping_time_s"] - wire["gantry_lowered_at_s"]
    print(f"\nunitree_mujoco sim2sim: walked {walked_m:.2f} m in {control_s:.2f} s of control (1 s stand, then vx "
          f"0.5 m/s); LowState_ sent {wire['states_sent']}, host estimate vx "
          f"{report['control']['velocity_est_mean'][0]:+.2f} m/s; pelvis at {damped[2]:.2f} m when damped")
    assert walked_m > 1.0, "forward progress under the policy"
    assert damped[2] > 0.6, "still standing when control ended"
    assert wire["last_command_is_damping"] is True and wire["bad_crc"] == 0
