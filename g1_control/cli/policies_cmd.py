"""`g1 policies fetch|list`: the pretrained policies a registry package ships."""

from __future__ import annotations

from pathlib import Path


def register(subparsers) -> None:
    parser = subparsers.add_parser(
        "policies",
        help="fetch or list tracking policies",
        description="Pretrained G1 policies come from the registry package holosoma-inference: `fetch` downloads "
        "that pinned wheel with pip (no dependencies), checks its SHA-256 and extracts only the ONNX files into "
        "the user cache ($G1_CONTROL_CACHE or ~/.cache/g1-control). First use of a policy fetches it too.",
    )
    sub = parser.add_subparsers(dest="action", metavar="ACTION", required=True)
    fetch = sub.add_parser("fetch", help="download and verify the policy files",
                           description="Download the pinned wheel of an asset (holosoma-policies by default; "
                           "holosoma-demo-mocap for the demo motion capture) with pip, check its SHA-256 and "
                           "extract the listed files into the cache. Offline, or without pip in this "
                           "environment: download the wheel elsewhere and pass --wheel FILE.")
    fetch.add_argument("--force", action="store_true", help="download again even if cached")
    fetch.add_argument("--wheel", type=Path, help="use this already-downloaded wheel instead of the registry")
    fetch.add_argument("--asset", default="holosoma-policies", help="asset name (default holosoma-policies)")
    fetch.set_defaults(func=_fetch)
    lst = sub.add_parser("list", help="list built-in policy specs and whether their files are cached",
                         description="List the built-in policy specs (names usable as tracker.policy), their "
                         "kind, and whether their ONNX files are in the cache.")
    lst.set_defaults(func=_list)


def _fetch(args) -> int:
    from g1_control import assets

    folder = assets.fetch(args.asset, force=args.force, wheel=args.wheel)
    files = sorted(p for p in folder.rglob("*") if p.is_file() and p.name != ".complete")
    print(f"{args.asset}: {len(files)} files in {folder}  (license: {assets.ASSETS[args.asset].license})")
    for f in files:
        print(f"  {f.relative_to(folder)}  {f.stat().st_size / 1e6:.1f} MB")
    return 0


def _list(args) -> int:
    import yaml

    from g1_control import assets
    from g1_control.trackers.policy_spec import builtin_specs

    for name, path in sorted(builtin_specs().items()):
        d = yaml.safe_load(path.read_text())
        onnx = d.get("onnx", {})
        cached = assets.is_fetched(onnx["asset"]) if isinstance(onnx, dict) and "asset" in onnx else True
        print(f"{name:28s} {d.get('kind', '?'):11s} {'cached' if cached else 'not fetched'}  {path}")
    return 0
