"""Typed configuration from plain dicts (YAML): dataclasses are the schema.

`from_dict(Cls, data, path)` builds a dataclass, refusing unknown keys, missing required fields
and wrong types with one error that names the key path ("tracker.rate_hz: expected a number,
got 'fast'"). Supported field types: bool, int, float, str, Literal[...], X | None, list[X],
tuple[X, ...], dict[str, X] and nested dataclasses.
"""

from __future__ import annotations

import dataclasses
import itertools
import math
import types
import typing
from typing import TYPE_CHECKING, Any, Literal, TypeVar

from g1_control.errors import LaunchFileError

if TYPE_CHECKING:
    from _typeshed import DataclassInstance

T = TypeVar("T", bound="DataclassInstance")


def _type_name(tp) -> str:
    origin = typing.get_origin(tp)
    if origin is Literal:
        return "one of " + ", ".join(repr(a) for a in typing.get_args(tp))
    if origin in (list, tuple):
        return "a list"
    if origin is dict:
        return "a mapping"
    if isinstance(tp, type) and dataclasses.is_dataclass(tp):
        return f"a mapping of {tp.__name__} fields"
    return {bool: "true or false", int: "an integer", float: "a number", str: "a string"}.get(tp, getattr(tp, "__name__", str(tp)))


def _shape_matches(tp, value) -> bool:
    """Whether `value` has the outer shape of type `tp` (so an error inside it is the one to report)."""
    origin = typing.get_origin(tp)
    if origin is Literal:
        return any(type(value) is type(a) for a in typing.get_args(tp))
    if origin in (list, tuple):
        return isinstance(value, (list, tuple))
    if origin is dict or dataclasses.is_dataclass(tp):
        return isinstance(value, dict)
    if tp is bool:
        return isinstance(value, bool)
    if tp in (int, float):
        return isinstance(value, (int, float)) and not isinstance(value, bool)
    if tp is str:
        return isinstance(value, str)
    return False


def _convert(tp, value: Any, path: str, error: type[Exception]):
    origin, args = typing.get_origin(tp), typing.get_args(tp)
    if origin in (typing.Union, types.UnionType):
        if value is None and type(None) in args:
            return None
        inner = [a for a in args if a is not type(None)]
        failures: list[tuple[object, Exception]] = []
        for a in inner:
            try:
                return _convert(a, value, path, error)
            except error as exc:
                failures.append((a, exc))
        # Report the alternative the value was shaped for (a mapping for a dataclass, a list for a
        # list...): its own message names the inner key that is wrong.
        shaped = [exc for a, exc in failures if _shape_matches(a, value)]
        if len(shaped) == 1:
            raise shaped[0]
        names = " or ".join(_type_name(a) for a, _ in failures) + (" or null" if type(None) in args else "")
        raise error(f"{path}: expected {names}, got {value!r}")
    if origin is Literal:
        if value not in args:
            raise error(f"{path}: expected {_type_name(tp)}, got {value!r}")
        return value
    if origin in (list, tuple):
        if not isinstance(value, (list, tuple)):
            raise error(f"{path}: expected a list, got {type(value).__name__} {value!r}")
        if origin is tuple and args and args[-1] is not Ellipsis:
            if len(value) != len(args):
                raise error(f"{path}: expected {len(args)} items, got {len(value)}")
            return tuple(_convert(a, v, f"{path}[{i}]", error) for i, (a, v) in enumerate(zip(args, value)))
        item = args[0] if args else Any
        items = [_convert(item, v, f"{path}[{i}]", error) for i, v in enumerate(value)]
        return tuple(items) if origin is tuple else items
    if origin is dict:
        if not isinstance(value, dict):
            raise error(f"{path}: expected a mapping, got {type(value).__name__}")
        return {str(k): _convert(args[1], v, f"{path}.{k}", error) for k, v in value.items()}
    if isinstance(tp, type) and dataclasses.is_dataclass(tp):
        return from_dict(tp, value, path, error)
    if tp is Any:
        return value
    if tp is bool:
        if not isinstance(value, bool):
            raise error(f"{path}: expected true or false, got {value!r}")
        return value
    if tp is int:
        if isinstance(value, bool) or not isinstance(value, int):
            raise error(f"{path}: expected an integer, got {value!r}")
        return value
    if tp is float:
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise error(f"{path}: expected a number, got {value!r}")
        if not math.isfinite(value):
            raise error(f"{path}: expected a finite number, got {value!r}")
        return float(value)
    if tp is str:
        if not isinstance(value, str):
            raise error(f"{path}: expected a string, got {value!r}")
        return value
    raise TypeError(f"unsupported config field type {tp!r} at {path}")


def from_dict(cls: type[T], data: Any, path: str = "", error: type[Exception] = LaunchFileError) -> T:
    """Build dataclass `cls` from `data`, validating every field (see module docstring)."""
    where = path or cls.__name__
    if data is None:
        data = {}
    if not isinstance(data, dict):
        raise error(f"{where}: expected a mapping of {cls.__name__} fields, got {type(data).__name__} {data!r}")
    hints = typing.get_type_hints(cls)
    fields = {f.name: f for f in dataclasses.fields(cls) if f.init}
    unknown = sorted(set(data) - set(fields))
    if unknown:
        raise error(f"{where}: unknown key{'s' if len(unknown) > 1 else ''} {', '.join(map(repr, unknown))}; "
                    f"allowed: {', '.join(fields)}")
    kwargs = {}
    for name, f in fields.items():
        key_path = f"{path}.{name}" if path else name
        if name in data:
            kwargs[name] = _convert(hints[name], data[name], key_path, error)
        elif f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING:
            raise error(f"{key_path}: required field is missing")
    obj = cls(**kwargs)
    check = getattr(obj, "validate", None)
    if callable(check):
        check(where)
    return obj


