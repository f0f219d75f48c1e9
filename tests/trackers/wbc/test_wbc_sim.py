"""The WBC in MuJoCo (lockstep, the full control loop): standing, a push, crouching, stepping
and walking without a fall, with tracking figures held to bounds measured when this was written
(they are deterministic: lockstep physics, no wall-clock dependence)."""

import numpy as np

from g1_control.tools.wbc_evaluate import run_wbc
from g1_control.trackers.wbc.tracker import WholeBodyTracker


def test_stands_still_with_millimetre_drift():
    figures, _ = run_wbc("stand", {"duration_s": 4.0})
    assert not figures.fell and figures.qp_failures == 0 and figures.qp_unsolved == 0
    assert figures.joint_rms_rad < 0.01
    assert figures.pelvis_height_max_m < 0.01
    assert figures.base_drift_max_m < 0.01


def test_survives_a_50_n_push_on_the_pelvis_and_comes_back():
    figures, loop = run_wbc("stand", {"duration_s": 5.0}, push_n=50.0, push_at_s=1.0, push_s=0.2)
    assert not figures.fell
    assert figures.base_drift_max_m > 0.02  # the push really moved it
    # The push makes the feet slide ~2 cm on the floor, which no proprioceptive controller can
    # see; relative to its feet the pelvis returns to where it stood.
    model, data = loop.backend.model, loop.backend.data
    feet = np.array([data.xpos[model.body(b).id] for b in ("left_ankle_roll_link", "right_ankle_roll_link")])
    slide = feet.mean(axis=0)[:2] - np.array([-0.0014, 0.0])  # feet centre at reset
    assert np.linalg.norm(slide) < 0.03
    pelvis_from_feet = data.qpos[:2] - feet.mean(axis=0)[:2]
    assert np.linalg.norm(pelvis_from_feet - np.array([0.0014, 0.0])) < 0.01


def test_crouches_15_cm_and_back():
    figures, loop = run_wbc("crouch")
    log = loop.log.arrays()
    z = log["base_pos_m"][:, 2]
    assert not figures.fell
    assert z[0] - z.min() > 0.14
    assert figures.pelvis_height_max_m < 0.015


class RecordingTracker(WholeBodyTracker):
    def __init__(self):
        super().__init__()
        self.tau, self.contacts = [], []

    def act(self, reference, state):
        out = super().act(reference, state)
        self.tau.append(out.tau_nm.copy())
        self.contacts.append(reference.contacts.copy())
        return out


def test_steps_in_place_and_contact_switches_do_not_jump(monkeypatch):
    import g1_control.trackers.wbc.tracker as tracker_module

    created = []
    monkeypatch.setattr(tracker_module, "WholeBodyTracker",
                        lambda config=None, **_: created.append(RecordingTracker()) or created[-1])
    figures, _ = run_wbc("step_in_place")
    assert not figures.fell and figures.joint_rms_rad < 0.02 and figures.base_drift_max_m < 0.03
    rec = created[0]
    tau, contacts = np.array(rec.tau), np.array(rec.contacts)
    switches = np.flatnonzero(np.any(np.diff(contacts.astype(int), axis=0) != 0, axis=1))
    assert len(switches) == 16  # eight steps: a liftoff and a touchdown each
    jumps = np.abs(tau[switches + 1] - tau[switches]).max(axis=1)
    # Measured 0.7-9.2 N m; with contact_ramp_s = liftoff_unload_s = 0 liftoffs jump 14-23 N m.
    assert jumps.max() < 12.0


def test_walks_at_0_3_mps():
    figures, loop = run_wbc("walk", {"speed_mps": 0.3})
    log = loop.log.arrays()
    assert not figures.fell and figures.qp_unsolved == 0
    assert log["base_pos_m"][-1, 0] > 1.8  # covered the walk
    assert figures.base_drift_final_m < 0.05
    assert figures.joint_rms_rad < 0.04
