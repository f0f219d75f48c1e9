"""sim2sim end to end: `g1 sim-robot` (MuJoCo G1 on its gantry, DDS on lo/domain 1, own partition)
and `g1 deploy` as separate processes, exactly as an operator runs them. The deploy walks the
state machine, the robot walks forward over DDS, and every ending is damping on the wire.

Thresholds are loose (shared 2-core host): the figures themselves are printed for the record."""

from __future__ import annotations

import json
import signal
import subprocess
import time

import pytest
from deploy_test_helpers import write_launch

from g1_control.tools.soak import G1Process as Proc
from tests.paths import LAUNCH_DIR

pytestmark = pytest.mark.timing


class Emulator(Proc):
    def __init__(self, partition: str, *flags: str):
        super().__init__("sim-robot", "--partition", partition, "--control-stdin", *flags, stdin=True)
        self.wait_for("^ready$", 60)

    def close(self) -> None:
        try:
            self.proc.stdin.write("quit\n")
            self.proc.stdin.flush()
            self.proc.wait(timeout=10)
        except (OSError, subprocess.TimeoutExpired):
            pass
        self.kill()


@pytest.fixture
def processes():
    started: list[Proc] = []
    yield started
    for p in reversed(started):  # the deploy first, then the robot; even when the test failed
        p.close() if isinstance(p, Emulator) else p.kill()


def test_sim2sim_walks_forward_and_ends_in_damping(tmp_path, partition, processes):
    robot = Emulator(partition, "--lower-gantry-on-policy")
    processes.append(robot)
    report_path = tmp_path / "deploy.json"
    host = Proc("deploy", str(LAUNCH_DIR / "sim2sim.yaml"), "--yes", "--partition", partition, "--duration", "5",
                "--json", str(report_path), "--out", str(tmp_path))
    processes.append(host)
    host.wait_for(r"zero torque: the robot is limp", 90)
    host.wait_for(r"control -> damping: control time over", 60)
    assert host.proc.wait(timeout=30) == 0, host.stderr
    report = json.loads(report_path.read_text())
    wire = robot.ask("report")

    assert report["sequence"] == ["zero_torque", "ramp", "hold", "control", "damping"]
    t = {tr["to"]: tr["t_s"] for tr in report["transitions"]}
    assert t["hold"] - t["ramp"] >= 2.0, "the ramp to the default pose takes at least 2 s"
    assert report["end_reason"].startswith("control time over") and not report["fault"]
    assert all(r["status"] in ("pass", "skip") for r in report["preflight"])

    # The gantry came off when the policy's first actions arrived; the robot then walked alone.
    lowered, damped = wire["gantry_lowered_base_pos_w_m"], wire["first_damping_base_pos_w_m"]
    assert lowered is not None and damped is not None
    assert abs(wire["gantry_lowered_at_s"] - t["control"]) < 0.3
    walked_m = damped[0] - lowered[0]
    control_s = wire["first_damping_time_s"] - wire["gantry_lowered_at_s"]
    print(f"\nsim2sim: walked {walked_m:.2f} m in {control_s:.2f} s of control (1 s stand, then vx 0.5 m/s); "
          f"lowcmd on the wire {wire['lowcmd_rate_hz']:.0f} Hz, period p50 {wire['lowcmd_period_p50_ms']:.2f} ms, "
          f"p99 {wire['lowcmd_period_p99_ms']:.2f} ms, max {wire['lowcmd_period_max_ms']:.1f} ms; "
          f"host estimate vx {report['control']['velocity_est_mean'][0]:+.2f} m/s")
    assert walked_m > 1.0, "forward progress under the policy"
    assert damped[2] > 0.6, "still standing (pelvis height) when control ended: no fall"
    assert report["control"]["velocity_est_mean"][0] > 0.3

    # Damping at exit: the last command the robot took is kp 0, kd > 0, and plenty of them came.
    assert wire["last_command_is_damping"] is True
    assert wire["damping_commands"] > 200, "damping streamed for exit_damping_s (1 s at 500 Hz)"
    assert wire["bad_crc"] == 0 and wire["wrong_mode_machine"] == 0
    assert wire["lowcmd_rate_hz"] > 300 and report["link"]["bad_crc"] == 0


def test_operator_drives_with_the_unitree_remote_and_stops_with_b(tmp_path, partition, processes):
    launch = write_launch(tmp_path, {"duration_s": None, "input": {"type": "unitree_remote", "timeline": None,
                                                                    "device": {"stale_after_s": 0.5}}})
    robot = Emulator(partition, "--lower-gantry-on-policy")
    processes.append(robot)
    host = Proc("deploy", str(launch), "--partition", partition, "--json", str(tmp_path / "deploy.json"),
                "--out", str(tmp_path))
    processes.append(host)
    line = host.wait_for(r"zero torque: the robot is limp", 90)
    assert "Press start to ramp" in line and "e-stop: L1+R1" in line and "stop (damping): B" in line
    time.sleep(0.5)
    assert host.proc.poll() is None and "-> ramp" not in "".join(host.seen), "nothing moves without the operator"
    robot.ask("press start")
    host.wait_for(r"zero_torque -> ramp: operator start", 10)
    host.wait_for(r"ramp -> hold", 10)
    host.wait_for(r"press A to start the policy", 5)
    robot.ask("press A")
    host.wait_for(r"hold -> control: operator run", 10)
    robot.ask("stick ly 0.6")
    time.sleep(4.0)
    robot.ask("stick ly 0.0")
    robot.ask("press B")
    host.wait_for(r"control -> damping: operator stop", 10)
    assert host.proc.wait(timeout=30) == 0, host.stderr
    wire = robot.ask("report")
    assert wire["first_damping_base_pos_w_m"][0] - wire["gantry_lowered_base_pos_w_m"][0] > 0.8
    assert wire["first_damping_base_pos_w_m"][2] > 0.6 and wire["last_command_is_damping"] is True
    report = json.loads((tmp_path / "deploy.json").read_text())
    assert report["sequence"] == ["zero_torque", "ramp", "hold", "control", "damping"]
    assert report["end_reason"] == "operator stop" and not report["fault"]


