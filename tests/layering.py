"""Import layering of a package, read from its source with `ast` (nothing is imported).

Every `import` and `from ... import` counts wherever it stands: at module level, inside a function
or class, under `if TYPE_CHECKING:` (marked type-only), relative or absolute, and
`importlib.import_module("pkg.mod")` with a literal name. `from pkg import name` is an import of
the module `pkg.name` when that module exists, else of `pkg`. Imports by a computed name and
subprocesses (`python -m pkg.mod`) are not seen.

A *unit* is the first name under the package: `g1_control.trackers.wbc.qp` is in unit `trackers`,
`g1_control.rotations` is unit `rotations`. Layers are listed top to bottom; a unit may import its
own modules and units of lower layers only; units that share a layer are independent siblings.
The checks return readable messages (empty when clean); tests/test_layers.py asserts on them.
"""

from __future__ import annotations

import ast
import itertools
from collections import defaultdict
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path

ROOT_UNIT = "(root)"
"""The package's own __init__.py: importable from every layer; it imports only the units named as
`root_imports` (a public API it re-exports)."""


@dataclass(frozen=True)
class Import:
    source: str
    """The importing module (dotted)."""
    file: Path
    line: int
    target: str
    """The imported module of the package (dotted), resolved as described in the module docstring."""
    type_only: bool
    """Under `if TYPE_CHECKING:` (never runs; still a dependency of the code's design)."""

    def where(self, root: Path) -> str:
        return f"{self.file.relative_to(root).as_posix()}:{self.line}"


def module_names(package_dir: Path) -> dict[str, Path]:
    """Dotted module name -> file, for every .py file of the package (packages by their __init__.py)."""
    package_dir = Path(package_dir)
    out = {}
    for file in sorted(package_dir.rglob("*.py")):
        parts = file.relative_to(package_dir.parent).with_suffix("").parts
        if parts[-1] == "__init__":
            parts = parts[:-1]
        out[".".join(parts)] = file
    return out


def unit_of(module: str, package: str) -> str:
    rest = module[len(package):].lstrip(".")
    return rest.split(".")[0] if rest else ROOT_UNIT


def _is_type_checking(test: ast.expr) -> bool:
    return (isinstance(test, ast.Name) and test.id == "TYPE_CHECKING") or (
        isinstance(test, ast.Attribute) and test.attr == "TYPE_CHECKING")


def _walk(node: ast.AST, type_only: bool = False) -> Iterable[tuple[ast.AST, bool]]:
    """Every node below `node`, with whether it sits in the body of an `if TYPE_CHECKING:`."""
    for child in ast.iter_child_nodes(node):
        yield child, type_only
        if isinstance(child, ast.If) and _is_type_checking(child.test):
            yield child.test, type_only
            for stmt in child.body:
                yield stmt, True
                yield from _walk(stmt, True)
            for stmt in child.orelse:
                yield stmt, type_only
                yield from _walk(stmt, type_only)
        else:
            yield from _walk(child, type_only)


def _resolve(name: str, modules: dict[str, Path]) -> str:
    """The longest existing module that `name` starts with (`pkg.mod.attr` -> `pkg.mod`)."""
    while name and name not in modules:
        name = name.rpartition(".")[0]
    return name


