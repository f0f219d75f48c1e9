"""A behaviour program: an ordered list of steps, validated, (de)serialised, described."""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from g1_control.program.exceptions import ProgramError
from g1_control.program.steps import Repeat, Step, iter_named_places
from g1_control.program.world import World


@dataclass
class Program:
    steps: list[Step] = field(default_factory=list)
    source: str = ""
    """The instruction the program was parsed from ('' when written by hand)."""

    def validate(self, world: World | None = None) -> Program:
        """Raise ProgramError naming the step and field of the first bad value; with a world, also
        every place name must be in it. Returns self."""
        if not self.steps:
            raise ProgramError("program: has no steps")
        for i, step in enumerate(self.steps):
            where = f"step {i + 1} ({step.kind if isinstance(step, Step) else '?'})"
            if not isinstance(step, Step):
                raise ProgramError(f"{where}: not a step; got {type(step).__name__}")
            step.validate(where)
            if world is not None:
                for path, name in iter_named_places(step):
                    if name not in world:
                        raise ProgramError(f"{where}.{path}: '{name}' is not in the world; known: "
                                           f"{', '.join(world.names())}")
        return self

    def to_dict(self) -> dict[str, Any]:
        out: dict[str, Any] = {"steps": [s.to_dict() for s in self.steps]}
        if self.source:
            out["source"] = self.source
        return out

    @classmethod
    def from_dict(cls, data: Any) -> Program:
        """From {"steps": [...], "source": "..."} or a bare list of steps; validated."""
        if isinstance(data, list):
            data = {"steps": data}
        if not isinstance(data, dict) or not isinstance(data.get("steps"), list):
            raise ProgramError("program: must be a list of steps or a mapping with a 'steps' list")
        unknown = set(data) - {"steps", "source"}
        if unknown:
            raise ProgramError(f"program: unknown field(s) {sorted(unknown)}; known: steps, source")
        steps = [Step.from_dict(s, f"step {i + 1}") for i, s in enumerate(data["steps"])]
        return cls(steps, str(data.get("source", ""))).validate()

    def describe(self) -> str:
        """One line per step ("3. walk to table, while: wave"); a repeat's steps indented under it."""
        lines: list[str] = []

        def emit(steps: list[Step], prefix: str, indent: str) -> None:
            for i, s in enumerate(steps):
                label = f"{prefix}{i + 1}"
                if isinstance(s, Repeat):
                    lines.append(f"{indent}{label}. repeat {s.count} times:")
                    emit(s.steps, label + ".", indent + "   ")
                else:
                    lines.append(f"{indent}{label}. {s.describe()}")

        emit(self.steps, "", "")
        return "\n".join(lines)

    def count_primitives(self) -> int:
        """Primitive steps run in all (repeats expanded; a parallel counts once)."""
        def n(s: Step) -> int:
            return s.count * sum(n(c) for c in s.steps) if isinstance(s, Repeat) else 1
        return sum(n(s) for s in self.steps)


def load_program(path: str | Path) -> Program:
    """A program from a .json or .yaml/.yml file."""
    path = Path(path)
    if not path.is_file():
        raise ProgramError(f"{path}: no such program file")
    text = path.read_text()
    if path.suffix in (".yaml", ".yml"):
        import yaml

        data = yaml.safe_load(text)
    else:
        data = json.loads(text)
    try:
        return Program.from_dict(data)
    except ProgramError as exc:
        raise ProgramError(f"{path}: {exc}") from None


def save_program(program: Program, path: str | Path) -> None:
    path = Path(path)
    data = program.to_dict()
    if path.suffix in (".yaml", ".yml"):
        import yaml

        path.write_text(yaml.safe_dump(data, sort_keys=False))
    else:
        path.write_text(json.dumps(data, indent=2) + "\n")


__all__ = ["Program", "load_program", "save_program"]
