#!/usr/bin/env python3
"""Mutation testing of the safety-critical code with mutmut (on demand; not in every CI run).

    python3 scripts/mutation.py                      # every group below (an hour or more on 2 cores)
    python3 scripts/mutation.py velocity schema      # some groups
    python3 scripts/mutation.py --rev HEAD~3 safety  # the code (and tests) of another commit
    python3 scripts/mutation.py loop --select 'g1_control.deploy.state_machine.*'  # some of a group's mutants

For each group, the committed tree (`--rev`, default HEAD) is exported to a scratch folder with a
mutmut configuration that mutates only the group's files and runs only the group's test files
(mutmut then runs, per mutant, only the tests that cover the mutated function). Hypothesis tests
run with fewer examples there (G1_FUZZ_EXAMPLES=25). It prints, per group, killed / survived /
no covering test / timeout and the score (killed / (killed + survived)), lists every survivor,
and writes everything to runs/mutation-<rev>/report.json. Surviving mutants are either killed by
a new test or listed with the reason they are equivalent in docs/mutation.md. Needs `pip install mutmut` (3.8 or later; 3.3.1's wheel shipped a top-level `tests`
package into site-packages).
"""

from __future__ import annotations

import argparse
import fnmatch
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]

GROUPS: dict[str, dict[str, list[str]]] = {
    "safety": {
        "mutate": ["g1_control/safety/filter.py", "g1_control/safety/config.py", "g1_control/safety/guarded_backend.py",
                   "g1_control/safety/events.py"],
        # test_safety_properties.py (hypothesis, hundreds of examples per run) is left out: too slow
        # to run per mutant on 2 cores; it runs in every CI run.
        "tests": ["tests/safety/test_safety_filter.py", "tests/safety/test_safety_guards.py",
                  "tests/safety/test_guarded_backend.py", "tests/safety/test_safety_edges.py",
                  "tests/safety/test_guarded_backend_edges.py", "tests/safety/test_safety_ik_failure.py"],
    },
    "preflight": {
        "mutate": ["g1_control/deploy/preflight.py"],
        "tests": ["tests/deploy/test_deploy_preflight_checks.py", "tests/deploy/test_deploy_preflight_paths.py",
                  "tests/deploy/test_deploy_preflight_bounds.py", "tests/deploy/test_deploy_preflight_simulators.py",
                  "tests/deploy/test_deploy_preflight_services.py"],
    },
    "decoders": {
        "mutate": ["g1_control/hardware/unitree/messages.py", "g1_control/hardware/unitree/conversions.py",
                   "g1_control/hardware/unitree/remote.py"],
        "tests": ["tests/hardware/test_unitree_hg.py", "tests/hardware/test_hw_conversions.py",
                  "tests/hardware/test_decoder_fuzz.py", "tests/hardware/test_decoder_fields.py",
                  "tests/hardware/test_decoder_edges.py"],
    },
    "schema": {
        "mutate": ["g1_control/launch/schema.py"],
        "tests": ["tests/launch/test_launch_schema.py", "tests/launch/test_launch_refusals.py",
                  "tests/launch/test_malformed_corpus.py", "tests/launch/test_launch_schema_bounds.py",
                  "tests/deploy/test_deploy_launch_schema.py", "tests/launch/test_launch_goals.py",
                  "tests/launch/test_launch_schema_paths.py", "tests/launch/test_launch_ik_section.py",
                  "tests/launch/test_launch_estimation.py", "tests/launch/test_launch_start_pose.py",
                  "tests/launch/test_launch_schema_words.py"],
    },
    "loop": {
        # The robot path's runtime trips (issue 26): the loop's CRC, peer and fall checks, the fall
        # judge, the deploy's state machine and its run's end. Its tests include deploys over DDS
        # (~10 s each): every mutant of these files (1,900) is about 4.5 hours on 2 cores, so only the
        # functions on the trip path run (`select`, ~450 mutants, about an hour): the loop's safety,
        # state reading, fall and event code, the fall judge, the deploy state machine, and the deploy
        # session's end of run (how a trip ends in damping and in the report). The loop's logging,
        # construction and the session's printing are left out.
        "mutate": ["g1_control/loop/control_loop.py", "g1_control/safety/fall.py",
                   "g1_control/deploy/state_machine.py", "g1_control/deploy/session.py"],
        "select": ["g1_control.loop.control_loop.x_first_fault*", "g1_control.loop.control_loop.xǁLoopEventǁ*",
                   *(f"g1_control.loop.control_loop.xǁControlLoopǁ{f}__mutmut_*" for f in (
                       "_safety", "_on_safety_event", "_check_fall", "_read_state", "_fault", "_event", "faulted",
                       "fall", "fell", "_feed_back", "_retarget")),
                   "g1_control.safety.fall.*", "g1_control.deploy.state_machine.*",
                   *(f"g1_control.deploy.session.*{f}__mutmut_*" for f in (
                       "_end_in_damping", "_on_signal", "finish", "_fill_report", "_state_machine"))],
        # No wall clock: the deploys over DDS run on it, and under mutmut (nice 19, beside other work)
        # their loop misses deadlines and trips, which fails mutmut's clean run (group loop-dds, for a
        # quiet machine). The session's end of run runs on a stand-in clock (test_deploy_session_end.py).
        # `timing` tests (paced by the wall clock) are left out the same way: a loaded host fails them.
        "pytest_args": ["-m", "not timing"],
        "tests": ["tests/loop/test_control_loop.py", "tests/safety/test_safety_fall.py",
                  "tests/launch/test_launch_trips.py", "tests/deploy/test_deploy_state_machine.py",
                  "tests/deploy/test_deploy_state_machine_edges.py", "tests/loop/test_control_loop_trips.py",
                  "tests/deploy/test_deploy_session_end.py", "tests/loop/test_control_loop_ik_failure.py"],
    },
    "velocity": {
        # locomotion.py is mutated whole; only VelocityCorrector's mutants are counted (the tracker's
        # other code is covered by physics tests that are too slow to run per mutant).
        "mutate": ["g1_control/trackers/locomotion.py"],
        "tests": ["tests/trackers/test_velocity_correction.py", "tests/trackers/test_velocity_feedforward.py",
                  "tests/trackers/test_velocity_settle.py"],
        "only": ["VelocityCorrector"],
    },
}
# The loop group with the robot path's deploys over DDS too (hours; a machine with nothing else on it).
# Workers fork from mutmut's fork server, not from its main process: the main process ran the suite
# for its stats, DDS tests included, and a child forked after Cyclone DDS made a domain has none of
# Cyclone's threads, so its first entity deletion waits forever (a DdsLink closed in a forked child
# hangs; every mutant whose tests reach a deploy over DDS did).
GROUPS["loop-dds"] = {**GROUPS["loop"], "pytest_args": [], "process_isolation": "forkserver",
                     "tests": [*GROUPS["loop"]["tests"], "tests/deploy/test_deploy_runtime_trips.py",
                               "tests/deploy/test_deploy_state_validation.py", "tests/deploy/test_deploy_run_folder.py"]}


