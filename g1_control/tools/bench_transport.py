"""`g1 bench transport`: cost of what runs 500 times a second per direction on the robot link.

Baselines are measured in the same run: the CRC bit by bit in Python (the SDK's fallback) and
Cyclone's pure-Python IdlStruct (de)serialisation (the SDK's path), when cyclonedds is installed.
"""

from __future__ import annotations

import json
import time

import numpy as np

from g1_control.hardware.unitree.conversions import lowstate_to_robot_state, motor_command_to_lowcmd
from g1_control.hardware.unitree.crc import crc32_words, crc32_words_bitwise, crc32_words_table
from g1_control.hardware.unitree.messages import LowState, compute_crc
from g1_control.robot import g1
from g1_control.types import MotorCommand, RobotState


def _time_us(fn, budget_s: float, min_runs: int = 3) -> float:
    """Median microseconds per call over repeated batches within ~budget_s."""
    fn()
    start = time.perf_counter()
    fn()
    one = max(time.perf_counter() - start, 1e-7)
    batch = max(1, int(0.02 / one))
    samples: list[float] = []
    end = time.perf_counter() + budget_s
    while len(samples) < min_runs or time.perf_counter() < end:
        t0 = time.perf_counter()
        for _ in range(batch):
            fn()
        samples.append((time.perf_counter() - t0) / batch * 1e6)
    return float(np.median(samples))


def main(args) -> int:
    from tqdm import tqdm

    budget = max(0.2, min(float(getattr(args, "seconds", 20.0)), 60.0) / 12)
    rng = np.random.default_rng(0)
    cmd = MotorCommand(q_rad=g1.DEFAULT_Q_RAD.copy(), kp=g1.KP_DEFAULT.copy(), kd=g1.KD_DEFAULT.copy(),
                       tau_nm=rng.normal(0, 1, g1.NUM_JOINTS))
    lowcmd = motor_command_to_lowcmd(cmd, 5)
    image = lowcmd.to_c_bytes()
    words = np.frombuffer(image[:-4], dtype="<u4")
    state_wire = LowState(mode_machine=5).to_dds()

    from g1_control.safety import SafetyFilter

    safety = SafetyFilter()
    state = RobotState(q_rad=g1.DEFAULT_Q_RAD.copy())

    cases = {
        "crc bitwise python (baseline)": lambda: crc32_words_bitwise(words),
        "crc table-driven python": lambda: crc32_words_table(words),
        "crc zlib (used)": lambda: crc32_words(image[:-4]),
        "LowCmd pack + crc": lambda: compute_crc(lowcmd),
        "LowCmd encode DDS sample (used)": lambda: motor_command_to_lowcmd(cmd, 5).to_dds(),
        "LowState decode + CRC check + RobotState (used)": lambda: lowstate_to_robot_state(
            LowState.from_dds(state_wire, verify=True), 0.0),
        "SafetyFilter.filter": lambda: safety.filter(cmd, state, 0.0),
    }
    try:
        from g1_control.hardware.unitree import idl as unitree_idl

        idl_cmd = unitree_idl.LowCmd_.deserialize(lowcmd.to_dds())
        cases["LowCmd IdlStruct.serialize (baseline)"] = lambda: idl_cmd.serialize()
        cases["LowState IdlStruct.deserialize (baseline)"] = lambda: unitree_idl.LowState_.deserialize(state_wire)
    except Exception as exc:
        print(f"(cyclonedds baselines skipped: {exc})")

    results = {}
    for name, fn in tqdm(cases.items(), desc="transport bench", unit="case"):
        results[name] = _time_us(fn, budget if "bitwise" not in name else min(budget, 1.0))

    base_crc = results["crc bitwise python (baseline)"]
    print(f"\n{'case':48s} {'us/call':>10s}  ratio")
    for name, us in results.items():
        if "(baseline)" in name:
            ratio = "baseline"
        elif name.startswith("crc"):
            ratio = f"{base_crc / us:8.0f}x faster than bitwise"
        elif "encode" in name and "LowCmd IdlStruct.serialize (baseline)" in results:
            ratio = f"{results['LowCmd IdlStruct.serialize (baseline)'] / us:8.1f}x faster than IdlStruct"
        elif "decode" in name and "LowState IdlStruct.deserialize (baseline)" in results:
            ratio = f"{results['LowState IdlStruct.deserialize (baseline)'] / us:8.1f}x faster than IdlStruct"
        else:
            ratio = ""
        print(f"{name:48s} {us:10.1f}  {ratio}")
    per_tick = results["LowCmd encode DDS sample (used)"] + results["LowState decode + CRC check + RobotState (used)"]
    print(f"\nencode + decode per 2 ms tick: {per_tick:.1f} us = {per_tick / 2000 * 100:.1f} % of one core at 500 Hz")
    if getattr(args, "json", None):
        with open(args.json, "w") as fh:
            json.dump({"us_per_call": results}, fh, indent=2)
    return 0
