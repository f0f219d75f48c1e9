"""Domain randomisation of the simulated G1 (g1_control/sim/randomize.py applied by MujocoBackend):
the compiled model differs from the nominal one as drawn, the same seed gives the same robot, and
the drivers' latency and strength act in physics."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from g1_control.errors import LaunchFileError
from g1_control.robot import g1
from g1_control.sim.mujoco_backend import MujocoBackend, MujocoConfig
from g1_control.sim.randomize import RandomizeConfig, draw
from g1_control.types import MotorCommand


def _sim(seed: int | None, **ranges) -> MujocoBackend:
    config = None if seed is None else RandomizeConfig(seed=seed, **ranges)
    return MujocoBackend(MujocoConfig(randomize=config))


def _robot_bodies(m) -> list[int]:
    robot = m.body(g1.BASE_BODY).id
    return [b for b in range(1, m.nbody) if m.body_rootid[b] == robot]


def _foot_geoms(m) -> list[int]:
    feet = {m.body(n).id for n in g1.FOOT_BODIES}
    return [i for i in range(m.ngeom) if m.geom_bodyid[i] in feet and m.geom_conaffinity[i]]


@pytest.fixture(scope="module")
def nominal() -> MujocoBackend:
    return _sim(None)


def test_the_model_differs_from_the_nominal_one_as_drawn(nominal):
    sim = _sim(3)
    m, m0, d = sim.model, nominal.model, sim.draw
    assert d is not None and d.seed == 3
    bodies = _robot_bodies(m)
    assert d.bodies == tuple(m.body(b).name for b in bodies) and len(bodies) > 20
    np.testing.assert_allclose(m.body_mass[bodies], m0.body_mass[bodies] * d.mass_scale)
    heavy = m0.body_mass[bodies] > 0  # a few bodies (the IMU's, the wrist's) carry no mass
    scale = m.body_mass[bodies][heavy] / m0.body_mass[bodies][heavy]
    assert 0.9 <= scale.min() < 0.97 and 1.03 < scale.max() <= 1.1, "+-10 %, spread over the range"
    np.testing.assert_allclose(m.body_inertia[bodies], m0.body_inertia[bodies] * d.mass_scale[:, None])
    offset = m.body_ipos[bodies] - m0.body_ipos[bodies]
    np.testing.assert_allclose(offset, d.com_offset_m, atol=1e-12)
    assert 0.01 < np.linalg.norm(offset, axis=1).max() <= 0.02
    feet = _foot_geoms(m)
    assert len(feet) == 8  # four spheres per foot
    assert np.all(m.geom_friction[feet, 0] == d.foot_friction) and 0.5 <= d.foot_friction <= 1.2
    assert np.all(m.geom_priority[feet] == 1), "the feet's friction is used, not the floor's"
    strength = m.actuator_forcerange[:, 1] / m0.actuator_forcerange[:, 1]
    np.testing.assert_allclose(strength, d.motor_strength)
    assert 0.85 <= strength.min() and strength.max() <= 1.0 and strength.std() > 0.01
    assert sim.latency_s == pytest.approx(round(d.latency_s / 0.002) * 0.002) and 0.004 <= sim.latency_s <= 0.016
    assert sim.describe().startswith("MujocoBackend randomised (seed 3: ")
    # the nominal robot is untouched by another backend's draw (models are compiled per backend)
    assert nominal.draw is None and nominal.latency_s == 0.0
    np.testing.assert_array_equal(nominal.model.body_mass, _sim(None).model.body_mass)


def test_the_same_seed_gives_the_same_robot_and_another_seed_another():
    a, b, c = _sim(7), _sim(7), _sim(8)
    for field in ("body_mass", "body_ipos", "body_inertia", "geom_friction", "actuator_forcerange"):
        np.testing.assert_array_equal(getattr(a.model, field), getattr(b.model, field), err_msg=field)
        assert not np.array_equal(getattr(a.model, field), getattr(c.model, field)), field
    assert a.latency_s == b.latency_s and a.describe() == b.describe() != c.describe()
    assert a.draw is not None and a.draw.as_dict() == b.draw.as_dict()  # type: ignore[union-attr]


def test_the_draw_is_a_function_of_the_seed_and_the_ranges():
    bodies = ("pelvis", "left_hip_pitch_link")
    narrow = RandomizeConfig(seed=1, mass_scale=(1.05, 1.05), com_offset_m=0.0, motor_strength=(0.5, 0.5),
                             latency_s=(0.01, 0.01), foot_friction=(0.3, 0.3))
    d = draw(narrow, bodies, g1.NUM_JOINTS)
    np.testing.assert_array_equal(d.mass_scale, [1.05, 1.05])
    np.testing.assert_array_equal(d.com_offset_m, np.zeros((2, 3)))
    assert d.motor_strength.shape == (g1.NUM_JOINTS,) and np.all(d.motor_strength == 0.5)
    assert (d.latency_s, d.foot_friction) == (0.01, 0.3)
    # latency and friction do not depend on how many bodies the variant has
    wide = RandomizeConfig(seed=1)
    assert draw(wide, bodies, 29).latency_s == draw(wide, bodies * 3, 29).latency_s


def _step_torques(sim: MujocoBackend, tau_nm: float, steps: int) -> list[np.ndarray]:
    """Write a feed-forward torque (no gains) and record the motors' force on each physics step."""
    sim.write_command(MotorCommand(tau_nm=np.full(g1.NUM_JOINTS, tau_nm)))
    out = []
    for _ in range(steps):
        sim.step(0.002)
        out.append(sim.data.actuator_force.copy())
    return out


