"""The package's own descriptions stay true to the code.

- Every module or folder a package docstring (`__init__.py`) names exists. Names are paths: `name.py`
  or `folder/`, relative to that package, to g1_control/ or to the repository (`tasks/`,
  `unitree/crc.py`, `sim/motor_law.py`); bare words are prose and not checked.
- docs/architecture.md's interface table names every public member of every interface in
  g1_control/interfaces.py.
(The layer list in the docs: tests/test_layers.py.)
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

from tests.paths import REPO

PACKAGE = REPO / "g1_control"

_PY = re.compile(r"(?<![\w./-])((?:[A-Za-z_]\w*/)*[A-Za-z_]\w*\.py)\b")
_FOLDER = re.compile(r"(?<![\w./-])((?:[A-Za-z_]\w*/)+)(?=[\s,;:)]|$)")


def named_paths(docstring: str) -> list[str]:
    """The module and folder paths a docstring names, in order of appearance."""
    found = [(m.start(), m.group(1)) for rx in (_PY, _FOLDER) for m in rx.finditer(docstring)]
    return [name for _, name in sorted(found)]


def missing_modules(package_dir: Path, repo: Path) -> list[str]:
    """'<package>/__init__.py: names <path>, which does not exist' for every path a package docstring
    names that is neither under that package, nor under `package_dir`, nor under `repo`."""
    out = []
    for init in sorted(package_dir.rglob("__init__.py")):
        doc = ast.get_docstring(ast.parse(init.read_text(encoding="utf-8"))) or ""
        for name in named_paths(doc):
            if not any((base / name).exists() for base in (init.parent, package_dir, repo)):
                out.append(f"{init.relative_to(repo).as_posix()}: names {name}, which does not exist")
    return out


def test_every_module_a_package_docstring_names_exists():
    assert len([p for p in PACKAGE.rglob("__init__.py")]) > 20
    names = sum(len(named_paths(ast.get_docstring(ast.parse(p.read_text())) or "")) for p in PACKAGE.rglob("__init__.py"))
    assert names > 50  # the checker sees the docstrings' module lists
    missing = missing_modules(PACKAGE, REPO)
    assert not missing, "package docstrings name modules that moved:\n  " + "\n  ".join(missing)


def test_the_checker_finds_paths_and_skips_prose(tmp_path):
    doc = ("Modules:\n    solver.py   the QP\n    tasks/      costs (m/s, left/right, and/or)\n"
           "the robot side is sim/robot_endpoint.py; see ../README.md and g1_control.sim.web, model.onnx")
    assert named_paths(doc) == ["solver.py", "tasks/", "sim/robot_endpoint.py"]
    pkg = tmp_path / "toy"
    (pkg / "ik" / "tasks").mkdir(parents=True)
    (pkg / "sim").mkdir()
    (pkg / "sim" / "robot_endpoint.py").write_text("")
    (pkg / "ik" / "solver.py").write_text("")
    (pkg / "ik" / "__init__.py").write_text(f'"""{doc}\n    bench.py    moved away\n"""\n')
    assert missing_modules(pkg, tmp_path) == ["toy/ik/__init__.py: names bench.py, which does not exist"]
    (pkg / "ik" / "tasks").rmdir()
    assert missing_modules(pkg, tmp_path) == ["toy/ik/__init__.py: names tasks/, which does not exist",
                                              "toy/ik/__init__.py: names bench.py, which does not exist"]


def _interface_members() -> dict[str, list[str]]:
    tree = ast.parse((PACKAGE / "interfaces.py").read_text(encoding="utf-8"))
    out = {}
    for node in tree.body:
        if isinstance(node, ast.ClassDef):
            names = []
            for item in node.body:
                if isinstance(item, ast.FunctionDef | ast.AsyncFunctionDef) and not item.name.startswith("_"):
                    names.append(item.name)
                elif isinstance(item, ast.AnnAssign) and isinstance(item.target, ast.Name):
                    names.append(item.target.id)
            out[node.name] = names
    return out


def test_the_architecture_doc_lists_every_interface_member():
    members = _interface_members()
    assert {"Backend", "InputDevice", "Generator", "Retargeter", "Tracker"} <= set(members)
    assert {"step_ticks", "peer_fault", "lockstep"} <= set(members["Backend"])
    text = (REPO / "docs" / "architecture.md").read_text(encoding="utf-8")
    rows = {m.group(1): m.group(2) for m in re.finditer(r"^\| `(\w+)` \| (.*?) \|", text, re.MULTILINE)}
    problems = []
    for cls, names in members.items():
        if cls not in rows:
            problems.append(f"{cls}: no row in the interface table")
            continue
        problems += [f"{cls}: `{name}` not listed" for name in names
                     if not re.search(rf"`{name}\b", rows[cls])]
    assert not problems, "docs/architecture.md, Interfaces:\n  " + "\n  ".join(problems)
