"""Motion generators: operator Command -> KinematicReference.

velocity.py      the trivial generator (velocity at the default pose), the loop's default
runtime.py       InbetweeningGenerator: smart primitives -> keyframe -> in-betweener, replanning
                 on command change / low buffer, cross-fade, plan stabilization
primitives.py    critically damped springs (root, heading), style poses, height, box, effectors
inbetween.py     the Inbetweener interface (canonical frames, partial keyframes)
baselines.py     interpolation and motion matching
learned.py       the trained backbone through ONNX Runtime (g1_control/policies/generator/backbone.onnx;
                 training/backbone.py is the torch model)
lmm.py           learned motion matching (decompressor, stepper, projector) through ONNX Runtime
feedback.py      reference-guided feedback toward per-style Gaussian mixtures of library poses
skeleton.py      the G1 variants (29-DoF, 23-DoF, with Dex3 hands) over one set of joint slots
data.py          a built library as generator features (any variant)
features.py, fk.py   the 67-D frame representation and batched forward kinematics
evaluation.py    Harvey et al. protocol (L2P, L2Q, NPSS); `g1 bench generator` is tools/bench_generator.py
factory.py       generators by name for launch files (the IK stage is built apart: g1_control/ik/stage.py)
scripted.py, whole_body.py   scripted whole-body references; WholeBodyTrajectory (feasible plans)
"""