def read_yaml(path, error: type[Exception] = LaunchFileError):
    """Parse the YAML file at `path`, refusing what yaml.safe_load lets through: a file that is not
    UTF-8 text, and a key given twice in one mapping (safe_load keeps the last one silently). Every
    refusal is one line naming the file (and the line)."""
    from pathlib import Path

    import yaml

    path = Path(path)
    try:
        text = path.read_bytes().decode("utf-8")
    except UnicodeDecodeError as exc:
        raise error(f"{path}: not a UTF-8 text file (byte {exc.start} is 0x{exc.object[exc.start]:02x}); "
                    "expected YAML") from None
    except OSError as exc:
        raise error(f"{path}: cannot be read: {exc.strerror}") from None
    if "\x00" in text:
        raise error(f"{path}: not a text file (it contains NUL bytes); expected YAML")
    try:
        return yaml.load(text, Loader=_StrictLoader)
    except _DuplicateKey as exc:
        raise error(f"{path}: {exc}") from None
    except yaml.YAMLError as exc:
        raise error(f"{path}: not valid YAML: {' '.join(str(exc).split())}") from None


class _DuplicateKey(Exception):
    pass


def _strict_loader():
    import yaml

    class StrictLoader(yaml.SafeLoader):
        def construct_mapping(self, node, deep=False):
            seen: dict = {}
            for key_node, _ in node.value:
                key = self.construct_object(key_node, deep=deep)
                try:
                    hash(key)
                except TypeError:
                    continue  # the base class reports unhashable keys
                if key in seen:
                    raise _DuplicateKey(f"duplicate key '{key}' at line {key_node.start_mark.line + 1} (first given "
                                        f"at line {seen[key] + 1}); YAML would silently keep the last one")
                seen[key] = key_node.start_mark.line
            return super().construct_mapping(node, deep=deep)

    return StrictLoader


_StrictLoader = _strict_loader()


def to_dict(obj) -> dict:
    return dataclasses.asdict(obj)


def apply_overrides(data: Any, overrides: typing.Iterable[str], error: type[Exception] = LaunchFileError) -> dict:
    """`data` (a YAML mapping) with dotted `KEY=VALUE` overrides applied, for `--set` on the command line.

    KEY is a dotted path (`tracker.policy`, `safety.max_tilt_rad`, `input.timeline[2].vx_mps`);
    missing mappings on the way are made, so any field of the schema can be set. VALUE is read as
    YAML (`0.5`, `true`, `[480, 360]`, `holosoma_loco_fastsac`). The result still goes through
    `from_dict`, so an unknown key or a wrong type fails there with the key named.
    """
    import copy
    import re

    import yaml

    data = copy.deepcopy(data) if data is not None else {}
    if not isinstance(data, dict):
        raise error(f"expected a mapping at the top, got {type(data).__name__}")
    for item in overrides:
        key, sep, raw = item.partition("=")
        key = key.strip()
        if not sep or not key:
            raise error(f"--set {item!r}: expected KEY=VALUE, e.g. tracker.policy=holosoma_loco_fastsac")
        try:
            value = yaml.safe_load(raw) if raw.strip() else ""
        except yaml.YAMLError as exc:
            raise error(f"--set {key}: value {raw!r} is not valid YAML ({exc})") from None
        steps: list[str | int] = []
        for part in key.split("."):
            m = re.fullmatch(r"([A-Za-z_][A-Za-z0-9_]*)((?:\[\d+\])*)", part)
            if not m:
                raise error(f"--set {key}: '{part}' is not a key name (letters, digits, _; [N] for a list item)")
            steps.append(m.group(1))
            steps.extend(int(i) for i in re.findall(r"\[(\d+)\]", m.group(2)))
        node: Any = data
        where = ""
        for step, nxt in itertools.pairwise(steps):
            where = f"{where}[{step}]" if isinstance(step, int) else (f"{where}.{step}" if where else step)
            node = _child(node, step, nxt, where, key, error)
        last = steps[-1]
        if isinstance(last, int):
            if not isinstance(node, list) or last >= len(node):
                raise error(f"--set {key}: no item [{last}] (the list has {len(node) if isinstance(node, list) else 0})")
            node[last] = value
        else:
            if not isinstance(node, dict):
                raise error(f"--set {key}: '{last}' is set on a {type(node).__name__}, not a mapping")
            node[last] = value
    return data


def _child(node: Any, step: str | int, nxt: str | int, where: str, key: str, error: type[Exception]) -> Any:
    if isinstance(step, int):
        if not isinstance(node, list) or step >= len(node):
            raise error(f"--set {key}: {where}: no such list item (the list has "
                        f"{len(node) if isinstance(node, list) else 0})")
        return node[step]
    if not isinstance(node, dict):
        raise error(f"--set {key}: {where} is inside a {type(node).__name__}, not a mapping")
    if node.get(step) is None:
        if isinstance(nxt, int):
            raise error(f"--set {key}: {where} has no list to index")
        node[step] = {}
    return node[step]