def collect_imports(package_dir: Path) -> list[Import]:
    """Every import of the package's own modules made by the package's modules."""
    package_dir = Path(package_dir)
    package = package_dir.name
    modules = module_names(package_dir)
    found: list[Import] = []
    for source, file in modules.items():
        is_init = file.name == "__init__.py"
        tree = ast.parse(file.read_text(encoding="utf-8"), filename=str(file))
        for node, type_only in _walk(tree):
            targets: list[str] = []
            if isinstance(node, ast.Import):
                targets = [alias.name for alias in node.names]
            elif isinstance(node, ast.ImportFrom):
                if node.level:
                    base = source.split(".")
                    if not is_init:
                        base = base[:-1]
                    base = base[: len(base) - (node.level - 1)]
                    stem = ".".join(base + ([node.module] if node.module else []))
                else:
                    stem = node.module or ""
                targets = [f"{stem}.{alias.name}" if f"{stem}.{alias.name}" in modules else stem
                           for alias in node.names]
            elif isinstance(node, ast.Call) and node.args and isinstance(node.args[0], ast.Constant) \
                    and isinstance(node.args[0].value, str):
                func = node.func
                called = func.attr if isinstance(func, ast.Attribute) else func.id if isinstance(func, ast.Name) else ""
                if called in ("import_module", "__import__"):
                    targets = [node.args[0].value]
            for target in targets:
                if target == package or target.startswith(package + "."):
                    resolved = _resolve(target, modules)
                    if resolved and resolved != source:
                        found.append(Import(source, file, getattr(node, "lineno", 0), resolved, type_only))
    return found


def layer_of(layers: Sequence[Sequence[str]]) -> dict[str, int]:
    """unit -> index of its layer (0 = top)."""
    return {unit: i for i, layer in enumerate(layers) for unit in layer}


def unassigned_units(package_dir: Path, layers: Sequence[Sequence[str]], data_units: Iterable[str] = ()) -> list[str]:
    """Units (subpackages and top-level modules) of the package that no layer names."""
    package_dir = Path(package_dir)
    known = set(layer_of(layers)) | set(data_units)
    units = {unit_of(m, package_dir.name) for m in module_names(package_dir)} - {ROOT_UNIT}
    return sorted(units - known)


def unknown_layer_units(package_dir: Path, layers: Sequence[Sequence[str]], data_units: Iterable[str] = ()) -> list[str]:
    """Names in the layer list that are not units of the package (a rename left the list behind)."""
    package_dir = Path(package_dir)
    units = {unit_of(m, package_dir.name) for m in module_names(package_dir)}
    return sorted((set(layer_of(layers)) | set(data_units)) - units)


def layer_violations(package_dir: Path, layers: Sequence[Sequence[str]], data_units: Iterable[str] = (),
                     imports: list[Import] | None = None, root_imports: Iterable[str] = ()) -> list[str]:
    """One message per import that goes up a layer, across siblings, into an unassigned unit, out of
    a data unit, or out of the package root to other than `root_imports`."""
    package_dir = Path(package_dir)
    package = package_dir.name
    rank = layer_of(layers)
    data = set(data_units)
    from_root = set(root_imports)
    names = [" | ".join(layer) for layer in layers]
    out = []
    for imp in imports if imports is not None else collect_imports(package_dir):
        src, dst = unit_of(imp.source, package), unit_of(imp.target, package)
        if src == dst or dst in data or dst == ROOT_UNIT or (src == ROOT_UNIT and dst in from_root):
            continue
        what = f"{imp.where(package_dir.parent)}: {imp.source} imports {imp.target}" + (
            " (type-only)" if imp.type_only else "")
        if src in data:
            out.append(f"{what}: {src} may import nothing of {package}")
        elif src == ROOT_UNIT:
            allowed = ", ".join(sorted(from_root)) or "nothing"
            out.append(f"{what}: the package root may import {allowed} of {package}")
        elif src not in rank or dst not in rank:
            missing = " and ".join(u for u in (src, dst) if u not in rank)
            out.append(f"{what}: {missing} is in no layer")
        elif rank[dst] < rank[src]:
            out.append(f"{what}: upward, from {src} (layer {rank[src] + 1}: {names[rank[src]]}) to {dst} "
                       f"(layer {rank[dst] + 1}: {names[rank[dst]]}, above it)")
        elif rank[dst] == rank[src]:
            out.append(f"{what}: across siblings {src} and {dst} (layer {rank[src] + 1}: {names[rank[src]]}), "
                       f"which are independent")
    return out


