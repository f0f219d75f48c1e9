"""Whole-body differential IK for the G1 on pinocchio: the retargeter stage of the loop and the
engine of offline mocap retargeting.

    configuration.py   the model + kinematic quantities at one q (one Jacobian pass shared by all)
    tasks/             costs: frame pose, relative frame pose, centre of mass, posture, damping,
                       temporal smoothness
    limits/            constraints: joint position, joint velocity, floating-base velocity, foot
                       contact held, ground non-penetration, self- and scene collision, step, swing foot
    kernels.py         the per-tick frame rows, compiled with numba
    solver.py          the dense QP per step (daqp, or proxsuite's proxqp)
    retargeter.py      IKRetargeter (interfaces.Retargeter) configured by IKConfig
    exceptions.py      the IK's named errors

Offline mocap retargeting (HumanMotion -> MotionClip, `g1 retarget`) is retarget/mocap.py;
`g1 bench ik` is tools/bench_ik.py.
"""
