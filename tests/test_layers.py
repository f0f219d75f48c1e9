"""The import layers of g1_control hold, with no import cycles (checker: tests/layering.py).

Contracts, checked on the source with `ast` (imports at any depth, type-only ones included):
- a unit (subpackage or top-level module) imports only its own modules and units of lower layers;
  units that share a layer are independent siblings and never import each other;
- every unit is in exactly one layer (a new package is placed here deliberately), and every name
  in the list is a unit;
- data packages hold no imports of g1_control; the package root imports nothing of it;
- no import cycle between units, and none between modules (type-only imports included: two modules
  that need each other's types share a lower module);
- the layer list in README.md and docs/architecture.md is the one printed from LAYERS and NOTES here
  (`python3 -m tests.test_layers --write` rewrites it), and the README's folder table follows it.
"""

from __future__ import annotations

import itertools
import re
import shutil
import sys
import textwrap
from pathlib import Path

import pytest

from tests.layering import (
    DOC_BEGIN,
    DOC_END,
    collect_imports,
    generated_span,
    import_cycles,
    layer_list,
    layer_of,
    layer_violations,
    unassigned_units,
    unknown_layer_units,
    with_layer_list,
)
from tests.paths import REPO

PACKAGE = REPO / "g1_control"

LAYERS: tuple[tuple[str, ...], ...] = (
    ("cli", "api"),
    ("tools",),
    ("deploy", "training"),
    ("library",),
    ("launch",),
    ("program",),
    ("report",),
    ("generator", "trackers", "teleop", "retarget"),
    ("ik", "loop"),
    ("motion", "safety", "estimation"),
    ("sim",),
    ("hardware",),
    ("interfaces",),
    ("types", "scene"),
    ("robot",),
    ("config", "assets", "rotations", "resources", "fanout"),
    ("errors",),
)
"""Top to bottom. A unit may import from its own package or from lower layers only."""

DATA_UNITS = ("policies",)
"""Shipped data (policy specs, the generator's weights): read as resources, importable by any layer."""

ROOT_IMPORTS = ("api",)
"""What g1_control/__init__.py may import: the public API it re-exports (lazily)."""

NOTES: dict[str, str] = {
    "cli": "one module per `g1` subcommand",
    "api": "the public Python API (docs/api.md)",
    "tools": "benches, fault suite, evaluations",
    "deploy": "g1 deploy (preflight, state machine, session)",
    "training": "generator training (torch; never imported by the runtime)",
    "library": "motion-library builder (physics rollouts, dance, retargeted mocap)",
    "launch": "launch-file schema, the loop builder, the runner",
    "program": "behaviour programs and the English instruction parser",
    "report": "what a run leaves: run folder, figures and summary, goal outcomes, Verdict, plots, overlay, replay",
    "generator": "motion generators: velocity, in-betweening, goals, scripted references",
    "trackers": "walking policy, whole-body controller (wbc/), the tracking layer",
    "teleop": "input devices and their mappings",
    "retarget": "offline mocap retargeting, clip quality metrics",
    "ik": "whole-body differential IK on pinocchio (tasks/, limits/, QP)",
    "loop": "the control loop, the multi-rate scheduler, rates",
    "motion": "MotionClip, its file formats and edits, the library on disk",
    "safety": "limits, watchdogs, falls, the one-way switch to damping",
    "estimation": "base velocity from IMU + stance-leg kinematics",
    "sim": "MuJoCo backend, viewer, headless render, browser view, robot emulator",
    "hardware": "unitree/ (messages, CRC, IDL, remote bytes) and links/ (DDS, CAN, serial)",
    "interfaces": "the stages' abstract bases: the loop's whole contract with a stage",
    "types": "the plain dataclasses passed between stages",
    "scene": "tables, platforms, boxes (no MuJoCo)",
    "robot": "g1.py (every G1 fact), description.py (pinocchio + MuJoCo models), dynamics.py",
    "config": "the typed config loader (dataclasses are the schema)",
    "assets": "pinned registry wheels fetched into the user cache",
    "rotations": "the one quaternion / yaw module",
    "resources": "launch files and docs that ship with the package",
    "fanout": "seeded trials over --jobs processes or a --ray cluster, the same results",
    "errors": "named errors",
    "policies": "data, read by any layer: policy specs, the shipped generator models",
}
"""One line per unit for the printed layer list (docs); a unit without a note is listed bare."""

