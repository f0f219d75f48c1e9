"""`g1 train generator | lmm`: train the motion generator's models on this CPU (fixed seeds).

    g1 train generator                              # the shared model (every skeleton) -> policies/generator/
    g1 train generator -o runs/gen_23 --skeletons g1_23dof   # a model for one variant
    g1 train generator -o runs/gen --steps 500      # a quick experiment elsewhere
    torchrun --nproc-per-node 4 -m g1_control.cli.main train generator -o runs/gen_ddp
    g1 train lmm                                    # learned motion matching -> policies/generator/lmm/

Needs the motion libraries (`g1 library build [--variant ...]`; built on first use). The backbone
run writes backbone.onnx (runtime model), model.json (skeletons), style_stats.json, feedback.npz
(reference mixtures) and train_config.json, and the records the runtime never reads, backbone.pt
(checkpoint), loss_history.json and loss.png, keeping the model with the lowest loss on held-out
clips. The records go next to the model, except for the shipped models (no -o), whose records go to
the repository's training_records/ (--records overrides), outside the import package. A run stops at its step
count or its time limit (default 25 min), whichever comes first, with the learning-rate schedule
finished either way. Under torchrun each process samples its own windows and gradients are
averaged (DDP, gloo backend, so it runs on CPUs). scripts/retrain_generator.sh retrains all.
"""

from __future__ import annotations

import argparse