def _cycles(edges: dict[str, set[str]]) -> list[list[str]]:
    """One cycle (as a closed path a -> ... -> a) per strongly connected component with a cycle."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    components: list[list[str]] = []

    def strongconnect(v: str) -> None:  # Tarjan's algorithm (recursion depth <= number of modules)
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in sorted(edges.get(v, ())):
            if w not in index:
                strongconnect(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                components.append(sorted(component))

    for v in sorted(edges):
        if v not in index:
            strongconnect(v)
    cycles = []
    for component in components:
        members = set(component)
        # Shortest path back to the start inside the component (breadth first).
        start = component[0]
        previous: dict[str, str] = {}
        frontier = [start]
        while frontier and start not in previous:
            nxt = []
            for v in frontier:
                for w in sorted(edges.get(v, ())):
                    if w in members and w not in previous:
                        previous[w] = v
                        nxt.append(w)
            frontier = nxt
        path = [start]
        v = previous[start]
        while v != start:
            path.append(v)
            v = previous[v]
        path.append(start)
        cycles.append(path[::-1])
    return cycles


def import_cycles(package_dir: Path, *, by_unit: bool, runtime_only: bool = True,
                  imports: list[Import] | None = None) -> list[str]:
    """Import cycles between units (by_unit) or between modules, one message per cycle. Type-only
    imports never run, so by default they do not close a cycle."""
    package_dir = Path(package_dir)
    package = package_dir.name
    imports = imports if imports is not None else collect_imports(package_dir)
    edges: dict[str, set[str]] = defaultdict(set)
    first: dict[tuple[str, str], Import] = {}
    for imp in imports:
        if runtime_only and imp.type_only:
            continue
        a, b = (unit_of(imp.source, package), unit_of(imp.target, package)) if by_unit else (imp.source, imp.target)
        if a != b:
            edges[a].add(b)
            first.setdefault((a, b), imp)
    out = []
    for cycle in _cycles(edges):
        steps = [f"{a} -> {b} at {first[(a, b)].where(package_dir.parent)}" for a, b in itertools.pairwise(cycle)]
        out.append(f"{'package' if by_unit else 'module'} import cycle: " + " -> ".join(cycle) + "; "
                   + ", ".join(steps))
    return out


# -- the layer list in the docs ----------------------------------------------------------------------

DOC_BEGIN = "<!-- layers: generated from LAYERS and NOTES in tests/test_layers.py; rewrite: python3 -m tests.test_layers --write -->"
DOC_END = "<!-- /layers -->"


def layer_list(layers: Sequence[Sequence[str]], notes: dict[str, str], data_units: Iterable[str] = ()) -> str:
    """The layers as the docs print them: a fenced block, one line per unit, top to bottom, the layer's
    number on its first unit (units under one number are independent siblings), each with its note."""
    data = list(data_units)
    width = max(len(u) for u in [*itertools.chain.from_iterable(layers), *data]) + 2
    digits = len(str(len(layers)))
    lines = []
    for i, layer in enumerate(layers):
        for k, unit in enumerate(layer):
            number = str(i + 1).rjust(digits) if k == 0 else " " * digits
            lines.append(f"{number}  {unit:<{width}}{notes.get(unit, '')}".rstrip())
    for unit in data:
        lines.append(f"{'-' * digits}  {unit:<{width}}{notes.get(unit, '')}".rstrip())
    return "\n".join(["```text", *lines, "```"])


def generated_span(text: str, where: str) -> tuple[int, int]:
    """(start, end) of what stands between DOC_BEGIN and DOC_END in `text` (the markers excluded)."""
    begin, end = text.find(DOC_BEGIN), text.find(DOC_END)
    if begin < 0 or end < begin or text.count(DOC_BEGIN) != 1:
        raise ValueError(f"{where}: expected one `{DOC_BEGIN}` line followed by a `{DOC_END}` line")
    return begin + len(DOC_BEGIN), end


def with_layer_list(text: str, block: str, where: str) -> str:
    """`text` with the part between the markers replaced by `block` (on lines of its own)."""
    start, end = generated_span(text, where)
    return text[:start] + "\n" + block + "\n" + text[end:]