LAYER_DOCS = (REPO / "README.md", REPO / "docs" / "architecture.md")
"""Where the layer list is printed (between the DOC_BEGIN and DOC_END markers of tests/layering.py)."""


def _report(messages: list[str]) -> str:
    return f"{len(messages)} problem(s):\n  " + "\n  ".join(messages)


@pytest.fixture(scope="module")
def imports():
    return collect_imports(PACKAGE)


def test_every_package_has_exactly_one_layer():
    assert not unassigned_units(PACKAGE, LAYERS, DATA_UNITS), (
        "place each new package or top-level module in LAYERS (tests/test_layers.py): "
        f"{unassigned_units(PACKAGE, LAYERS, DATA_UNITS)}")
    assert not unknown_layer_units(PACKAGE, LAYERS, DATA_UNITS), "LAYERS names units that do not exist"
    named = [u for layer in LAYERS for u in layer] + list(DATA_UNITS)
    assert len(named) == len(set(named)), "a unit is listed twice"
    assert set(NOTES) <= set(named), f"NOTES for units in no layer: {sorted(set(NOTES) - set(named))}"


def test_imports_go_down_the_layers_only(imports):
    assert len(imports) > 500  # the checker sees the package's imports (about a thousand)
    violations = layer_violations(PACKAGE, LAYERS, DATA_UNITS, imports, ROOT_IMPORTS)
    assert not violations, _report(violations)


def test_no_import_cycle_between_packages(imports):
    cycles = import_cycles(PACKAGE, by_unit=True, runtime_only=False, imports=imports)
    assert not cycles, _report(cycles)


def test_no_import_cycle_between_modules(imports):
    cycles = import_cycles(PACKAGE, by_unit=False, imports=imports)
    assert not cycles, _report(cycles)


def test_no_import_cycle_between_modules_even_through_type_only_imports(imports):
    # Two modules that need each other's types share a lower module instead (issue 22: program/
    # device.py and judge.py both import records.py).
    cycles = import_cycles(PACKAGE, by_unit=False, runtime_only=False, imports=imports)
    assert not cycles, _report(cycles)


@pytest.mark.parametrize("doc", LAYER_DOCS, ids=lambda p: p.name)
def test_the_docs_print_the_layer_list_of_this_test(doc):
    text = doc.read_text(encoding="utf-8")
    start, end = generated_span(text, doc.name)
    expected = layer_list(LAYERS, NOTES, DATA_UNITS)
    assert text[start:end].strip("\n") == expected, (
        f"{doc.relative_to(REPO)}: its layer list differs from LAYERS/NOTES in tests/test_layers.py; "
        f"rewrite it with `python3 -m tests.test_layers --write`. Expected:\n{expected}")


README_FOLDERS = "| folder (`g1_control/...`) | contents |"


def test_the_readme_folder_table_follows_the_layers():
    """Its rows name every unit, in layer order (a row may name several units of one or more layers)."""
    text = (REPO / "README.md").read_text(encoding="utf-8")
    assert README_FOLDERS in text, f"README.md: no table headed {README_FOLDERS!r}"
    rows = text.split(README_FOLDERS, 1)[1].split("\n\n", 1)[0].strip().splitlines()[1:]
    rank = layer_of([*LAYERS, DATA_UNITS])
    order: list[str] = []
    for row in rows:
        first = row.split("|")[1]
        order += [name.strip("/").removesuffix(".py") for name in re.findall(r"`([^`]+)`", first)]
    assert sorted(order) == sorted(rank), (
        f"README.md folder table: missing {sorted(set(rank) - set(order))}, unknown {sorted(set(order) - set(rank))}")
    out_of_order = [f"{b} (layer {rank[b] + 1}) listed after {a} (layer {rank[a] + 1})"
                    for a, b in itertools.pairwise(order) if rank[a] > rank[b]]
    assert not out_of_order, f"README.md folder table is not in layer order: {out_of_order}"


def test_layer_list_text_and_markers():
    notes = {"top": "the top", "mid_b": "beside mid_a", "data": "shipped data"}
    block = layer_list(TOY_LAYERS, notes, ["data"])
    assert block.splitlines() == [
        "```text",
        "1  top    the top",
        "2  mid_a",
        "   mid_b  beside mid_a",
        "3  low",
        "-  data   shipped data",
        "```"]
    doc = f"intro\n{DOC_BEGIN}\nold list\n{DOC_END}\nafter\n"
    new = with_layer_list(doc, block, "doc.md")
    assert new == f"intro\n{DOC_BEGIN}\n{block}\n{DOC_END}\nafter\n"
    start, end = generated_span(new, "doc.md")
    assert new[start:end].strip("\n") == block
    with pytest.raises(ValueError, match="doc.md: expected one"):
        generated_span("no markers here", "doc.md")
    with pytest.raises(ValueError, match="doc.md: expected one"):
        generated_span(f"{DOC_END}\n{DOC_BEGIN}\n", "doc.md")


