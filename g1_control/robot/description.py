"""The G1 description (URDF + meshes) from the `example-robot-data` registry package, and the
pinocchio and MuJoCo models built from it. Nothing is downloaded at run time.

MuJoCo gets the same URDF through MjSpec, then what a URDF cannot say: a free joint on the
pelvis, armature and motors from g1.py, an IMU site, a floor, and collisions restricted to
robot-vs-floor (the G1 URDF's feet are four small spheres each, as in Menagerie; the other
collision meshes only matter once the robot is down).
"""

from __future__ import annotations

import functools
import sysconfig
from pathlib import Path

import numpy as np

from g1_control.errors import RobotDescriptionError
from g1_control.robot import g1

URDF_RELATIVE = "robots/g1_description/urdf/g1_29dof_rev_1_0.urdf"
HAND_URDF_RELATIVE = "robots/g1_description/urdf/g1_29dof_with_hand_rev_1_0.urdf"
"""The G1 with Dex3-1 hands (backend.hands: dex3): the same 29 joints, a palm and 7 finger joints per
hand instead of the rubber hand."""

HANDS = ("none", "dex3")

FINGER_STIFFNESS_NM_PER_RAD = 2.0
FINGER_DAMPING_NMS_PER_RAD = 0.05
FINGER_ARMATURE_KGM2 = 1e-4
"""The simulated Dex3's finger joints: a motor each (actuator named as the joint without "_joint",
after the body's 29, force limited to the URDF's effort), under the hand's motor law
tau = kp (q* - q) + kd (dq* - dq) + tau_ff (HandCmd_'s fields; MujocoBackend.write_fingers). Until
a command arrives each motor holds the open pose (every finger at 0) with kp FINGER_STIFFNESS_NM_PER_RAD:
what the hand's own controller does with its last command. FINGER_DAMPING_NMS_PER_RAD is the joint's
own viscous friction, under any command."""

JOINT_STOP_TIMECONST_STEPS = 2
"""A joint's stop (its limit constraint) pulls a joint back from beyond its range with a time
constant of this many physics steps: the stiffest MuJoCo integrates stably (its default, 0.02 s,
is 4 steps of 5 ms and 10 of 2 ms)."""
JOINT_STOP_SOLIMP = (0.99, 0.999, 0.001, 0.5, 2.0)
"""The stop's impedance: it takes 99 % of the load at the range's edge (MuJoCo's default takes 90 %,
rising to 95 % 1 mrad in). The G1's stops are metal: with MuJoCo's default soft limits a limp G1
hanging in its gantry sagged 0.0075 rad past its waist pitch stop under the torso's weight, and a
joint arriving at 3-10 rad/s went 0.02-0.05 rad past its range, more than the deploy's preflight
allows (DeployConfig.joint_limit_tolerance_rad) and nothing the robot's encoders would read.
Only the emulated robot has them so far (mujoco_spec(hard_stops=True)): as the default of every
simulation they changed the WBC's push-recovery outcomes (tests/trackers/wbc/test_wbc_recovery.py's
push_front_3 fell, and push_front_4 no longer fell without the recovery swing weight), which are
to be judged again over seeded pushes before the default moves."""


@functools.cache
def description_dir() -> Path:
    """Folder holding robots/g1_description inside the installed example-robot-data package."""
    candidates = []
    for key in ("purelib", "platlib", "data"):
        root = Path(sysconfig.get_paths()[key])
        candidates += [root / "cmeel.prefix/share/example-robot-data", root / "share/example-robot-data"]
    for cand in candidates:
        if (cand / URDF_RELATIVE).is_file():
            return cand
    raise RobotDescriptionError(
        "The G1 URDF was not found. It ships in the 'example-robot-data' package: "
        "run `pip install example-robot-data` (looked in: " + ", ".join(map(str, candidates)) + ")"
    )


def urdf_path(hands: str = "none") -> Path:
    """The G1 URDF: with rubber hands (hands 'none'), or with Dex3-1 hands ('dex3')."""
    if hands not in HANDS:
        raise RobotDescriptionError(f"unknown hands '{hands}'; known: {', '.join(HANDS)}")
    return description_dir() / (HAND_URDF_RELATIVE if hands == "dex3" else URDF_RELATIVE)


@functools.cache
def finger_joint_names() -> tuple[str, ...]:
    """The Dex3 hands' finger joints as the hand URDF lists them (left hand, then right)."""
    import xml.etree.ElementTree as ET

    root = ET.parse(urdf_path("dex3")).getroot()
    return tuple(j.get("name", "") for j in root.iter("joint")
                 if j.get("type") == "revolute" and "_hand_" in j.get("name", ""))


def mesh_dir() -> Path:
    return description_dir() / "robots/g1_description/meshes"


