"""`g1 library`: the generator's G1 motion library.

    g1 library build                  # into the user cache (~/.cache/g1-control/library)
    g1 library build -o lib/ --force  # elsewhere, rebuilt even when the cache matches
    g1 library show                   # styles, clips and frames per split
    g1 library build --variant g1_23dof            # the 23-DoF G1's library, from the 29-DoF one
    g1 library build --variant g1_29dof_with_hand  # the G1 with Dex3 hands (synthesized fingers)

Sources: MuJoCo rollouts of the holosoma locomotion policy under seeded random commands, one
upper-body style per rollout (tracked in physics through the policy's upper-body override); the
131 s dance clip stored in holosoma's WBT policy; the seven holosoma demo mocap sequences
retargeted by the project's IK; all mirrored left/right. Clips are cut into 8 s pieces; whole
pieces (with their mirror images) are held out for evaluation. Every piece must pass `g1 check`
(no joint beyond its limits, no link in the floor or the scene, no self-collision, sliding on at
most 1 % of stance frames): a piece that fails is repaired through the IK (self-collision, ground
and contact limits; admitted only if it then passes) or else left out with its mirror, and the
build (and `g1 library show`) lists which and why; `--no-repair` leaves them out, `--no-gate`
admits them. A build takes about 1-2 minutes
on 2 cores and is skipped when the index on disk was built with the same configuration.
"""

from __future__ import annotations

import argparse

from g1_control.fanout import add_arguments as add_fanout_arguments


def register(subparsers) -> None:
    parser = subparsers.add_parser("library", help="build or show the generator's G1 motion library",
                                   description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="library_command", metavar="ACTION", required=True)
    build = sub.add_parser("build", help="build the library (cached)", description=__doc__,
                           formatter_class=argparse.RawDescriptionHelpFormatter)
    build.add_argument("-o", "--output", help="library folder (default: the user cache)")
    build.add_argument("--force", action="store_true", help="rebuild even when the cached index matches")
    build.add_argument("--rollout-seconds", type=float, default=45.0, help="seconds per rollout (default 45)")
    build.add_argument("--rollouts-per-style", type=int, default=2, help="rollouts (seeds) per style (default 2)")
    build.add_argument("--no-dance", action="store_true", help="leave out the WBT dance clip")
    build.add_argument("--no-demo", action="store_true", help="leave out the retargeted demo mocap")
    build.add_argument("--no-gate", action="store_true",
                       help="admit every piece, even those that fail `g1 check` (default: they are repaired through "
                       "the IK or left out, and the build says which and why)")
    build.add_argument("--no-repair", action="store_true",
                       help="leave out a piece that fails `g1 check` instead of repairing it through the IK")
    add_fanout_arguments(build, jobs_default=2, what="rollouts")
    build.add_argument("--variant", default="g1_29dof", choices=("g1_29dof", "g1_23dof", "g1_29dof_with_hand"),
                       help="robot variant (default g1_29dof; the others are derived from the 29-DoF library through "
                            "the IK, see g1_control/library/variants.py)")
    build.set_defaults(func=_build)
    show = sub.add_parser("show", help="print styles, clips and frames per split",
                          description="Print the built library's styles, clips and frame counts per split "
                          "(train / held-out). Look at a clip with g1 view CLIP.npz.")
    show.add_argument("path", nargs="?", help="library folder (default: the user cache)")
    show.set_defaults(func=_show)


def _build(args) -> int:
    from g1_control.library.builder import LibraryConfig, build_library
    from g1_control.motion.library import default_library_dir

    config = LibraryConfig(rollout_seconds=args.rollout_seconds, rollouts_per_style=args.rollouts_per_style,
                           dance=not args.no_dance, demo=not args.no_demo, gate=not args.no_gate, repair=not args.no_repair)
    if args.variant != "g1_29dof":
        from g1_control.library.variants import build_variant_library

        base = build_library(default_library_dir(), config, jobs=args.jobs, ray=args.ray)  # no-op when cached
        lib = build_variant_library(args.variant, base.root, args.output, force=args.force)
        print(lib.summary())
        print(f"library {args.variant}: {lib.root} (built in {lib.index['build_s']} s from {base.root})")
        return 0
    out = args.output or default_library_dir()
    lib = build_library(out, config, force=args.force, jobs=args.jobs, ray=args.ray)
    print(lib.summary())
    print(f"library: {lib.root} (built in {lib.index['build_s']} s)")
    return 0


def _show(args) -> int:
    from g1_control.motion.library import MotionLibrary, default_library_dir

    lib = MotionLibrary(args.path or default_library_dir())
    print(lib.summary())
    for info in lib.index.get("rollouts", []):
        if info.get("fault"):
            print(f"rollout {info['style']} seed {info['seed']}: {info['fault']}, kept {info['recorded_s']:.1f} s")
    gate = lib.index.get("gate", {})
    if gate.get("left_out") or gate.get("repaired"):
        from g1_control.library.builder import gate_summary

        print(gate_summary(gate))
    return 0
