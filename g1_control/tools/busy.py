"""A load generator: N processes that keep a core each busy, for running timing-sensitive tests on a
loaded host (.ci/run's second pass) or checking a loop against other work.

    python -m g1_control.tools.busy --procs 2 --seconds 600     # until then, Ctrl-C or SIGTERM

The workers die with this process (PR_SET_PDEATHSIG): nothing is left running.
"""

from __future__ import annotations

import argparse
import ctypes
import os
import signal
import sys
import time

_SPIN = """
import ctypes, signal
ctypes.CDLL(None).prctl(1, signal.SIGKILL)  # PR_SET_PDEATHSIG: die with the parent
x = 0
while True:
    x = (x * 1103515245 + 12345) & 0x7FFFFFFF
"""


def start(procs: int) -> list:
    import subprocess

    return [subprocess.Popen([sys.executable, "-c", _SPIN]) for _ in range(procs)]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--procs", type=int, default=os.cpu_count() or 2, help="busy processes (default: one per core)")
    parser.add_argument("--seconds", type=float, default=3600.0, help="stop after this long (default 3600)")
    args = parser.parse_args(argv)
    ctypes.CDLL(None).prctl(1, signal.SIGTERM)  # and this one with whoever started it
    workers = start(args.procs)
    print(f"busy: {args.procs} processes ({', '.join(str(w.pid) for w in workers)}) for up to {args.seconds:.0f} s",
          flush=True)
    signal.signal(signal.SIGTERM, lambda *_: sys.exit(0))
    try:
        time.sleep(args.seconds)
    except KeyboardInterrupt:
        pass
    finally:
        for w in workers:
            w.kill()
            w.wait()
    return 0


if __name__ == "__main__":
    sys.exit(main())
