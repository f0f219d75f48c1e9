"""Parser latency: `g1 bench parser` (or `python3 -m g1_control.program.language.bench`).

The parser runs in the input stage (between a typed line and the next tick), so its budget is
1 ms p99 for a 30-word instruction. Timings are printed, never asserted in unit tests.

Both the thread's CPU time and the wall clock are reported, and every parse is interleaved with a
baseline of known, fixed work (BASELINE_ITERATIONS of a pure-Python loop, about as long as a parse):
parse, baseline, parse, baseline, ... On a shared, loaded machine the wall-clock tail is the
scheduler's (the thread waiting for a core); the baseline sees the same waits at the same moments,
so when the parser's wall p99 and the baseline's rise together the tail is the machine, not the
parser. The parser's own cost is its CPU time; its wall p99 is meaningful on a quiet machine.
"""

from __future__ import annotations

import argparse
import json
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
BASELINE_ITERATIONS = 5000
"""Fixed work of the baseline: a pure-Python loop of this many additions (~0.11 ms of CPU here, about a parse)."""


def _baseline() -> int:
    total = 0
    for i in range(BASELINE_ITERATIONS):
        total += i
    return total


def _stats(samples: np.ndarray) -> dict[str, float]:
    return {"p50_ms": float(np.percentile(samples, 50) * 1e3), "p99_ms": float(np.percentile(samples, 99) * 1e3),
            "max_ms": float(samples.max() * 1e3)}


def bench(n: int = 2000, warmup: int = 200) -> dict[str, dict]:
    """Per instruction: parser and baseline, each {cpu, wall} x {p50_ms, p99_ms, max_ms}, interleaved."""
    parser = InstructionParser()
    out = {}
    clock, cpu_clock = time.perf_counter, time.thread_time
    for text in INSTRUCTIONS:
        for _ in range(warmup):
            parser.parse(text)
            _baseline()
        times = np.empty((4, n))  # parse wall, parse cpu, baseline wall, baseline cpu
        for k in range(n):
            c0, t0 = cpu_clock(), clock()
            parser.parse(text)
            t1, c1 = clock(), cpu_clock()
            _baseline()
            t2, c2 = clock(), cpu_clock()
            times[:, k] = (t1 - t0, c1 - c0, t2 - t1, c2 - c1)
        out[text] = {"words": len(text.split()),
                     "parse": {"wall": _stats(times[0]), "cpu": _stats(times[1])},
                     "baseline": {"wall": _stats(times[2]), "cpu": _stats(times[3])}}
    return out


def report(results: dict[str, dict]) -> str:
    lines = [f"{'':>5}  {'parse cpu p50/p99':>19}  {'parse wall p50/p99':>19}  {'baseline cpu p50/p99':>21}  "
             f"{'baseline wall p50/p99':>21}  instruction"]
    for text, r in results.items():
        p, b = r["parse"], r["baseline"]
        lines.append(f"{r['words']:3d} w  {p['cpu']['p50_ms']:8.3f} {p['cpu']['p99_ms']:8.3f} ms  "
                     f"{p['wall']['p50_ms']:8.3f} {p['wall']['p99_ms']:8.3f} ms  "
                     f"{b['cpu']['p50_ms']:9.3f} {b['cpu']['p99_ms']:9.3f} ms  "
                     f"{b['wall']['p50_ms']:9.3f} {b['wall']['p99_ms']:9.3f} ms  {text[:40]}...")
    return "\n".join(lines)


def bench_main(args) -> int:
    """`g1 bench parser` (--seconds is ignored; 2000 parses per instruction)."""
    results = bench()
    print(report(results))
    if args.json:  # g1 bench's --json
        with open(args.json, "w") as fh:
            json.dump(results, fh, indent=2)
    return 0


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("-n", type=int, default=2000, help="parses per instruction")
    args = ap.parse_args(argv)
    print(report(bench(args.n)))


if __name__ == "__main__":
    main()
