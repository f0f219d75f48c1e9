"""Model-based whole-body control on pinocchio: an inverse-dynamics QP with contact wrenches,
capture-point balance and a Tracker that turns a JointReference into torque + PD targets.

Modules: model (dynamics and frames), contacts (foot wrench constraints), tasks (acceleration
tasks), qp (the inverse-dynamics QP), capture_point (LIPM balance feedback), gait (walking from a
velocity command: footsteps, step timing, DCM plan, swing feet), zmp_preview (CoM plans
for references), odometry (floating-base position from the stance feet), tracker (the Tracker),
references (scripted test references), evaluate and bench (figures).
"""
