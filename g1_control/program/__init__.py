"""Behaviour programs: typed steps, a runner that executes them tick by tick, and English -> program.

    from g1_control.program import parse_instruction, ProgramRunner, ProgramProgress, World, Landmark
    program = parse_instruction("walk forward two meters, then turn left and wave")
    runner = ProgramRunner(program, world)
    command = runner.update(now_s, ProgramProgress(x_m, y_m, yaw_rad, goal_status))

See README.md in this folder for the format, the grammar and the corpus figures.
"""

from g1_control.program.exceptions import InstructionError, ProgramError, UnknownWordError
from g1_control.program.language.parser import InstructionParser, parse_instruction
from g1_control.program.program import Program, load_program, save_program
from g1_control.program.runner import (
    COMPLETED,
    FAILED,
    TIMED_OUT,
    GoalRequest,
    ProgramProgress,
    ProgramRunner,
    RunnerConfig,
    StepOutcome,
)
from g1_control.program.steps import (
    STEP_TYPES,
    Height,
    Parallel,
    Pick,
    Place,
    Reach,
    Repeat,
    Stand,
    Step,
    StepDown,
    StepUp,
    Style,
    Turn,
    Walk,
)
from g1_control.program.world import Landmark, World

__all__ = [
    "COMPLETED",
    "FAILED",
    "STEP_TYPES",
    "TIMED_OUT",
    "GoalRequest",
    "Height",
    "InstructionError",
    "InstructionParser",
    "Landmark",
    "Parallel",
    "Pick",
    "Place",
    "Program",
    "ProgramError",
    "ProgramProgress",
    "ProgramRunner",
    "Reach",
    "Repeat",
    "RunnerConfig",
    "Stand",
    "Step",
    "StepDown",
    "StepOutcome",
    "StepUp",
    "Style",
    "Turn",
    "UnknownWordError",
    "Walk",
    "World",
    "load_program",
    "parse_instruction",
    "save_program",
]
