"""g1 deploy with a behaviour program: shown, confirmed on a robot, dry-run whole in MuJoCo, and
run on the emulated robot (sim2sim) with the program driving once control starts."""

from __future__ import annotations

import json

import pytest
from deploy_test_helpers import ROOT

from g1_control.deploy.preflight import PreflightRefused, dry_run_launch
from g1_control.deploy.session import DeployOptions, deploy
from g1_control.launch.schema import load_launch
from g1_control.program import parse_instruction, save_program
from tests.deploy.test_deploy_sim2sim import Emulator, Proc
from tests.paths import LAUNCH_DIR

ROBOT = ROOT / "launch" / "robot.yaml"


def test_free_text_on_a_robot_runs_only_after_the_operator_says_yes():
    said, asked = [], []
    program = parse_instruction("walk forward 1 meter and turn left")
    options = DeployOptions(program=program, program_text="walk forward 1 meter and turn left",
                            interface="g1test-no-such-nic")

    def ask(question):
        asked.append(question)
        return "n"

    report = deploy(ROBOT, options, say=said.append, ask=ask)
    assert report.refused and report.end_reason == "program not confirmed by the operator"
    assert "1. walk forward 1 m\n2. turn left 90 deg" in said[0] and len(asked) == 1
    assert not report.preflight, "nothing was checked, opened or sent"


def test_yes_does_not_answer_for_a_robot():
    options = DeployOptions(yes=True, program=parse_instruction("turn left"), program_text="turn left",
                            interface="g1test-no-such-nic")
    with pytest.raises(PreflightRefused):
        deploy(ROBOT, options, say=lambda s: None, ask=lambda q: pytest.fail("asked on a refused deploy"))


def test_the_dry_run_runs_the_whole_program():
    launch = load_launch(ROOT / "launch" / "sim2sim.yaml")
    program = parse_instruction("walk forward 2 meters, turn around, walk forward 2 meters")
    dry = dry_run_launch(launch, program)
    assert dry.input.type == "program" and dry.backend.type == "mujoco" and dry.input.pose == "estimator"
    assert dry.input.parsed_program().to_dict()["steps"] == program.to_dict()["steps"]
    assert dry.total_duration_s >= max(launch.deploy.dry_run_s, 20.0)


@pytest.fixture
def processes():
    started: list[Proc] = []
    yield started
    for p in reversed(started):
        p.close() if isinstance(p, Emulator) else p.kill()


def test_sim2sim_program_file_drives_the_robot(tmp_path, partition, processes):
    program_file = tmp_path / "program.yaml"
    save_program(parse_instruction("walk forward 1 meter, then turn left 90 degrees"), program_file)
    robot = Emulator(partition, "--lower-gantry-on-policy")
    processes.append(robot)
    report_path = tmp_path / "deploy.json"
    host = Proc("deploy", str(LAUNCH_DIR / "sim2sim.yaml"), "--yes", "--partition", partition, "--duration", "14",
                "--program", str(program_file), "--json", str(report_path))
    processes.append(host)
    host.wait_for(r"behaviour program \(from the program file\)", 60)
    host.wait_for(r"dry_run .*PASS.*program finished, 2 steps", 120)
    host.wait_for(r"program step 1\. walk forward 1 m: completed", 60)
    host.wait_for(r"program step 2\. turn left 90 deg: completed", 30)
    host.wait_for(r"control -> damping: control time over", 30)
    assert host.proc.wait(timeout=30) == 0, host.stderr
    report = json.loads(report_path.read_text())
    program = report["control"]["program"]
    assert program["finished"] and [s["status"] for s in program["steps"]] == ["completed", "completed"]
    wire = robot.ask("report")
    walked = wire["first_damping_base_pos_w_m"][0] - wire["gantry_lowered_base_pos_w_m"][0]
    print(f"\nsim2sim program: the emulated robot moved {walked:.2f} m along x (walk 1 m, then a turn in place)")
    assert 0.8 < walked < 1.3 and wire["first_damping_base_pos_w_m"][2] > 0.6
