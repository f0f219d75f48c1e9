"""Parser latency: `python3 -m g1_control.program.language.bench` prints p50/p99 per instruction.

The parser runs in the input stage (between a typed line and the next tick), so its budget is
1 ms p99 for a 30-word instruction. Timings are printed, never asserted in unit tests. Both the
wall clock and the thread's CPU time are reported: on a shared, loaded machine the wall-clock tail
is the scheduler's (the thread waiting for a core), the CPU time is the parser's own.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from g1_control.program.language.parser import InstructionParser

INSTRUCTIONS = (
    # 30 words each
    "walk forward two meters, then turn left ninety degrees and wave while walking back to the table; "
    "pick up the box and put it on the other table, turn around",
    "walk forward one and a half meters slowly, turn right 45 degrees, reach for the cup with your "
    "left hand, bring it to the shelf and dance for five seconds",
    "go back 80 cm at 0.3 m/s, then spin a full circle to the right twice, step onto the "
    "platform within 20 seconds, wave for 3 s and step down",
)


def bench(n: int = 2000, warmup: int = 200) -> dict[str, dict[str, float]]:
    parser = InstructionParser()
    out = {}
    for text in INSTRUCTIONS:
        for _ in range(warmup):
            parser.parse(text)
        wall, cpu = np.empty(n), np.empty(n)
        for k in range(n):
            c0, t0 = time.thread_time(), time.perf_counter()
            parser.parse(text)
            wall[k], cpu[k] = time.perf_counter() - t0, time.thread_time() - c0
        out[text] = {"words": len(text.split()),
                     "wall_p50_ms": float(np.percentile(wall, 50) * 1e3), "wall_p99_ms": float(np.percentile(wall, 99) * 1e3),
                     "cpu_p50_ms": float(np.percentile(cpu, 50) * 1e3), "cpu_p99_ms": float(np.percentile(cpu, 99) * 1e3)}
    return out


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("-n", type=int, default=2000, help="parses per instruction")
    args = ap.parse_args(argv)
    for text, r in bench(args.n).items():
        print(f"{r['words']:3d} words  wall p50 {r['wall_p50_ms']:.3f} ms p99 {r['wall_p99_ms']:.3f} ms  "
              f"cpu p50 {r['cpu_p50_ms']:.3f} ms p99 {r['cpu_p99_ms']:.3f} ms  | {text[:50]}...")


if __name__ == "__main__":
    main()
