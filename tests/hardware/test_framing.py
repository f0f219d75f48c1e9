from __future__ import annotations

import numpy as np
import pytest

from g1_control.hardware.links.framing import KIND_LOWCMD, KIND_LOWSTATE, OVERHEAD, Deframer, encode_frame

RNG = np.random.default_rng(1)


def _payload(n=1004) -> bytes:
    return RNG.integers(0, 256, n).astype(np.uint8).tobytes()


def test_frames_survive_any_chunking():
    payloads = [_payload() for _ in range(5)]
    stream = b"".join(encode_frame(KIND_LOWCMD, i, p) for i, p in enumerate(payloads))
    d = Deframer()
    got = []
    pos = 0
    while pos < len(stream):
        step = int(RNG.integers(1, 300))
        got += d.feed(stream[pos: pos + step])
        pos += step
    assert [f.payload for f in got] == payloads and [f.seq for f in got] == list(range(5))
    assert d.counters.bad_checksum == d.counters.bad_header == d.counters.skipped_bytes == d.counters.lost == 0


def test_corruption_drops_only_the_damaged_frame_and_resyncs():
    frames = [encode_frame(KIND_LOWSTATE, i, _payload(200)) for i in range(4)]
    damaged = bytearray(frames[1])
    damaged[50] ^= 0xFF
    stream = b"noise" + frames[0] + bytes(damaged) + b"\x00G" + frames[2] + frames[3]
    d = Deframer()
    got = d.feed(stream)
    assert [f.seq for f in got] == [0, 2, 3]
    assert d.counters.bad_checksum == 1 and d.counters.lost == 1 and d.counters.skipped_bytes > 0


def test_corrupted_length_cannot_swallow_the_next_frame():
    a, b = encode_frame(KIND_LOWCMD, 0, _payload(100)), encode_frame(KIND_LOWCMD, 1, _payload(100))
    bad = bytearray(a)
    bad[5] = 60  # length 100 -> 60
    got = Deframer().feed(bytes(bad) + b)
    assert [f.seq for f in got] == [1]


def test_overhead_and_bad_arguments():
    assert len(encode_frame(KIND_LOWCMD, 0, b"x" * 1004)) == 1004 + OVERHEAD == 1015
    with pytest.raises(ValueError, match="frame kind must be one of"):
        encode_frame(9, 0, b"")
    with pytest.raises(ValueError, match="at most 4096"):
        encode_frame(KIND_LOWCMD, 0, bytes(5000))
