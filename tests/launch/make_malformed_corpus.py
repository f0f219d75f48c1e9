"""Writes the malformed-file corpus under tests/launch/corpus/{launch,policy,clip}/ (run once; the files are
kept in the repository, and tests/launch/test_malformed_corpus.py asserts the message for each one
from tests/launch/corpus/expected.yaml).

    python tests/launch/make_malformed_corpus.py
"""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent / "corpus"

LAUNCH_BASE = """name: corpus
duration_s: 2.0
input:
  type: scripted
  timeline:
    - {duration_s: 2.0, vx_mps: 0.3, label: walk}
output: {video: false}
"""


def launch_cases() -> dict[str, str | bytes]:
    b = LAUNCH_BASE
    return {
        "lowlevel_hz_zero.yaml": b + "rates: {lowlevel_hz: 0}\n",
        "lowlevel_hz_negative.yaml": b + "rates: {lowlevel_hz: -500}\n",
        "tracker_hz_not_dividing.yaml": b + "rates: {tracker_hz: 33}\n",
        "unknown_style.yaml": b.replace("label: walk}", "label: walk, style: moonwalk}"),
        "unknown_random_style.yaml": b.replace("type: scripted", "type: random").replace(
            "  timeline:\n    - {duration_s: 2.0, vx_mps: 0.3, label: walk}\n", "  random: {style: moonwalk}\n"),
        "duplicate_top_key.yaml": b + "name: other\n",
        "duplicate_nested_key.yaml": b + "rates:\n  tracker_hz: 50\n  tracker_hz: 25\n",
        "binary_junk.yaml": bytes(range(256)) * 8,
        "nul_bytes.yaml": b + "description: a\x00b\n",
        "latin1_text.yaml": (b + "description: caf\xe9\n").encode("latin-1"),
        "negative_max_vx.yaml": b + "limits: {max_vx_mps: -1.0}\n",
        "zero_max_wz.yaml": b + "limits: {max_wz_radps: 0}\n",
        "negative_vx_over_limit.yaml": b.replace("vx_mps: 0.3", "vx_mps: -2.0"),
        "negative_wz_over_limit.yaml": b.replace("vx_mps: 0.3", "wz_radps: -5.0"),
        "unknown_top_key.yaml": b + "tracer: {type: policy}\n",
        "duration_not_a_number.yaml": b.replace("duration_s: 2.0", "duration_s: ten", 1),
        "duration_zero.yaml": b.replace("duration_s: 2.0", "duration_s: 0", 1),
        "duration_nan.yaml": b.replace("duration_s: 2.0", "duration_s: .nan", 1),
        "duration_inf.yaml": b.replace("duration_s: 2.0", "duration_s: .inf", 1),
        "backend_type_unknown.yaml": b + "backend: {type: robot}\n",
        "dds_without_interface.yaml": b + "backend: {type: unitree_dds, domain: 1}\n",
        "dds_domain_out_of_range.yaml": b + "backend: {type: unitree_dds, interface: lo, domain: 300}\n",
        "physics_dt_too_large.yaml": b + "backend: {physics_dt_s: 0.1}\n",
        "scripted_without_timeline.yaml": b.replace(
            "  timeline:\n    - {duration_s: 2.0, vx_mps: 0.3, label: walk}\n", ""),
        "wbc_too_slow.yaml": b + "tracker: {type: wbc}\ngenerator: {type: scripted}\nrates: {tracker_hz: 50}\n",
        "wbc_foot_friction_zero.yaml": b + "rates: {tracker_hz: 250}\ntracker: {type: wbc, foot_friction: 0}\n",
        "wbc_foot_friction_nan.yaml": b + "rates: {tracker_hz: 250}\ntracker: {type: wbc, foot_friction: .nan}\n",
        "unknown_reference.yaml": b + "rates: {tracker_hz: 250}\ntracker: {type: wbc}\n"
                                      "generator: {type: scripted, reference: moonwalk}\n",
        "negative_stale_state.yaml": b + "safety: {stale_state_s: -1}\n",
        "gain_cap_too_high.yaml": b + "safety: {max_kp: 5000}\n",
        "damping_kd_over_cap.yaml": b + "safety: {max_kd: 1.0, damping_kd: 2.0}\n",
        "ramp_too_fast.yaml": b + "deploy: {ramp_s: 0.5}\n",
        "realtime_priority_out_of_range.yaml": b + "deploy: {realtime_priority: 150}\n",
        "top_level_list.yaml": "- name: corpus\n- duration_s: 2\n",
        "empty_file.yaml": "",
        "invalid_yaml_syntax.yaml": b + "rates: {tracker_hz: 50\n",
        "unknown_policy.yaml": b + "tracker: {policy: no_such_policy}\n",
        "zero_max_tilt.yaml": b + "limits: {max_tilt_rad: 0}\n",
        "video_size_one_item.yaml": b.replace("output: {video: false}", "output: {video: false, video_size: [480]}"),
        "timeline_not_a_list.yaml": b.replace(
            "  timeline:\n    - {duration_s: 2.0, vx_mps: 0.3, label: walk}\n", "  timeline: walk\n"),
        "bool_as_rate.yaml": b + "rates: {tracker_hz: true}\n",
        # every branch of the schema's own checks (scripts/mutation.py group "schema")
        "physics_dt_too_small.yaml": b + "backend: {physics_dt_s: 0.0001}\n",
        "dds_domain_negative.yaml": b + "backend: {type: unitree_dds, interface: lo, domain: -1}\n",
        "can_without_channel.yaml": b + "backend: {type: can, can_interface: virtual}\n",
        "can_without_interface.yaml": b + "backend: {type: can, channel: can0}\n",
        "serial_without_port.yaml": b + "backend: {type: serial}\n",
        "mode_pr_two.yaml": b + "backend: {type: unitree_dds, interface: lo, mode_pr: 2}\n",
        "command_rate_too_low.yaml": b + "backend: {type: unitree_dds, interface: lo, command_rate_hz: 49.9}\n",
        "command_rate_too_high.yaml": b + "backend: {type: serial, port: /dev/ttyUSB0, command_rate_hz: 1000.5}\n",
        "connect_timeout_zero.yaml": b + "backend: {type: unitree_dds, interface: lo, connect_timeout_s: 0}\n",
        "dry_run_too_short.yaml": b + "deploy: {dry_run_s: 9.9}\n",
        "auto_start_negative.yaml": b + "deploy: {auto_start_s: -0.1}\n",
        "auto_run_negative.yaml": b + "deploy: {auto_run_s: -0.1}\n",
        "min_hold_negative.yaml": b + "deploy: {min_hold_s: -0.1}\n",
        "exit_damping_negative.yaml": b + "deploy: {exit_damping_s: -1}\n",
        "state_window_zero.yaml": b + "deploy: {state_window_s: 0}\n",
        "input_check_zero.yaml": b + "deploy: {input_check_s: 0}\n",
        "min_state_rate_zero.yaml": b + "deploy: {min_state_rate_hz: 0}\n",
        "max_start_tilt_zero.yaml": b + "deploy: {max_start_tilt_rad: 0}\n",
        "joint_tolerance_negative.yaml": b + "deploy: {joint_limit_tolerance_rad: -0.01}\n",
        "realtime_priority_negative.yaml": b + "deploy: {realtime_priority: -1}\n",
        "device_type_given.yaml": b.replace("type: scripted", "type: gamepad").replace(
            "  timeline:\n    - {duration_s: 2.0, vx_mps: 0.3, label: walk}\n", "  device: {type: keyboard}\n"),
        "gamepad_script_empty_step.yaml": b.replace("type: scripted", "type: gamepad_script").replace(
            "  timeline:\n    - {duration_s: 2.0, vx_mps: 0.3, label: walk}\n", "  gamepad_script: [{}]\n"),
        "unknown_reference_param.yaml": b + "rates: {tracker_hz: 250}\ntracker: {type: wbc}\ngenerator: {type: scripted, "
                                            "reference: walk, reference_params: {pace: 2, gait: 1}}\n",
        "gamepad_bad_mapping.yaml": b.replace("type: scripted", "type: gamepad").replace(
            "  timeline:\n    - {duration_s: 2.0, vx_mps: 0.3, label: walk}\n",
            "  device: {mapping: {axes: {vx: {axis: wheel}}}}\n"),
        "remote_gamepad_button.yaml": b.replace("type: scripted", "type: unitree_remote").replace(
            "  timeline:\n    - {duration_s: 2.0, vx_mps: 0.3, label: walk}\n",
            "  device: {mapping: {buttons: {LB+RB: estop}}}\n"),
        "gamepad_script_bad_mapping.yaml": b.replace("type: scripted", "type: gamepad_script").replace(
            "  timeline:\n    - {duration_s: 2.0, vx_mps: 0.3, label: walk}\n",
            "  gamepad_script: [{t_s: 0.0, press: A}]\n  device: {mapping: {buttons: {L1+R1: estop}}}\n"),
        "layer_with_scripted.yaml": b + "rates: {tracker_hz: 250}\ntracker: {type: layer}\ngenerator: {type: scripted}\n",
        "wbt_wrong_rate.yaml": b + "rates: {tracker_hz: 25}\ntracker: {type: wbt}\n",
        "vy_over_limit.yaml": b.replace("vx_mps: 0.3", "vy_mps: 0.61"),
        "negative_duration.yaml": b.replace("duration_s: 2.0", "duration_s: -1", 1),
        "lowlevel_hz_too_high.yaml": b + "rates: {lowlevel_hz: 20000, tracker_hz: 50}\n",
        "input_rate_not_dividing.yaml": b + "rates: {input_hz: 30}\n",
        "estimator_rate_zero.yaml": b + "rates: {estimator_hz: 0}\n",
        # values that would disable a trip or a start check (issue 26)
        "safety_tilt_pi.yaml": b + "safety: {max_tilt_rad: 3.1416}\n",
        "safety_tilt_above_pi.yaml": b + "safety: {max_tilt_rad: 3.5}\n",
        "limits_tilt_above_pi.yaml": b + "limits: {max_tilt_rad: 3.5}\n",
        "safety_temperature_over_rating.yaml": b + "safety: {max_motor_temperature_c: 150}\n",
        "start_temperature_500.yaml": b + "deploy: {max_start_temperature_c: 500}\n",
        "battery_negative.yaml": b + "deploy: {min_battery_v: -5}\n",
        "battery_below_empty.yaml": b + "deploy: {min_battery_v: 12}\n",
        "battery_above_full.yaml": b + "deploy: {min_battery_v: 60}\n",
        "fall_pelvis_height_zero.yaml": b + "fall: {min_pelvis_height_m: 0}\n",
        "fall_pelvis_height_above_standing.yaml": b + "fall: {min_pelvis_height_m: 0.9}\n",
        # domain randomisation (issue 23): ranges inside their bounds, low <= high, the simulator only
        "randomize_mass_scale_reversed.yaml": b + "backend: {randomize: {mass_scale: [1.1, 0.9]}}\n",
        "randomize_strength_above_bound.yaml": b + "backend: {randomize: {motor_strength: [0.85, 1.5]}}\n",
        "randomize_latency_negative.yaml": b + "backend: {randomize: {latency_s: [-0.005, 0.015]}}\n",
        "randomize_friction_zero.yaml": b + "backend: {randomize: {foot_friction: [0.0, 1.2]}}\n",
        "randomize_com_offset_too_large.yaml": b + "backend: {randomize: {com_offset_m: 0.5}}\n",
        "randomize_range_one_item.yaml": b + "backend: {randomize: {foot_friction: [0.5]}}\n",
        "randomize_on_robot.yaml": b + "backend: {type: unitree_dds, interface: lo, randomize: {seed: 1}}\n",
    }


