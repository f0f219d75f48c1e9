"""Generators by name, for launch files and tools. The IK stage is built apart from the generator
(g1_control/launch/builder.py:make_ik); a generator whose references are feasible by construction
says so on each reference (KinematicReference.feasible_plan), and the IK stage passes those on.

    velocity   the operator's velocity at the default pose; feasible by construction (no IK)
    backbone   the in-betweening generator with the trained backbone (ONNX), through the IK
    learned_motion_matching   the same runtime with learned motion matching (lmm.py)
    interpolation / motion_matching   the same runtime with a baseline in-betweener (for comparison)

The learned kinds serve one robot skeleton (skeleton.py: g1_29dof, g1_23dof, g1_29dof_with_hand),
picked from the launch file's robot (backend.expected_variant + backend.hands); a model trained
for other skeletons is refused with SkeletonError naming both.
"""

from __future__ import annotations

from pathlib import Path

from g1_control.errors import G1ControlError
from g1_control.interfaces import Generator
from g1_control.types import CommandLimits

GENERATORS = ("velocity", "backbone", "interpolation", "motion_matching", "learned_motion_matching")


def make_inbetweener(kind: str, *, model: str | Path | None = None, skeleton: str = "g1_29dof"):
    """The in-betweener of a learned or baseline kind (not 'velocity')."""
    from g1_control.generator.learned import SHIPPED_DIR, OnnxInbetweener

    if kind == "backbone":
        return OnnxInbetweener(Path(model) if model else SHIPPED_DIR / "backbone.onnx", skeleton=skeleton)
    if kind == "learned_motion_matching":
        from g1_control.generator.lmm import SHIPPED_LMM_DIR, LearnedMotionMatchingInbetweener

        folder = Path(model) if model else SHIPPED_LMM_DIR
        return LearnedMotionMatchingInbetweener(folder.parent if folder.suffix == ".onnx" else folder, skeleton=skeleton)
    if kind == "interpolation":
        from g1_control.generator.baselines import InterpolationInbetweener

        return InterpolationInbetweener()
    if kind == "motion_matching":
        from g1_control.generator.baselines import MotionMatchingInbetweener
        from g1_control.generator.data import load_split

        return MotionMatchingInbetweener(load_split(None, "train", skeleton)[0])
    raise G1ControlError(f"unknown generator '{kind}'; known: {', '.join(GENERATORS)}")


def make_generator(kind: str, *, model: str | Path | None = None, limits: CommandLimits | None = None,
                   skeleton: str = "g1_29dof", feedback: bool = True, foot_lock: bool = True) -> Generator:
    """The generator; `limits`: the operator command range (the loop builder's one source of
    velocity limits, g1_control/launch/builder.py); `skeleton`: the robot's (generator/skeleton.py);
    `feedback`: reference-guided feedback when the model ships mixtures; `foot_lock`: plans' stance
    feet held (foot_lock.py)."""
    from g1_control.generator.velocity import VelocityReferenceGenerator

    if kind == "velocity":
        return VelocityReferenceGenerator(limits)
    if kind not in GENERATORS:
        raise G1ControlError(f"unknown generator '{kind}'; known: {', '.join(GENERATORS)}")
    from g1_control.generator.feedback import ReferenceFeedback
    from g1_control.generator.learned import SHIPPED_DIR
    from g1_control.generator.runtime import InbetweeningGenerator, RuntimeConfig
    from g1_control.generator.style_stats import load_style_stats

    inbetweener = make_inbetweener(kind, model=model, skeleton=skeleton)
    model_dir = Path(model).parent if (kind == "backbone" and model) else SHIPPED_DIR
    styles = load_style_stats(model_dir / "style_stats.json")
    mixtures = model_dir / "feedback.npz"
    fb = ReferenceFeedback.load(mixtures, skeleton) if feedback and mixtures.is_file() else None
    config = RuntimeConfig(foot_lock=foot_lock)
    if limits is not None:
        config.spring.max_vx_mps = min(config.spring.max_vx_mps, max(-limits.vx_mps[0], limits.vx_mps[1]))
        config.spring.max_vy_mps = min(config.spring.max_vy_mps, max(-limits.vy_mps[0], limits.vy_mps[1]))
        config.spring.max_wz_radps = min(config.spring.max_wz_radps, max(-limits.wz_radps[0], limits.wz_radps[1]))
    return InbetweeningGenerator(inbetweener, styles, config, skeleton=skeleton, feedback=fb)