def write_layer_docs() -> list[str]:
    """Rewrite the layer list in LAYER_DOCS; the names of the files that changed."""
    changed = []
    block = layer_list(LAYERS, NOTES, DATA_UNITS)
    for doc in LAYER_DOCS:
        text = doc.read_text(encoding="utf-8")
        new = with_layer_list(text, block, doc.name)
        if new != text:
            doc.write_text(new, encoding="utf-8")
            changed.append(str(doc.relative_to(REPO)))
    return changed


# -- the checker itself, on small package trees --------------------------------------------------

TOY_LAYERS = (("top",), ("mid_a", "mid_b"), ("low",))


def _tree(root: Path, files: dict[str, str]) -> Path:
    """A package `toy` under root with `files` (path relative to the package -> source)."""
    pkg = root / "toy"
    for rel, text in {"__init__.py": "", **files}.items():
        path = pkg / rel
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(textwrap.dedent(text))
        if path.parent != pkg and not (path.parent / "__init__.py").exists():
            (path.parent / "__init__.py").write_text("")
    return pkg


CLEAN = {
    "top/__init__.py": "from toy.mid_a import run\n",
    "top/app.py": "import toy.low.util\nfrom toy.mid_b.part import piece\nfrom toy import low\n",
    "mid_a/__init__.py": "from toy.mid_a.run import run\n",
    "mid_a/run.py": "from . import helpers\nfrom ..low import util\n\ndef run():\n    from toy.low.util import f\n",
    "mid_a/helpers.py": "from toy.low import util\n",
    "mid_b/part.py": "from toy.low.util import f as piece\n",
    "low/util.py": "import os\n\ndef f():\n    return os.sep\n",
}


def test_checker_passes_a_clean_tree(tmp_path):
    pkg = _tree(tmp_path, CLEAN)
    assert unassigned_units(pkg, TOY_LAYERS) == []
    assert layer_violations(pkg, TOY_LAYERS) == []
    assert import_cycles(pkg, by_unit=True) == []
    assert import_cycles(pkg, by_unit=False) == []
    seen = {(i.source, i.target) for i in collect_imports(pkg)}
    # relative and `from pkg import module` forms resolve to the module
    assert ("toy.mid_a.run", "toy.mid_a.helpers") in seen
    assert ("toy.mid_a.run", "toy.low.util") in seen
    assert ("toy.top.app", "toy.low") in seen
    assert ("toy.mid_b.part", "toy.low.util") in seen


@pytest.mark.parametrize("rel, source, line, needle", [
    # a function-level upward import
    ("low/util.py", "def g():\n    from toy.top.app import x\n", 2,
     "upward, from low (layer 3: low) to top (layer 1: top, above it)"),
    # `from pkg import unit` across siblings
    ("mid_a/helpers.py", "from toy import mid_b\n", 1, "across siblings mid_a and mid_b (layer 2: mid_a | mid_b)"),
    # a relative import going up
    ("low/deep/mod.py", "from ...top import app\n", 1, "toy.low.deep.mod imports toy.top.app: upward, from low"),
    # an import only for the type checker still counts
    ("low/typed.py", "from typing import TYPE_CHECKING\n\nif TYPE_CHECKING:\n    from toy.mid_a.run import run\n", 4,
     "(type-only): upward, from low"),
    # importlib with a literal name
    ("low/dyn.py", "import importlib\n\n\ndef h():\n    return importlib.import_module('toy.top.app')\n", 5,
     "upward, from low"),
    # in a class body, inside a try
    ("mid_b/cls.py", "class C:\n    try:\n        import toy.top\n    except ImportError:\n        pass\n", 3,
     "toy.mid_b.cls imports toy.top: upward, from mid_b"),
])
def test_checker_names_file_line_and_both_layers(tmp_path, rel, source, line, needle):
    pkg = _tree(tmp_path, {**CLEAN, rel: source})
    violations = layer_violations(pkg, TOY_LAYERS)
    assert len(violations) == 1, violations
    assert violations[0].startswith(f"toy/{rel}:{line}: "), violations[0]
    assert needle in violations[0], violations[0]


