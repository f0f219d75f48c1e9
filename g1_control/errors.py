"""Named errors. Each message says what was wrong and what was expected."""


class G1ControlError(Exception):
    """Base class of every error this project raises on purpose."""


class InvalidCommandError(G1ControlError, ValueError):
    """An operator command that must not reach the robot (NaN, unknown button, ...)."""


class InvalidStateError(G1ControlError, ValueError):
    """A robot state no controller may act on (wrong shape, NaN, broken quaternion)."""


class LaunchFileError(G1ControlError, ValueError):
    """A launch file that fails validation; raised before anything runs."""


class PolicyMismatchError(G1ControlError, ValueError):
    """A policy whose joint order, gains or observation size does not match the robot."""


class PolicyFetchError(G1ControlError, RuntimeError):
    """Policy files could not be obtained (registry unreachable, hash mismatch, ...)."""


class RobotDescriptionError(G1ControlError, RuntimeError):
    """The G1 description package is missing or does not look like the G1."""


class InputDeviceError(G1ControlError, RuntimeError):
    """An operator input device that cannot be opened or used (missing path, no permission, not a tty)."""


class RemoteDecodeError(G1ControlError, ValueError):
    """Wireless-remote bytes that do not have the layout the G1 reports (40 bytes, see docs/robot_facts.md)."""


class MalformedMessageError(G1ControlError, ValueError):
    """A robot message (DDS sample, CAN/serial frame) that is short, truncated or of another type."""


class CrcMismatchError(G1ControlError, ValueError):
    """A robot message whose CRC/checksum does not match its contents."""


class TransportError(G1ControlError, RuntimeError):
    """A robot transport that cannot be opened or used (missing DDS library, port busy, ...)."""


class NetworkInterfaceError(TransportError):
    """A network interface that does not exist or is down; the message lists the ones that exist."""


class RobotNotConnectedError(TransportError):
    """No valid state arrived from the robot (not powered, wrong interface/domain, not running)."""


class VariantMismatchError(G1ControlError, ValueError):
    """The robot reports a DoF variant (mode_machine) other than the one the setup expects."""


class MotionServiceError(TransportError):
    """The robot's built-in motion service could not be released before low-level control."""


class SafetyConfigError(G1ControlError, ValueError):
    """A safety configuration with a missing, negative or non-finite threshold."""


class RetargetError(G1ControlError, RuntimeError):
    """The retargeter (IK stage) found no joint reference for this tick, even with its constraints
    relaxed. The control loop holds the last good reference for safety.ik_hold_ticks tracker ticks,
    then damps (g1_control/loop/control_loop.py)."""


class WbcConfigError(G1ControlError, ValueError):
    """A whole-body controller configuration or input that cannot be used (bad gains, shapes, geometry)."""


class WbcSolveError(G1ControlError, RuntimeError):
    """The whole-body inverse-dynamics QP found no solution for this tick."""


class FanOutError(G1ControlError, RuntimeError):
    """Work that cannot be fanned out: a bad --jobs or --ray, Ray not installed, a cluster that
    cannot be reached or whose workers cannot import g1_control."""


class Interrupted(KeyboardInterrupt):
    """SIGINT or SIGTERM ended a run (after its run folder was closed); the exit status is 128 + signum."""

    def __init__(self, signum: int):
        import signal

        super().__init__(f"{signal.Signals(signum).name} received")
        self.signum = signum