@functools.cache
def urdf_joint_limits() -> dict[str, np.ndarray]:
    """The 29 joints' `<limit>` as the URDF states them, in g1.JOINT_NAMES order: 'lower', 'upper'
    (rad), 'velocity' (rad/s), 'effort' (N m). Read from the file, not from g1.py, so that checks
    of g1.py and of clips have an independent reference."""
    import xml.etree.ElementTree as ET

    root = ET.parse(urdf_path()).getroot()
    found = {j.get("name"): j.find("limit") for j in root.iter("joint")}
    missing = [n for n in g1.JOINT_NAMES if found.get(n) is None]
    if missing:
        raise RobotDescriptionError(f"the G1 URDF has no <limit> for {missing}")
    limits = {n: found[n] for n in g1.JOINT_NAMES}
    out = {key: np.array([float(lim.get(key, "nan")) if lim is not None else np.nan for lim in limits.values()])
           for key in ("lower", "upper", "velocity", "effort")}
    for key, arr in out.items():
        if not np.all(np.isfinite(arr)):
            bad = [n for n, v in zip(g1.JOINT_NAMES, arr) if not np.isfinite(v)]
            raise RobotDescriptionError(f"the G1 URDF's <limit> of {bad} has no number for '{key}'")
        arr.setflags(write=False)
    return out


@functools.cache
def pinocchio_model(hands: str = "none"):
    """pinocchio.Model of the G1 with a free-flyer root (nq 36, nv 35). hands 'dex3': the G1 with
    Dex3-1 hands, fingers locked in the open pose (every finger joint at 0), so the joints are the
    same 29 and the hands count with their own masses and frames."""
    import pinocchio as pin

    model = pin.buildModelFromUrdf(str(urdf_path(hands)), pin.JointModelFreeFlyer())
    if hands == "dex3":
        fingers = [model.getJointId(n) for n in finger_joint_names()]
        model = pin.buildReducedModel(model, fingers, pin.neutral(model))
    names = [model.names[i] for i in range(2, model.njoints)]
    if tuple(names) != g1.JOINT_NAMES:
        raise RobotDescriptionError(f"URDF joint order {names} differs from g1.JOINT_NAMES")
    return model


def pinocchio_q(base_pos_w: np.ndarray, base_quat_wxyz: np.ndarray, q_rad: np.ndarray) -> np.ndarray:
    """Pinocchio configuration (x y z, qx qy qz qw, joints) from our conventions."""
    w, x, y, z = base_quat_wxyz
    return np.concatenate([base_pos_w, [x, y, z, w], q_rad])