def register(subparsers) -> None:
    parser = subparsers.add_parser("train", help="train a learned model of the project (generator backbone)",
                                   description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="train_target", metavar="MODEL", required=True)
    gen = sub.add_parser("generator", help="the in-betweening backbone of the motion generator",
                         description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    gen.add_argument("-o", "--output", help="output folder (default: policies/generator, the shipped model)")
    gen.add_argument("--records", help="folder for the checkpoint, loss history and plot (default: the output "
                     "folder; for the shipped model, training_records/generator)")
    gen.add_argument("--library", help="motion library folder (default: the user cache; built when missing)")
    gen.add_argument("--steps", type=int, default=6000, help="optimizer steps (default 6000)")
    gen.add_argument("--skeletons", default=None,
                     help="comma-separated skeletons to train on (default: all three, one shared model; with "
                          "--library, that library's skeleton)")
    gen.add_argument("--batch", type=int, default=128, help="windows per step over all processes (default 128)")
    gen.add_argument("--lr", type=float, default=1e-3, help="peak learning rate (default 1e-3)")
    gen.add_argument("--time-limit", type=float, default=25.0, metavar="MIN",
                     help="stop after this many minutes of the process' CPU time, keeping the best model (default 25)")
    gen.add_argument("--wall-limit", type=float, default=50.0, metavar="MIN",
                     help="stop after this many minutes of wall time whatever the load (default 50)")
    gen.add_argument("--threads", type=int, default=1, help="torch threads per process (default 1: fastest here)")
    gen.add_argument("--seed", type=int, default=0)
    gen.add_argument("--eval-every", type=int, default=250, help="steps between held-out evaluations (default 250)")
    gen.add_argument("--skate-weight", type=float, default=0.1,
                     help="weight of the foot-skating term: the predicted feet's horizontal speed (m/s) where the "
                          "true foot stands; 0 turns it off (default 0.1)")
    gen.add_argument("--model", metavar="JSON", default="{}",
                     help='backbone size overrides, e.g. \'{"d_model": 96, "layers": 4}\' (default: BackboneConfig)')
    gen.set_defaults(func=_generator)
    lmm = sub.add_parser("lmm", help="learned motion matching: decompressor, stepper, projector",
                         description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    lmm.add_argument("-o", "--output", help="output folder (default: policies/generator/lmm, the shipped model)")
    lmm.add_argument("--records", help="folder for the checkpoint, loss history and plot (default: the output "
                     "folder; for the shipped model, training_records/generator/lmm)")
    lmm.add_argument("--library", help="motion library folder (default: the skeleton's library in the user cache)")
    lmm.add_argument("--skeleton", default="g1_29dof", help="skeleton (default g1_29dof)")
    lmm.add_argument("--time-limit", type=float, default=25.0, metavar="MIN",
                     help="total minutes of the process' CPU time (default 25)")
    lmm.add_argument("--wall-limit", type=float, default=50.0, metavar="MIN", help="wall-clock cap in minutes (default 50)")
    lmm.add_argument("--scale", type=float, default=1.0, help="multiplies every stage's step count (tests: 0.01)")
    lmm.add_argument("--seed", type=int, default=0)
    lmm.set_defaults(func=_lmm)


def _generator(args) -> int:
    import json

    from g1_control.errors import G1ControlError
    from g1_control.generator.learned import SHIPPED_DIR
    from g1_control.generator.skeleton import SKELETONS
    from g1_control.library.builder import build_library
    from g1_control.motion.library import default_library_dir
    from g1_control.training.train import TrainConfig, train

    try:
        model = json.loads(args.model)
    except json.JSONDecodeError as exc:
        raise G1ControlError(f"--model must be a JSON object of BackboneConfig fields: {exc}") from None
    if args.skate_weight < 0:
        raise G1ControlError(f"--skate-weight must be >= 0 (0 turns the foot-skating term off), got {args.skate_weight}")
    if args.skeletons:
        skeletons = tuple(s for s in args.skeletons.split(",") if s)
    elif args.library:
        from g1_control.generator.data import library_variant
        from g1_control.motion.library import MotionLibrary

        skeletons = (library_variant(MotionLibrary(args.library)),)
    else:
        skeletons = SKELETONS
    if args.library is None:
        from g1_control.library.variants import build_variant_library

        build_library(default_library_dir())  # a no-op when the cached library matches
        for sk in skeletons:
            build_variant_library(sk)
    elif len(skeletons) != 1:
        raise G1ControlError("--library names one library: give one skeleton with --skeletons")
    config = TrainConfig(steps=args.steps, batch=args.batch, lr=args.lr, time_limit_s=args.time_limit * 60,
                         wall_limit_s=args.wall_limit * 60,
                         threads=args.threads, seed=args.seed, eval_every=args.eval_every, model=model,
                         skeletons=skeletons, skate_weight=args.skate_weight)
    from g1_control.training import TRAINING_RECORDS_DIR

    out = args.output or SHIPPED_DIR
    records = args.records or (None if args.output else TRAINING_RECORDS_DIR / "generator")
    result = train(out, config, args.library, records_dir=records)
    if result.get("best_val_loss") is not None:
        print(f"trained {result['steps']} steps in {result['wall_s'] / 60:.1f} min ({result['cpu_s'] / 60:.1f} CPU-min) "
              f"(world size {result['world_size']}); best held-out loss {result['best_val_loss']:.4f}; "
              f"written to {out}")
    return 0


def _lmm(args) -> int:
    from g1_control.generator.lmm import SHIPPED_LMM_DIR
    from g1_control.library.builder import build_library
    from g1_control.motion.library import default_library_dir
    from g1_control.training.lmm import LmmTrainConfig, train_lmm

    if args.library is None:
        from g1_control.library.variants import build_variant_library

        build_library(default_library_dir())
        build_variant_library(args.skeleton)
    from g1_control.training import TRAINING_RECORDS_DIR

    out = args.output or SHIPPED_LMM_DIR
    records = args.records or (None if args.output else TRAINING_RECORDS_DIR / "generator" / "lmm")
    result = train_lmm(out, LmmTrainConfig(seed=args.seed, time_limit_s=args.time_limit * 60,
                                           wall_limit_s=args.wall_limit * 60, scale=args.scale,
                                           skeleton=args.skeleton), args.library, records_dir=records)
    print(f"trained learned motion matching in {result['wall_s'] / 60:.1f} min ({result['cpu_s'] / 60:.1f} CPU-min); "
          f"written to {out}")
    return 0
