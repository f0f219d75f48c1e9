"""Whole-body differential IK for the G1 on pinocchio: the retargeter stage of the loop and the
engine of offline mocap retargeting.

    configuration.py   the model + kinematic quantities at one q (one Jacobian pass shared by all)
    tasks/             costs: frame pose, relative frame pose, centre of mass, posture, damping,
                       temporal smoothness
    limits/            constraints: joint position, joint velocity, floating-base velocity, foot
                       contact held, ground non-penetration, self-collision
    solver.py          the dense QP per step (daqp, or proxsuite's proxqp)
    retargeter.py      IKRetargeter (interfaces.Retargeter) configured by IKConfig
    mocap_retarget.py  HumanMotion -> MotionClip (offline; `g1 retarget`)
    bench.py           `g1 bench ik`
"""