def test_checker_refuses_unplaced_packages_and_data_imports(tmp_path):
    pkg = _tree(tmp_path, {**CLEAN, "extra/thing.py": "", "data/__init__.py": "import toy.low\n",
                           "top/uses.py": "import toy.extra.thing\nimport toy.data\n"})
    assert unassigned_units(pkg, TOY_LAYERS, ["data"]) == ["extra"]
    assert unknown_layer_units(pkg, (*TOY_LAYERS, ("gone",)), ["data"]) == ["gone"]
    violations = layer_violations(pkg, TOY_LAYERS, ["data"])
    assert any("toy/top/uses.py:1" in v and "extra is in no layer" in v for v in violations), violations
    assert any("toy/data/__init__.py:1" in v and "data may import nothing of toy" in v for v in violations), violations
    assert not any("toy/top/uses.py:2" in v for v in violations)  # data is importable from any layer
    # the package root re-exports a public unit only
    pkg = _tree(tmp_path / "r", {**CLEAN, "__init__.py": "def __getattr__(name):\n    from toy import top\n"
                                                          "    from toy.low import util\n"})
    assert layer_violations(pkg, TOY_LAYERS, root_imports=["top"]) == [
        "toy/__init__.py:3: toy imports toy.low.util: the package root may import top of toy"]


def test_checker_reports_cycles(tmp_path):
    pkg = _tree(tmp_path, {
        **CLEAN,
        # modules: a -> b -> c -> a (the last one inside a function, as cycles usually hide)
        "low/a.py": "from toy.low import b\n",
        "low/b.py": "import toy.low.c\n",
        "low/c.py": "def f():\n    from toy.low.a import x\n",
        # packages: mid_b -> low (allowed) and low -> mid_b (upward)
        "low/up.py": "from toy.mid_b import part\n",
    })
    modules = import_cycles(pkg, by_unit=False)
    assert modules == ["module import cycle: toy.low.a -> toy.low.b -> toy.low.c -> toy.low.a; "
                       "toy.low.a -> toy.low.b at toy/low/a.py:1, toy.low.b -> toy.low.c at toy/low/b.py:1, "
                       "toy.low.c -> toy.low.a at toy/low/c.py:2"]
    packages = import_cycles(pkg, by_unit=True)
    assert len(packages) == 1 and packages[0].startswith("package import cycle: low -> mid_b -> low; ")
    # a cycle closed only by a type-only import never runs: not a module cycle by default
    pkg2 = _tree(tmp_path / "t", {"m1.py": "import toy.m2\n",
                                  "m2.py": "from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n    import toy.m1\n"})
    assert import_cycles(pkg2, by_unit=False) == []
    assert len(import_cycles(pkg2, by_unit=False, runtime_only=False)) == 1


def test_a_deliberate_violation_in_a_copy_of_g1_control_fails(tmp_path):
    """The real layer list on a copy of the real package, with one bad import added."""
    copy = tmp_path / "g1_control"
    shutil.copytree(PACKAGE, copy, ignore=lambda _, names: [n for n in names if n == "__pycache__"
                                                           or (n.endswith((".onnx", ".pt", ".png", ".json")))])
    assert layer_violations(copy, LAYERS, DATA_UNITS, root_imports=ROOT_IMPORTS) == []
    target = copy / "rotations.py"
    lines = target.read_text().splitlines()
    target.write_text("\n".join([*lines, "", "", "def _bad():", "    from g1_control.launch import builder", ""]))
    violations = layer_violations(copy, LAYERS, DATA_UNITS, root_imports=ROOT_IMPORTS)
    rank = layer_of(LAYERS)
    assert violations == [
        f"g1_control/rotations.py:{len(lines) + 4}: g1_control.rotations imports g1_control.launch.builder: upward, "
        f"from rotations (layer {rank['rotations'] + 1}: {' | '.join(LAYERS[rank['rotations']])}) to launch "
        f"(layer {rank['launch'] + 1}: launch, above it)"]


if __name__ == "__main__":
    if sys.argv[1:] != ["--write"]:
        sys.exit("usage: python3 -m tests.test_layers --write   (rewrites the layer list in README.md and "
                 "docs/architecture.md from LAYERS and NOTES)")
    print("\n".join(f"rewrote the layer list in {name}" for name in write_layer_docs()) or "the docs are up to date")