def mujoco_spec(floor: bool = True, timestep_s: float = 0.005, variant: g1.Variant = g1.G1_29DOF,
                hands: str = "none", hard_stops: bool = False):
    """MjSpec of the G1 scene built from the URDF (see module docstring), as `variant` is built:
    the joints the variant lacks (g1_23dof: waist roll/pitch, wrist pitch/yaw) are removed, so
    their links are welded to their parents at the joint's zero, as the locked waist and the
    wrist-less forearm of the real robot are. Its actuators are the variant's joints, in g1.JOINT_NAMES
    order (nu = variant.num_dof). hands 'dex3': the G1 with Dex3-1 hands, fingers held open
    (FINGER_STIFFNESS_NM_PER_RAD), a motor per finger joint after the body's; the 29-DoF G1 only. hard_stops: the joints'
    stops as JOINT_STOP_TIMECONST_STEPS and JOINT_STOP_SOLIMP say (the emulated robot, `g1 sim-robot`);
    else MuJoCo's default soft limits, which the lockstep simulation and its tuned figures still use."""
    import mujoco

    if hands == "dex3" and variant.num_dof != g1.NUM_JOINTS:
        raise RobotDescriptionError(f"Dex3 hands are modelled on the 29-DoF G1 only, not on {variant.name}")
    xml = urdf_path(hands).read_text()
    # MuJoCo's URDF importer resolves meshes by file name in meshdir.
    xml = xml.replace("package://example-robot-data/robots/g1_description/meshes/", "")
    mujoco_ext = (
        f'<mujoco><compiler meshdir="{mesh_dir()}" strippath="true" discardvisual="false" '
        'balanceinertia="true" fusestatic="false"/></mujoco>'
    )
    xml = xml.replace("<robot name=\"g1_29dof_rev_1_0\">", "<robot name=\"g1_29dof_rev_1_0\">" + mujoco_ext, 1)
    if mujoco_ext not in xml:
        head, rest = xml.split("<robot", 1)
        name_end = rest.index(">") + 1
        xml = head + "<robot" + rest[:name_end] + mujoco_ext + rest[name_end:]
    spec = mujoco.MjSpec.from_string(xml)
    spec.option.timestep = timestep_s
    spec.option.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    spec.compiler.degree = False

    pelvis = spec.body(g1.BASE_BODY)
    pelvis.add_freejoint(name="floating_base")
    pelvis.pos = [0.0, 0.0, g1.DEFAULT_PELVIS_HEIGHT_M]

    for i in sorted(set(range(g1.NUM_JOINTS)) - set(variant.active_joints)):
        spec.delete(spec.joint(g1.JOINT_NAMES[i]))
    for i in variant.active_joints:
        name = g1.JOINT_NAMES[i]
        joint = spec.joint(name)
        joint.armature = float(g1.ARMATURE_KGM2[i])
        joint.range = [float(g1.Q_MIN_RAD[i]), float(g1.Q_MAX_RAD[i])]
        joint.limited = mujoco.mjtLimited.mjLIMITED_TRUE
        if hard_stops:
            joint.solref_limit = [JOINT_STOP_TIMECONST_STEPS * timestep_s, 1.0]  # critically damped
            joint.solimp_limit = list(JOINT_STOP_SOLIMP)
        motor = spec.add_actuator(name=name.removesuffix("_joint"), target=name)
        motor.trntype = mujoco.mjtTrn.mjTRN_JOINT
        limit = float(g1.EFFORT_LIMIT_NM[i])
        motor.ctrlrange = [-limit, limit]
        motor.ctrllimited = mujoco.mjtLimited.mjLIMITED_TRUE
    if hands == "dex3":
        for name in finger_joint_names():
            finger = spec.joint(name)
            finger.armature = FINGER_ARMATURE_KGM2
            finger.damping = [FINGER_DAMPING_NMS_PER_RAD, 0.0, 0.0]
            finger.limited = mujoco.mjtLimited.mjLIMITED_TRUE
        for name in finger_joint_names():
            limit = float(spec.joint(name).actfrcrange[1])  # the URDF's effort, as MuJoCo's importer read it
            # the hand's motor law in the bias (ctrl unused), holding the open pose until commanded
            motor = spec.add_actuator(name=name.removesuffix("_joint"), target=name)
            motor.trntype = mujoco.mjtTrn.mjTRN_JOINT
            motor.gaintype = mujoco.mjtGain.mjGAIN_FIXED
            motor.gainprm[0] = 0.0
            motor.biastype = mujoco.mjtBias.mjBIAS_AFFINE
            motor.biasprm[:3] = [0.0, -FINGER_STIFFNESS_NM_PER_RAD, 0.0]
            motor.ctrllimited = mujoco.mjtLimited.mjLIMITED_FALSE
            motor.forcelimited = mujoco.mjtLimited.mjLIMITED_TRUE
            motor.forcerange = [-limit, limit]

    # Collisions: robot geoms touch the floor only (contype 0 / conaffinity 1 vs floor 1 / 0), so a
    # fallen robot lies on the floor instead of sinking through it. The URDF importer marks visual
    # geoms group 1 without contacts; collision geoms go to group 3 (hidden: they repeat the visuals).
    for geom in spec.geoms:
        if geom.contype == 0 and geom.conaffinity == 0:
            continue  # visual
        geom.contype, geom.conaffinity = 0, 1
        geom.condim = 3
        geom.friction = [1.0, 0.005, 0.0001]
        geom.group = 3

    pelvis.add_site(name="imu", pos=[0.0, 0.0, 0.0])
    spec.add_sensor(name="imu_gyro", type=mujoco.mjtSensor.mjSENS_GYRO,
                    objtype=mujoco.mjtObj.mjOBJ_SITE, objname="imu")
    spec.add_sensor(name="imu_acc", type=mujoco.mjtSensor.mjSENS_ACCELEROMETER,
                    objtype=mujoco.mjtObj.mjOBJ_SITE, objname="imu")
    spec.add_sensor(name="imu_quat", type=mujoco.mjtSensor.mjSENS_FRAMEQUAT,
                    objtype=mujoco.mjtObj.mjOBJ_SITE, objname="imu")

    if floor:
        world = spec.worldbody
        world.add_light(pos=[0, 0, 3], dir=[0, 0, -1], type=mujoco.mjtLightType.mjLIGHT_DIRECTIONAL)
        tex = spec.add_texture(name="grid", type=mujoco.mjtTexture.mjTEXTURE_2D,
                               builtin=mujoco.mjtBuiltin.mjBUILTIN_CHECKER,
                               rgb1=[0.25, 0.3, 0.35], rgb2=[0.35, 0.4, 0.45], width=300, height=300)
        mat = spec.add_material(name="grid", texrepeat=[5, 5], reflectance=0.1)
        mat.textures[mujoco.mjtTextureRole.mjTEXROLE_RGB] = tex.name
        world.add_geom(name="floor", type=mujoco.mjtGeom.mjGEOM_PLANE, size=[0, 0, 0.05],
                       material="grid", contype=1, conaffinity=0, condim=3, friction=[1.0, 0.005, 0.0001])
        spec.visual.global_.offwidth = 1280
        spec.visual.global_.offheight = 720
    return spec


@functools.cache
def mujoco_model(timestep_s: float = 0.005):
    """Compiled MjModel of the G1 scene (cached; treat as read-only)."""
    return mujoco_spec(timestep_s=timestep_s).compile()
