"""A robot stand-in built only from Unitree's official message definitions (run as a subprocess).

Publishes official LowState_ samples (official serialiser, CRC from the official packing) on
rt/lowstate and reads rt/lowcmd with the official LowCmd_ type; prints a JSON summary. If the
project's types or bytes differed from Unitree's, discovery would not match or the CRCs would fail.
"""

from __future__ import annotations

import json
import sys
import time

from tests.hardware.unitree_reference import hg, official_crc


def main(interface: str, domain: int, partition: str, seconds: float) -> None:
    from cyclonedds.domain import DomainParticipant
    from cyclonedds.pub import DataWriter, Publisher
    from cyclonedds.qos import Policy, Qos
    from cyclonedds.sub import DataReader, Subscriber
    from cyclonedds.topic import Topic

    from g1_control.hardware.links.dds import domain_participant

    participant: DomainParticipant = domain_participant(interface, domain)
    group = Qos(Policy.Partition([partition]))
    writer = DataWriter(Publisher(participant, qos=group), Topic(participant, "rt/lowstate", hg.LowState_))
    reader = DataReader(Subscriber(participant, qos=group), Topic(participant, "rt/lowcmd", hg.LowCmd_),
                        qos=Qos(Policy.History.KeepLast(64)))
    imu = hg.IMUState_([1.0, 0.0, 0.0, 0.0], [0.0] * 3, [0.0, 0.0, 9.81], [0.0] * 3, 30)
    motors = [hg.MotorState_(1, 0.1 * (i % 5), 0.0, 0.0, 0.0, [31, 33], 48.0, [0, 0], 0, [0] * 4) for i in range(35)]
    received, crc_ok, mode_machines = 0, 0, set()
    end = time.monotonic() + seconds
    tick = 0
    while time.monotonic() < end:
        state = hg.LowState_([0, 0], 0, 4, tick, imu, motors, list(range(40)), [0] * 4, 0)
        state.crc = official_crc(state)
        writer.write(state)
        tick += 1
        for cmd in reader.take(64):
            if not hasattr(cmd, "motor_cmd"):
                continue
            received += 1
            mode_machines.add(cmd.mode_machine)
            if received <= 20:  # the bit-by-bit oracle costs ~1.5 ms; check the first twenty
                crc_ok += int(official_crc(cmd) == cmd.crc)
        time.sleep(0.01)
    print(json.dumps({"received": received, "crc_ok": crc_ok, "checked": min(received, 20),
                      "mode_machines": sorted(mode_machines), "states_sent": tick}), flush=True)


if __name__ == "__main__":
    main(sys.argv[1], int(sys.argv[2]), sys.argv[3], float(sys.argv[4]))
