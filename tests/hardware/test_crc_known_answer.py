"""Known-answer CRC tests: constants computed outside this project's code, so a CRC changed the same
way on both sides of the link (host and emulator agree, the robot would not) cannot pass.

The constants come from the protocol's definition (docs/robot_facts.md): CRC-32 with polynomial
0x04C11DB7, initial value 0xFFFFFFFF, MSB first, no reflection, no final XOR, over each little-endian
32-bit word of the packed struct except the crc word, i.e. CRC-32/MPEG-2 over each word's big-endian
bytes. They were computed once by a separate byte-wise MPEG-2 routine that reproduces the catalogue's
check value (CRC-32/MPEG-2 of "123456789" = 0x0376E6E7), and are typed in here."""

from __future__ import annotations

import struct

import numpy as np

from g1_control.hardware.unitree.crc import crc32_words, crc32_words_bitwise, crc32_words_table
from g1_control.hardware.unitree.messages import LowCmd, verify_crc

WORDS_12345678 = (0x31323334, 0x35363738)
"""The words whose big-endian bytes are ASCII "12345678"."""
CRC_12345678 = 0x49E3C2FB
"""CRC-32/MPEG-2 of b"12345678"."""
CRC_KNOWN_LOWCMD = 0x9322E116
"""CRC of known_lowcmd_image() (mode_machine 5; motors 0-28 enabled, q = 0.1 i, tau 0.5, kp 40, kd 1)."""


def known_lowcmd_image() -> bytes:
    """LowCmd_'s C image without its crc word, packed by hand (4-byte alignment, little-endian): mode_pr,
    mode_machine, 2 pad bytes; 35 x {mode u8, 3 pad, q, dq, tau, kp, kd f32, reserve u32}; reserve u32[4]."""
    out = struct.pack("<BBxx", 0, 5)
    for i in range(35):
        out += struct.pack("<BxxxfffffI", *((1, 0.1 * i, 0.0, 0.5, 40.0, 1.0, 0) if i < 29 else (0,) * 7))
    return out + struct.pack("<4I", 0, 0, 0, 0)


def test_every_crc_form_gives_the_known_value_of_known_words():
    words = np.array(WORDS_12345678, dtype="<u4")
    assert crc32_words(words.tobytes()) == CRC_12345678
    assert crc32_words_table(words) == CRC_12345678
    assert crc32_words_bitwise(words) == CRC_12345678


def test_a_known_lowcmd_carries_the_known_crc_in_its_last_word():
    image = known_lowcmd_image()
    assert len(image) + 4 == 1004
    msg = LowCmd(mode_machine=5)
    msg.motor_mode[:29] = 1
    msg.motor_q_rad[:29] = 0.1 * np.arange(29)
    msg.motor_tau_nm[:29] = 0.5
    msg.motor_kp_nm_per_rad[:29] = 40.0
    msg.motor_kd_nms_per_rad[:29] = 1.0
    wire = msg.to_c_bytes()
    assert wire[:-4] == image, "the message packs as the protocol's struct"
    assert msg.crc == CRC_KNOWN_LOWCMD
    assert wire[-4:] == struct.pack("<I", CRC_KNOWN_LOWCMD)
    assert crc32_words(image) == CRC_KNOWN_LOWCMD
    verify_crc(LowCmd.from_c_bytes(wire))
