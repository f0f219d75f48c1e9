"""Whole-body IK for the G1 on pinocchio: the IK stage of the loop, the engine of offline mocap
retargeting (g1_control/retarget/mocap.py) and the pose solver of planned whole-body references.
Every IK solver of the project lives here.

    configuration.py   the model + kinematic quantities at one q (one Jacobian pass shared by all)
    tasks/             costs: frame pose, relative frame pose, centre of mass, posture, damping,
                       temporal smoothness
    limits/            constraints: joint position, joint velocity, floating-base velocity, foot
                       contact held, ground non-penetration, self- and scene collision, step, swing foot
    kernels.py         the per-tick frame rows, compiled with numba
    solver.py          the dense QP per step (daqp, or proxsuite's proxqp)
    retargeter.py      IKRetargeter (interfaces.Retargeter) configured by IKConfig
    stage.py           IKStage: the loop's one IK stage (a reference's feasible plan passes through,
                       any other is solved by IKRetargeter; the launch file's `ik:` section)
    whole_body.py      WholeBodyIK: damped least squares to convergence, for planned whole-body poses
    exceptions.py      the IK's named errors

Offline mocap retargeting (HumanMotion -> MotionClip, `g1 retarget`) is retarget/mocap.py;
`g1 bench ik` is tools/bench_ik.py.
"""