def export(rev: str, dest: Path) -> None:
    archive = subprocess.run(["git", "-C", str(REPO), "archive", rev], check=True, capture_output=True).stdout
    subprocess.run(["tar", "-x", "-C", str(dest)], input=archive, check=True)


def configure(dest: Path, group: dict) -> None:
    toml = dest / "pyproject.toml"
    text = toml.read_text()
    text = re.sub(r"\n\[tool\.mutmut\][^\[]*", "\n", text)
    listed = ", ".join(f'"{p}"' for p in group["mutate"])
    # An older --rev may lack some of the test files: run the ones it has.
    tests = ", ".join(f'"{p}"' for p in group["tests"] if (dest / p).exists())
    pytest_args = ", ".join(f'"{a}"' for a in ["-p", "no:cacheprovider", "-q", *group.get("pytest_args", [])])
    text += (f"\n[tool.mutmut]\nsource_paths = [\"g1_control\"]\nonly_mutate = [{listed}]\n"
             f"tests_dir = [{tests}]\npytest_add_cli_args = [{pytest_args}]\n"
             "also_copy = [\"g1_control\", \"launch\", \"tests\"]\n")
    if "process_isolation" in group:
        text += f"process_isolation = \"{group['process_isolation']}\"\n"
    toml.write_text(text)


def parse_results(text: str) -> dict[str, str]:
    """`mutmut results --all true` lines 'name: status' -> {name: status}."""
    out = {}
    for line in text.splitlines():
        m = re.match(r"\s*([\w.ǁ]+__mutmut_\d+): (.+)$", line)
        if m:
            out[m.group(1)] = m.group(2).strip()
    return out


