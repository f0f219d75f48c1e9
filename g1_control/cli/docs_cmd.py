"""`g1 docs [TOPIC]`: the documentation that comes with g1-control, in the terminal."""

from __future__ import annotations


def register(subparsers) -> None:
    parser = subparsers.add_parser(
        "docs",
        help="show the documentation (README, architecture, API, package READMEs)",
        description="Print a document that comes with g1-control: the README, docs/ (architecture, API, robot "
        "facts), the license texts, and each package's README (deploy, teleop, generator, ...). Without "
        "TOPIC, list the topics and where the files are.",
    )
    parser.add_argument("topic", nargs="?", help="topic name (g1 docs lists them)")
    parser.add_argument("--path", action="store_true", help="print the file's path instead of its text")
    parser.set_defaults(func=_run)


def _run(args) -> int:
    from g1_control.errors import G1ControlError
    from g1_control.resources import docs

    topics = docs()
    if not args.topic:
        for name, path in topics.items():
            print(f"  {name:14s} {path}")
        print("g1 docs TOPIC prints one")
        return 0
    if args.topic not in topics:
        raise G1ControlError(f"no document '{args.topic}'; topics: {', '.join(topics)}")
    print(topics[args.topic] if args.path else topics[args.topic].read_text())
    return 0