def test_commands_reach_the_drivers_after_the_drawn_latency(nominal):
    sim = _sim(2, latency_s=(0.0099, 0.0101))  # 10 ms = 5 physics steps
    assert sim.latency_s == pytest.approx(0.010)
    for s in (sim, nominal):
        s.reset()
        _step_torques(s, 0.0, 8)  # zero torque reached the drivers (after the latency)
    delayed = _step_torques(sim, 2.0, 8)
    direct = _step_torques(nominal, 2.0, 2)
    assert np.all(direct[0] == 2.0), "nominal: the next physics step already applies it"
    # the force a step reports is the law of that step: 5 steps still the old command, then the new one
    assert [bool(np.all(f == 0.0)) for f in delayed[:5]] == [True] * 5
    assert np.all(delayed[5] > 0.0)
    # lockstep batches (step_ticks) keep the delay too: the law switches inside the batch
    sim.reset()
    # steps 0-4 start < 10 ms after the write; step 5 starts 10 ms after it
    sim.step_ticks(MotorCommand(tau_nm=np.full(g1.NUM_JOINTS, 1.0)), 0.002, 5)
    assert np.abs(sim.data.actuator_force).max() < 1e-6, "still reset's hold of the standing pose, no error yet"
    sim.step(0.002)
    assert np.all(sim.data.actuator_force > 0.5)


def test_a_weaker_motor_gives_the_drawn_fraction_of_the_torque():
    sim = _sim(4, latency_s=(0.0, 0.0))
    sim.reset()
    forces = _step_torques(sim, 2.0, 1)[0]
    assert sim.draw is not None
    np.testing.assert_allclose(forces, 2.0 * sim.draw.motor_strength)  # 2 N m is inside every drawn limit


def test_reset_drops_commands_still_on_their_way():
    sim = _sim(5, latency_s=(0.014, 0.015))
    sim.reset()
    sim.write_command(MotorCommand(tau_nm=np.full(g1.NUM_JOINTS, 3.0)))
    sim.reset()
    for _ in range(10):
        sim.step(0.002)
    assert not np.any(sim.data.actuator_force == 3.0 * sim.draw.motor_strength), "no stale torque after reset"  # type: ignore[union-attr]


def test_the_feet_touch_the_floor_with_the_drawn_friction():
    sim = _sim(6)
    sim.reset()
    sim.step(0.2)
    feet = set(_foot_geoms(sim.model))
    d = sim.data
    contacts = [d.contact[i] for i in range(d.ncon) if {int(d.contact[i].geom[0]), int(d.contact[i].geom[1])} & feet]
    assert contacts, "standing: the feet touch the floor"
    assert sim.draw is not None
    assert all(c.friction[0] == pytest.approx(sim.draw.foot_friction) for c in contacts)
    assert mujoco.mj_name2id(sim.model, mujoco.mjtObj.mjOBJ_GEOM, "floor") >= 0


@pytest.mark.parametrize(("ranges", "message"), [
    ({"mass_scale": (1.2, 0.9)}, "r.mass_scale: [1.2, 0.9] must be [low, high] with 0.5 <= low <= high <= 2 "
                                 "(a factor on each link's mass)"),
    ({"motor_strength": (0.2, 1.0)}, "r.motor_strength: [0.2, 1] must be [low, high] with 0.3 <= low <= high <= 1.2 "
                                     "(a factor on each motor's torque)"),
    ({"latency_s": (-0.001, 0.01)}, "r.latency_s: [-0.001, 0.01] must be [low, high] with 0 <= low <= high <= 0.1 "
                                    "(seconds of command latency)"),
    ({"foot_friction": (0.5, 4.0)}, "r.foot_friction: [0.5, 4] must be [low, high] with 0.05 <= low <= high <= 3 "
                                    "(a sliding friction coefficient)"),
    ({"com_offset_m": 0.2}, "r.com_offset_m: 0.2 is outside [0, 0.1] m"),
    ({"seed": -1}, "r.seed: -1 must be >= 0"),
])
def test_bad_ranges_are_refused_with_the_key_named(ranges, message):
    with pytest.raises(LaunchFileError) as info:
        RandomizeConfig(**ranges).validate("r")
    assert str(info.value) == message