@pytest.mark.parametrize("sig", ["SIGTERM", "SIGINT"])
def test_a_signal_during_control_puts_damping_on_the_wire(tmp_path, partition, processes, sig):
    robot = Emulator(partition, "--physics", "mock")
    processes.append(robot)
    launch = write_launch(tmp_path, {"deploy": {"state_window_s": 0.3}})
    host = Proc("deploy", str(launch), "--yes", "--partition", partition, "--duration", "60", "--out", str(tmp_path))
    processes.append(host)
    host.wait_for(r"hold -> control: run \(--yes\)", 90)
    time.sleep(0.5)
    assert robot.ask("report")["damping_commands"] == 0
    t_signal = time.monotonic()
    host.proc.send_signal(getattr(signal, sig))
    host.wait_for(rf"control -> damping: estop: {sig} received", 10)
    assert host.proc.wait(timeout=30) == 0, "a signal is a planned ending (damping first)"
    wire = robot.ask("report")
    to_wire_ms = (wire["first_damping_time_s"] - t_signal) * 1000
    print(f"\n{sig} -> first damping LowCmd_ at the robot: {to_wire_ms:.1f} ms")
    assert 0 < to_wire_ms < 100, "damping reaches the robot within a few ticks of the signal"
    assert wire["last_command_is_damping"] is True and wire["damping_commands"] > 200


def test_a_fault_during_control_damps_and_exits_3_in_debug_mode(tmp_path, partition, processes):
    """Robot already in debug mode (no built-in controller, --no-release-motion-service); the robot
    reports a 1.3 rad tilt during control: the deploy trips, damping reaches the robot, exit 3."""
    robot = Emulator(partition, "--physics", "mock", "--no-builtin")
    processes.append(robot)
    launch = write_launch(tmp_path, {"deploy": {"state_window_s": 0.3}})
    host = Proc("deploy", str(launch), "--yes", "--no-release-motion-service", "--partition", partition,
                "--duration", "60", "--out", str(tmp_path))
    processes.append(host)
    line = host.wait_for(r"zero torque: the robot is limp", 90)
    assert not any("releasing the robot's built-in motion service" in s for s in host.seen), line
    host.wait_for(r"hold -> control", 30)
    time.sleep(0.3)
    t_inject = robot.ask("tilt")["t_s"]
    host.wait_for(r"control -> damping: tilt: pelvis tilted 1.30 rad", 10)
    assert host.proc.wait(timeout=30) == 3, "a safety fault ends the deploy with exit status 3"
    wire = robot.ask("report")
    to_wire_ms = (wire["first_damping_time_s"] - t_inject) * 1000
    print(f"\ntilt injected -> first damping LowCmd_ at the robot: {to_wire_ms:.1f} ms")
    assert 0 < to_wire_ms < 200, "tilt seen within a few 50 Hz ticks, damping on the wire right after"
    assert wire["last_command_is_damping"] is True and wire["ignored_while_builtin_active"] == 0


def test_the_launch_files_generator_chain_runs_on_the_robot_path_and_styles_follow_the_dpad(tmp_path, partition,
                                                                                          processes):
    """launch/sim2sim_generator.yaml: the generator -> IK -> policy chain over DDS, the same chain the
    preflight's MuJoCo dry run ran, and the emulator's upper-body joints following the plan as the
    remote's d-pad switches styles."""
    from deploy_test_helpers import SIM2SIM_GENERATOR

    robot = Emulator(partition, "--lower-gantry-on-policy")
    processes.append(robot)
    report_path = tmp_path / "deploy.json"
    host = Proc("deploy", str(SIM2SIM_GENERATOR), "--yes", "--partition", partition, "--duration", "9",
                "--json", str(report_path))
    processes.append(host)
    chain_line = host.wait_for(r"control chain \(as checked by the dry run\)", 120)
    assert "InbetweeningGenerator [backbone] -> IKStage [feasible plans pass; else daqp QP, 1 iteration(s) at 50 Hz, " \
           "contacts free] -> LocomotionPolicyTracker" in chain_line
    host.wait_for(r"hold -> control: run \(--yes\)", 60)
    time.sleep(3.0)
    robot.ask("press right")  # default -> wave
    host.wait_for(r"control -> damping: control time over", 60)
    assert host.proc.wait(timeout=30) == 0, host.stderr
    report = json.loads(report_path.read_text())
    for stage in ("generator", "retargeter", "tracker", "rates", "safety"):
        assert report["chain"][stage] == report["dry_run_chain"][stage]
    assert report["chain"]["backend"] == "UnitreeDDSBackend" and report["dry_run_chain"]["backend"] == "MujocoBackend"
    styles = report["control"]["upper_body_vs_plan"]
    print(f"\nsim2sim generator: upper body vs plan {styles}")
    assert set(styles) == {"default", "wave"}
    assert all(s["rms_rad"] < 0.2 for s in styles.values())
    wire = robot.ask("report")
    assert wire["first_damping_base_pos_w_m"][2] > 0.6 and wire["last_command_is_damping"] is True
