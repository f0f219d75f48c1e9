"""g1-control: real-time generative whole-body control for the Unitree G1.

The public Python API lives in g1_control/api.py (docs/api.md) and is re-exported here lazily:
`import g1_control as g1c; g1c.load_launch("sim_walk")`. Importing a submodule (g1_control.errors,
g1_control.robot.g1, ...) does not load the API or its heavy dependencies.
"""

__version__ = "0.1.0"

_API = (
    "Backend", "Command", "CommandInput", "ControlLoop", "EstimatedState", "G1ControlError", "Generator",
    "HumanMotion", "IKConfig", "IKRetargeter", "InputDevice", "JointReference", "KinematicReference",
    "LaunchFile", "MotionClip", "MotorCommand", "Retargeter", "RobotState", "RunRecord", "RunResult", "Tracker",
    "build_loop", "g1", "launch_files", "load_clip", "load_launch", "read_run", "retarget", "run", "save_clip",
)
__all__ = [*_API, "__version__"]


def __getattr__(name: str):
    if name in _API:
        from g1_control import api

        return getattr(api, name)
    raise AttributeError(f"module 'g1_control' has no attribute {name!r}")


def __dir__():
    return sorted(set(globals()) | set(_API))
