"""`g1 train generator`: train the motion generator's in-betweening backbone on this CPU.

    g1 train generator                              # ships into policies/generator/
    g1 train generator -o runs/gen --steps 500      # a quick experiment elsewhere
    torchrun --nproc-per-node 4 -m g1_control.cli.main train generator -o runs/gen_ddp

Needs the motion library (`g1 library build`; built on first use). Writes backbone.pt (checkpoint),
backbone.onnx (runtime model), train_config.json, loss_history.json and loss.png, keeping the
model with the lowest loss on held-out clips. The shipped run takes about 15 minutes on one
core of this machine; under torchrun each process samples its own windows and gradients are
averaged (DDP, gloo backend, so it runs on CPUs).
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
    gen.add_argument("--library", help="motion library folder (default: the user cache; built when missing)")
    gen.add_argument("--steps", type=int, default=7000, help="optimizer steps (default 7000)")
    gen.add_argument("--batch", type=int, default=128, help="windows per step over all processes (default 128)")
    gen.add_argument("--lr", type=float, default=1e-3, help="peak learning rate (default 1e-3)")
    gen.add_argument("--time-limit", type=float, default=25.0, metavar="MIN",
                     help="stop after this many minutes, keeping the best model (default 25)")
    gen.add_argument("--threads", type=int, default=1, help="torch threads per process (default 1: fastest here)")
    gen.add_argument("--seed", type=int, default=0)
    gen.add_argument("--eval-every", type=int, default=250, help="steps between held-out evaluations (default 250)")
    gen.add_argument("--model", metavar="JSON", default="{}",
                     help='backbone size overrides, e.g. \'{"d_model": 96, "layers": 4}\' (default: BackboneConfig)')
    gen.set_defaults(func=_generator)


def _generator(args) -> int:
    from g1_control.generator.learned import SHIPPED_DIR
    from g1_control.library.builder import build_library
    from g1_control.motion.library import default_library_dir
    from g1_control.training.train import TrainConfig, train

    library = args.library or default_library_dir()
    if args.library is None:
        build_library(library)  # a no-op when the cached library matches
    import json

    from g1_control.errors import G1ControlError

    try:
        model = json.loads(args.model)
    except json.JSONDecodeError as exc:
        raise G1ControlError(f"--model must be a JSON object of BackboneConfig fields: {exc}") from None
    config = TrainConfig(steps=args.steps, batch=args.batch, lr=args.lr, time_limit_s=args.time_limit * 60,
                         threads=args.threads, seed=args.seed, eval_every=args.eval_every, model=model)
    out = args.output or SHIPPED_DIR
    result = train(out, config, library)
    if result.get("best_val_loss") is not None:
        print(f"trained {result['steps']} steps in {result['wall_s'] / 60:.1f} min "
              f"(world size {result['world_size']}); best held-out loss {result['best_val_loss']:.4f}; "
              f"written to {out}")
    return 0
