"""Files that ship with g1-control besides its code: the launch files and the documentation.

In a source checkout (editable install, or `PYTHONPATH=.`) they are the repository's own
`launch/*.yaml`, `README.md`, `docs/*.md`, `LICENSE` and `THIRD_PARTY_LICENSES.md`. A wheel
carries copies of the same files under `g1_control/_shipped/` (written by setup.py's build
step), so an installed package finds them without the repository:

    g1 launch sim_walk          # a shipped launch file by name
    g1 launch --list
    g1 init my_launch_files     # copy them somewhere to edit
    g1 docs deploy              # print a README
"""

from __future__ import annotations

import shutil
from pathlib import Path

from g1_control.errors import LaunchFileError

PACKAGE_DIR = Path(__file__).resolve().parent
SHIPPED_DIR = PACKAGE_DIR / "_shipped"
"""Where a wheel keeps the launch files and docs (absent in a source checkout)."""
SOURCE_ROOT = PACKAGE_DIR.parent
"""The repository root when running from a checkout."""

ROOT_DOCS = ("README.md", "LICENSE", "THIRD_PARTY_LICENSES.md")


def launch_dir() -> Path:
    """The folder of the launch files that come with this installation."""
    shipped = SHIPPED_DIR / "launch"
    return shipped if shipped.is_dir() else SOURCE_ROOT / "launch"


def launch_files() -> dict[str, Path]:
    """Shipped launch files by name (file stem), sorted."""
    folder = launch_dir()
    return {p.stem: p for p in sorted(folder.glob("*.yaml"))} if folder.is_dir() else {}


def resolve_launch(arg: str | Path) -> tuple[Path, bool]:
    """(path, shipped): `arg` as a path when that file exists, else a shipped launch file.

    A shipped file is found by name (`sim_walk`, `sim_walk.yaml`) or by the path the README uses
    (`launch/sim_walk.yaml`), so the quick start works from any directory once installed.
    """
    path = Path(arg)
    if path.is_file():
        return path, False
    known = launch_files()
    name = path.name[:-5] if path.name.endswith(".yaml") else path.name
    bare = len(path.parts) == 1 or (len(path.parts) == 2 and path.parts[0] == "launch")
    if bare and name in known:
        return known[name], True
    hint = f"; shipped launch files: {', '.join(known)} (g1 launch --list)" if known else ""
    raise LaunchFileError(f"{arg}: no such launch file{hint}")


def copy_launch_files(dest: Path, *, force: bool = False) -> list[Path]:
    """Copy every shipped launch file into `dest` (made if missing); refuse to overwrite unless `force`."""
    dest.mkdir(parents=True, exist_ok=True)
    sources = launch_files()
    clash = [dest / p.name for p in sources.values() if (dest / p.name).exists()]
    if clash and not force:
        raise LaunchFileError(f"{dest}: {', '.join(p.name for p in clash)} already there; pass --force to overwrite")
    written = []
    for src in sources.values():
        shutil.copyfile(src, dest / src.name)
        written.append(dest / src.name)
    return written


def docs() -> dict[str, Path]:
    """Documentation by topic: `readme`, `license`, `third-party`, each docs/*.md by stem, and each
    package README by package name (`deploy`, `teleop`, ...)."""
    shipped = SHIPPED_DIR / "docs"
    root = shipped if shipped.is_dir() else SOURCE_ROOT
    topics: dict[str, Path] = {}
    for name, topic in zip(ROOT_DOCS, ("readme", "license", "third-party")):
        if (root / name).is_file():
            topics[topic] = root / name
    doc_dir = shipped if shipped.is_dir() else SOURCE_ROOT / "docs"
    for p in sorted(doc_dir.glob("*.md")):
        if p.name not in ROOT_DOCS:
            topics.setdefault(p.stem, p)
    for p in sorted(PACKAGE_DIR.glob("*/README.md")):
        topics.setdefault(p.parent.name, p)
    return topics