def run_group(name: str, group: dict, rev: str, workdir: Path, diffs_wanted: bool = True) -> dict:
    dest = workdir / name
    dest.mkdir(parents=True)
    export(rev, dest)
    configure(dest, group)
    env = {**os.environ, "G1_FUZZ_EXAMPLES": "25", "PYTHONPATH": str(dest)}
    t0 = time.monotonic()
    run = subprocess.run(["mutmut", "run", "--max-children", "2", *group.get("select", [])], check=False, cwd=dest,
                         env=env, capture_output=True, text=True)
    results = subprocess.run(["mutmut", "results", "--all", "true"], check=False, cwd=dest, env=env, capture_output=True, text=True)
    statuses = parse_results(results.stdout)
    only = group.get("only")
    if only:
        statuses = {k: v for k, v in statuses.items() if any(o in k for o in only)}
    select = group.get("select")
    if select:  # mutants not selected were never run ("not checked"): not part of the score
        statuses = {k: v for k, v in statuses.items() if any(fnmatch.fnmatch(k, pat) for pat in select)}
    survivors = sorted(k for k, v in statuses.items() if v == "survived")
    diffs = {}
    for mutant in survivors if diffs_wanted else ():
        shown = subprocess.run(["mutmut", "show", mutant], check=False, cwd=dest, env=env, capture_output=True, text=True)
        diffs[mutant] = shown.stdout.strip()
    count = {s: sum(1 for v in statuses.values() if v == s) for s in sorted(set(statuses.values()))}
    killed, survived = count.get("killed", 0), count.get("survived", 0)
    return {"group": name, "files": group["mutate"], "tests": group["tests"], "seconds": time.monotonic() - t0,
            "counts": count, "score": killed / (killed + survived) if killed + survived else None,
            "survivors": diffs or dict.fromkeys(survivors, ""), "mutmut_exit": run.returncode, "mutmut_tail": run.stdout[-1500:] + run.stderr[-1500:]}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("groups", nargs="*", default=[], help=f"groups (default: all): {', '.join(GROUPS)}")
    parser.add_argument("--rev", default="HEAD", help="the commit whose code and tests are mutated (default HEAD)")
    parser.add_argument("--keep", action="store_true", help="keep the scratch folders")
    parser.add_argument("--no-diffs", action="store_true", help="list survivors by name only (mutmut show is slow)")
    parser.add_argument("--select", nargs="+", metavar="PATTERN",
                        help="run only the mutants matching these mutmut name patterns (fnmatch), instead of the "
                             "group's own selection: to recheck the functions a new test aims at")
    args = parser.parse_args(argv)
    if shutil.which("mutmut") is None:
        print("mutmut is not installed: pip install 'mutmut>=3.8'", file=sys.stderr)
        return 2
    names = args.groups or list(GROUPS)
    unknown = [n for n in names if n not in GROUPS]
    if unknown:
        parser.error(f"unknown group(s) {unknown}; groups: {', '.join(GROUPS)}")
    sha = subprocess.run(["git", "-C", str(REPO), "rev-parse", "--short", args.rev], check=True, capture_output=True,
                         text=True).stdout.strip()
    out_dir = REPO / "runs" / f"mutation-{sha}-{'-'.join(names)}{'-selected' if args.select else ''}"
    out_dir.mkdir(parents=True, exist_ok=True)
    workdir = Path(tempfile.mkdtemp(prefix=f"g1-mutation-{sha}-"))
    reports = []
    try:
        for name in names:
            print(f"== {name}: mutating {', '.join(GROUPS[name]['mutate'])} against {', '.join(GROUPS[name]['tests'])}",
                  flush=True)
            group = {**GROUPS[name], "select": args.select} if args.select else GROUPS[name]
            report = run_group(name, group, args.rev, workdir, not args.no_diffs)
            reports.append(report)
            score = "n/a" if report["score"] is None else f"{100 * report['score']:.1f}%"
            print(f"   {report['counts']}  score {score}  ({report['seconds']:.0f} s)", flush=True)
            for mutant, diff in report["survivors"].items():
                print(f"   survived: {mutant}\n" + "\n".join("      " + line for line in diff.splitlines()[-8:]))
            (out_dir / "report.json").write_text(json.dumps(reports, indent=2))
    finally:
        if not args.keep:
            shutil.rmtree(workdir, ignore_errors=True)
    total_k = sum(r["counts"].get("killed", 0) for r in reports)
    total_s = sum(r["counts"].get("survived", 0) for r in reports)
    print(f"all groups: {total_k} killed, {total_s} survived, score "
          f"{100 * total_k / max(1, total_k + total_s):.1f}%; report {out_dir / 'report.json'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
