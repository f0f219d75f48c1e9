"""Swap the tracker: another policy by configuration, or your own Tracker around the built one.

    python examples/swap_tracker.py

`wrap_tracker(tracker, safety)` is how `g1 deploy` puts its state machine around whatever tracker
the launch file names; the same hook takes your own class. Any object implementing
g1c.Tracker (act, reset, observe) fits.
"""

import numpy as np

import g1_control as g1c


class ArmsAtDefault(g1c.Tracker):
    """The walking policy, with the arms held at the default pose instead of swinging."""

    def __init__(self, inner: g1c.Tracker):
        self.inner = inner
        self.arms = np.asarray(g1c.g1.ARM_JOINTS)
        self.ticks = 0

    def act(self, reference, state):
        command = self.inner.act(reference, state)
        command.q_rad[self.arms] = np.asarray(g1c.g1.DEFAULT_Q_RAD)[self.arms]
        self.ticks += 1
        return command

    def reset(self, state):
        self.inner.reset(state)

    def observe(self, estimate):
        self.inner.observe(estimate)

    @property
    def policy_command(self):
        return self.inner.policy_command


# 1. By configuration: the same launch file with the other shipped walking policy.
launch = g1c.load_launch("sim_walk", overrides=["duration_s=6", "tracker.policy=holosoma_loco_fastsac"])
loop = g1c.build_loop(launch)
print("tracker:", loop.chain["tracker"])
loop.reset()
loop.run(6.0)
print(f"  fell: {loop.fell}")
loop.backend.close()

# 2. In code: your own Tracker around the one the launch file builds.
launch = g1c.load_launch("sim_walk", overrides=["duration_s=6"])
wrapped = []
loop = g1c.build_loop(launch, wrap_tracker=lambda tracker, safety: wrapped.append(ArmsAtDefault(tracker)) or wrapped[0])
print("tracker:", loop.chain["tracker"], "wrapped in", loop.chain["wrapper"])
loop.reset()
loop.run(6.0)
arms = wrapped[0].arms
spread = float(np.abs(loop.log.arrays()["q_target_rad"][:, arms] - np.asarray(g1c.g1.DEFAULT_Q_RAD)[arms]).max())
print(f"  {wrapped[0].ticks} ticks through ArmsAtDefault; arm targets off the default pose by at most {spread:.3f} rad; "
      f"fell: {loop.fell}")
loop.backend.close()
assert spread < 1e-9 and not loop.fell