def policy_cases() -> dict[str, str | bytes]:
    shipped = HERE.parents[2] / "g1_control" / "policies" / "specs" / "holosoma_loco_ppo.yaml"
    # Without the shipped file's comments (they cite project documents this corpus does not carry).
    base = "".join(line for line in shipped.read_text().splitlines(keepends=True) if not line.startswith("#"))
    # A spec outside the package finds its ONNX through the asset, as the shipped one does.
    joints = "joint_names: metadata        # read from the ONNX metadata, checked against the robot\n"
    gains = "gains: metadata              # kp/kd from the ONNX metadata, checked against the robot's gains\n"
    default_q = "default_q: robot             # g1.DEFAULT_Q_RAD\n"
    from g1_control.robot import g1

    names = list(g1.JOINT_NAMES)
    return {
        "unknown_key.yaml": base + "gain: metadata\n",
        "onnx_missing_file.yaml": base.replace("path: holosoma_inference/models/loco/g1_29dof/ppo_g1_29dof.onnx",
                                               "path: holosoma_inference/models/loco/g1_29dof/missing.onnx"),
        "onnx_not_a_path.yaml": base.replace("onnx:\n  asset: holosoma-policies\n"
                                             "  path: holosoma_inference/models/loco/g1_29dof/ppo_g1_29dof.onnx\n",
                                             "onnx: 5\n"),
        "joint_order_reversed.yaml": base.replace(joints, f"joint_names: {names[::-1]}\n"),
        "joint_unknown.yaml": base.replace(joints, f"joint_names: {names[:-1] + ['tail_joint']}\n"),
        "gains_wrong_length.yaml": base.replace(gains, "gains: {kp: [100.0, 100.0], kd: [2.0, 2.0]}\n"),
        "gains_negative.yaml": base.replace(gains, f"gains: {{kp: {[-1.0] * 29}, kd: {[1.0] * 29}}}\n"),
        "default_q_outside_limits.yaml": base.replace(default_q, f"default_q: {[0.0] * 3 + [5.0] + [0.0] * 25}\n"),
        "default_q_nan.yaml": base.replace(default_q, "default_q: [" + ", ".join([".nan"] + ["0.0"] * 28) + "]\n"),
        "observation_unknown_term.yaml": base.replace("    - {name: sin_phase}\n", "    - {name: wind_speed}\n"),
        "observation_wrong_input.yaml": base.replace("  input: actor_obs\n", "  input: obs\n"),
        "observation_missing_term.yaml": base.replace("    - {name: sin_phase}\n", ""),
        "duplicate_key.yaml": base + "rate_hz: 100\n",
        "binary_junk.yaml": bytes(range(255, -1, -1)) * 8,
        "top_level_list.yaml": "- name: x\n- kind: locomotion\n",
        "rate_not_a_number.yaml": base.replace("rate_hz: 50", "rate_hz: fast"),
        "phase_without_period.yaml": base.replace("  period_s: 1.0\n", ""),
        "action_scale_text.yaml": base.replace("  scale: 0.25\n", "  scale: quarter\n"),
        "invalid_yaml.yaml": base + "observation: [\n",
    }


