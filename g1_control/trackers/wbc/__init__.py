"""Model-based whole-body control on pinocchio: an inverse-dynamics QP with contact wrenches,
capture-point balance and a Tracker that turns a JointReference into torque + PD targets.

    contacts.py        foot wrench constraints
    tasks.py           acceleration tasks
    qp.py              the inverse-dynamics QP
    capture_point.py   LIPM balance feedback
    gait.py            walking from a velocity command: footsteps, step timing, DCM plan, swing feet
    odometry.py        floating-base position from the stance feet
    tracker.py         the Tracker

Elsewhere: the model (dynamics and frames) is robot/dynamics.py; CoM plans for references
generator/zmp_preview.py; the scripted test references generator/scripted.py; the figures
tools/wbc_evaluate.py, tools/bench_wbc.py and tools/bench_locomotion.py.
"""
