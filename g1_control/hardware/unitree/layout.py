"""Byte layout of fixed-size IDL structs under the two rules the G1 protocol uses.

The robot serialises each message twice over: on the DDS wire as XCDR1 (every primitive aligned
to its own size from the start of the payload, structs neither aligned nor padded), and in memory
as a C struct (every struct aligned to its widest member and padded to a multiple of it), which is
what the CRC covers. The same schema yields both layouts here, flattened to one byte-offset array
per leaf field, so packing a message is a handful of vectorised numpy assignments instead of a
Python loop over 35 motors.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np

Rule = Literal["c", "xcdr1"]


@dataclass(frozen=True)
class Primitive:
    name: str
    dtype: np.dtype

    @property
    def size(self) -> int:
        return self.dtype.itemsize


U8 = Primitive("uint8", np.dtype("<u1"))
I16 = Primitive("int16", np.dtype("<i2"))
U32 = Primitive("uint32", np.dtype("<u4"))
F32 = Primitive("float32", np.dtype("<f4"))


@dataclass(frozen=True)
class Struct:
    """A fixed-size IDL struct: (field name, element type, array length) in declaration order."""

    name: str
    fields: tuple[tuple[str, Primitive | Struct, int], ...]

    @property
    def alignment(self) -> int:
        return max(t.size if isinstance(t, Primitive) else t.alignment for _, t, _ in self.fields)


@dataclass(frozen=True)
class Leaf:
    """One primitive field of a flattened struct: every byte offset it occupies, shaped like the
    nesting (e.g. `motor_cmd.q` in LowCmd_ has shape (35,), `motor_state.temperature` (35, 2))."""

    path: str
    primitive: Primitive
    offsets: np.ndarray

    @property
    def index(self) -> np.ndarray:
        """Offsets in units of the element size (valid because every leaf is aligned to its size)."""
        return self.offsets // self.primitive.size


@dataclass(frozen=True)
class Layout:
    struct: Struct
    rule: Rule
    size: int
    leaves: dict[str, Leaf]


def _align(pos: int, alignment: int) -> int:
    return (pos + alignment - 1) // alignment * alignment


def flatten(struct: Struct, rule: Rule) -> Layout:
    """Offsets of every leaf of `struct` laid out under `rule` ("c" memory or "xcdr1" wire)."""
    offsets: dict[str, list[int]] = {}
    shapes: dict[str, tuple[int, ...]] = {}
    prims: dict[str, Primitive] = {}

    def walk(s: Struct, pos: int, prefix: str, outer: tuple[int, ...]) -> int:
        if rule == "c":
            pos = _align(pos, s.alignment)
        for name, typ, count in s.fields:
            path = prefix + name
            shape = outer + ((count,) if count > 1 else ())
            for _ in range(count):
                if isinstance(typ, Primitive):
                    pos = _align(pos, typ.size)
                    offsets.setdefault(path, []).append(pos)
                    shapes[path], prims[path] = shape, typ
                    pos += typ.size
                else:
                    pos = walk(typ, pos, path + ".", shape)
        if rule == "c":
            pos = _align(pos, s.alignment)
        return pos

    size = walk(struct, 0, "", ())
    leaves = {
        path: Leaf(path, prims[path], np.asarray(offs, dtype=np.intp).reshape(shapes[path]))
        for path, offs in offsets.items()
    }
    for leaf in leaves.values():
        if np.any(leaf.offsets % leaf.primitive.size):
            raise AssertionError(f"{struct.name}.{leaf.path} is not aligned to its size under {rule}")
    return Layout(struct, rule, size, leaves)


class FieldCodec:
    """Packs/unpacks named leaves of one layout into a bytes-like buffer starting at `base`.

    `base` must keep every leaf aligned to its size in the whole buffer (0 for C memory, 4 for a
    DDS sample, whose payload follows the 4-byte encapsulation header)."""

    def __init__(self, layout: Layout, base: int = 0):
        if base % 4:
            raise ValueError(f"base offset {base} must be a multiple of 4 to keep fields aligned")
        self.layout = layout
        self.base = base
        self.size = base + layout.size
        # Buffer length rounded up so that 4-byte views cover every field.
        self.buffer_size = _align(self.size, 4)
        self._index = {path: (leaf.primitive.dtype, (leaf.offsets + base) // leaf.primitive.size)
                       for path, leaf in layout.leaves.items()}

    def put(self, buf: np.ndarray, path: str, value) -> None:
        """Write `value` (cast to the field's type) into the uint8 array `buf`."""
        dtype, index = self._index[path]
        buf.view(dtype)[index] = value

    def get(self, buf: np.ndarray, path: str) -> np.ndarray:
        dtype, index = self._index[path]
        return buf.view(dtype)[index]