def _npz(**arrays) -> bytes:
    buf = io.BytesIO()
    np.savez(buf, **arrays)
    return buf.getvalue()


def clip_cases() -> dict[str, str | bytes]:
    from g1_control.motion.clip import MotionClip
    from g1_control.motion.formats.clip_npz import write_clip_npz
    from g1_control.robot import g1

    t = 12
    joints = np.tile(g1.DEFAULT_Q_RAD, (t, 1))
    root = np.column_stack([np.linspace(0, 0.1, t), np.zeros(t), np.full(t, 0.78)])
    quat = np.tile([1.0, 0.0, 0.0, 0.0], (t, 1))
    clip = MotionClip.from_joint_trajectory(30.0, root, quat, joints, source="corpus")
    tmp = HERE / "_valid.npz"
    write_clip_npz(clip, tmp)
    with np.load(tmp) as data:
        good = {k: data[k] for k in data.files}
    valid = tmp.read_bytes()
    tmp.unlink()

    def variant(**changes) -> bytes:
        d = dict(good)
        for k, v in changes.items():
            if v is None:
                d.pop(k)
            else:
                d[k] = v
        return _npz(**d)

    nan_joints = good["joint_pos"].copy()
    nan_joints[3, 5] = np.nan
    far_joint = good["joint_pos"].copy()
    far_joint[:, 3] = 40.0
    zero_quat = good["root_quat_w"].copy()
    zero_quat[2] = 0.0
    row = ",".join(["0.0", "0.0", "0.78", "0.0", "0.0", "0.0", "1.0"] + [repr(float(v)) for v in g1.DEFAULT_Q_RAD])
    bvh_head = ("HIERARCHY\nROOT Hips\n{\n  OFFSET 0 0 0\n  CHANNELS 6 Xposition Yposition Zposition Zrotation "
                "Xrotation Yrotation\n  End Site\n  {\n    OFFSET 0 10 0\n  }\n}\n")
    return {
        "not_a_zip.npz": b"this is not an npz file\n",
        "truncated_zip.npz": valid[: len(valid) // 2],
        "missing_joint_pos.npz": variant(joint_pos=None),
        "joint_pos_wrong_width.npz": variant(joint_pos=good["joint_pos"][:, :28]),
        "joint_pos_nan.npz": variant(joint_pos=nan_joints),
        "zero_frames.npz": variant(joint_pos=good["joint_pos"][:0]),
        "fps_zero.npz": variant(fps=np.array(0.0)),
        "fps_negative.npz": variant(fps=np.array(-30.0)),
        "fps_nan.npz": variant(fps=np.array(np.nan)),
        "unknown_joint_names.npz": variant(joint_names=np.array([n.replace("knee", "elbow_2")
                                                                 for n in g1.JOINT_NAMES])),
        "joint_far_outside_limits.npz": variant(joint_pos=far_joint),
        "root_quat_zero.npz": variant(root_quat_w=zero_quat),
        "frame_counts_differ.npz": variant(joint_vel=good["joint_vel"][:-1]),
        "pickled_object.npz": _npz(joint_pos=np.array([{"a": 1}], dtype=object), fps=np.array(30.0)),
        "csv_wrong_columns.csv": row + "\n" + ",".join(row.split(",")[:-1]) + "\n",
        "csv_not_numeric.csv": row + "\n" + row.replace("0.78", "tall", 1) + "\n",
        "csv_empty.csv": "",
        "csv_nan.csv": row + "\n" + row.replace("0.78", "nan", 1) + "\n",
        "csv_quaternion_not_unit.csv": row.replace(",1.0,", ",2.0,", 1) + "\n",
        "csv_binary_junk.csv": bytes(range(256)) * 4,
        "bvh_no_motion.bvh": bvh_head,
        "bvh_frame_count_mismatch.bvh": bvh_head + "MOTION\nFrames: 3\nFrame Time: 0.033333\n0 0 0 0 0 0\n",
        "bvh_binary_junk.bvh": bytes(range(256)) * 4,
        "bvh_not_numbers.bvh": bvh_head + "MOTION\nFrames: 1\nFrame Time: 0.033333\n0 0 zero 0 0 0\n",
    }


def write(folder: str, cases: dict[str, str | bytes]) -> None:
    out = HERE / folder
    out.mkdir(exist_ok=True)
    for name, content in cases.items():
        data = content.encode("utf-8") if isinstance(content, str) else content
        (out / name).write_bytes(data)


if __name__ == "__main__":
    write("launch", launch_cases())
    write("policy", policy_cases())
    write("clip", clip_cases())
