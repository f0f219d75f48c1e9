"""The tests mirror the package: tests/<package>/... for g1_control/<package>/..., unique basenames.

- Every folder under tests/ is a package of g1_control at the same path (tests/trackers/wbc/ for
  g1_control/trackers/wbc/), so a package's tests are found where the package is; the one other
  kind is a test folder for a folder of the repository (OTHER_FOLDERS: tests/examples/ for examples/).
- Test files at the root of tests/ test a top-level module (test_rotations.py for
  g1_control/rotations.py) or the package as a whole (WHOLE_PACKAGE_TESTS).
- Python file basenames are unique across tests/ (conftest.py aside): pytest imports test files,
  and the helpers they import, by basename.
"""

from __future__ import annotations

from collections import defaultdict
from pathlib import Path

from tests.paths import REPO

TESTS = REPO / "tests"
PACKAGE = REPO / "g1_control"

WHOLE_PACKAGE_TESTS = {"test_layers.py", "test_tests_mirror_packages.py", "test_packaging_wheel.py",
                       "test_package_docs.py", "test_timing_reruns.py"}
"""Root test files about g1_control as a whole rather than one module."""
OTHER_FOLDERS = {"examples": REPO / "examples"}
"""Test folders for folders of the repository that are not packages of g1_control."""


def _python_files() -> list[Path]:
    return sorted(p for p in TESTS.rglob("*.py") if "__pycache__" not in p.parts)


def test_every_test_folder_mirrors_a_package():
    folders = sorted({p.parent for p in _python_files()} - {TESTS})
    assert folders, "expected tests/<package>/ folders"
    # A package: a folder of g1_control with Python modules (an __init__.py or a namespace package).
    stray = [f.relative_to(REPO).as_posix() for f in folders
             if not any((PACKAGE / f.relative_to(TESTS)).glob("*.py"))
             and not OTHER_FOLDERS.get(f.relative_to(TESTS).parts[0], REPO / "-").is_dir()]
    assert not stray, f"test folders with no g1_control package at the same path: {stray}"


def test_root_test_files_test_a_top_level_module_or_the_whole_package():
    modules = sorted(p.stem for p in PACKAGE.glob("*.py") if p.stem != "__init__")
    assert {"rotations", "config", "errors"} <= set(modules)
    stray = [p.name for p in TESTS.glob("test_*.py") if p.name not in WHOLE_PACKAGE_TESTS
             and not any(p.stem == f"test_{m}" or p.stem.startswith(f"test_{m}_") for m in modules)]
    assert not stray, (f"tests/ root holds tests of top-level modules ({', '.join(modules)}) only; move {stray} "
                       "to tests/<package>/")


def test_basenames_are_unique():
    by_name: dict[str, list[str]] = defaultdict(list)
    for p in _python_files():
        if p.name not in ("conftest.py", "__init__.py"):
            by_name[p.name].append(p.relative_to(REPO).as_posix())
    clashes = {name: paths for name, paths in by_name.items() if len(paths) > 1}
    assert not clashes, f"python files under tests/ that share a basename: {clashes}"
