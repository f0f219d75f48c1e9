"""Generator + retargeter pairs by name, for launch files and tools.

    velocity   the operator's velocity at the default pose; copy retargeter (no IK)
    backbone   the in-betweening generator with the trained backbone (ONNX), through the IK
    interpolation / motion_matching   the same runtime with a baseline in-betweener (for comparison)
"""

from __future__ import annotations

from pathlib import Path

from g1_control.errors import G1ControlError
from g1_control.types import CommandLimits

GENERATORS = ("velocity", "backbone", "interpolation", "motion_matching")


def make_generator(kind: str, *, model: str | Path | None = None, limits: CommandLimits | None = None):
    """The generator and its retargeter; `limits`: the operator command range (the loop builder's
    one source of velocity limits, g1_control/launch/builder.py)."""
    from g1_control.generator.velocity import CopyRetargeter, VelocityReferenceGenerator

    if kind == "velocity":
        return VelocityReferenceGenerator(limits), CopyRetargeter()
    if kind not in GENERATORS:
        raise G1ControlError(f"unknown generator '{kind}'; known: {', '.join(GENERATORS)}")
    from g1_control.generator.inbetween import Inbetweener
    from g1_control.generator.learned import SHIPPED_DIR, OnnxInbetweener
    from g1_control.generator.retarget import GeneratorRetargeter
    from g1_control.generator.runtime import InbetweeningGenerator, RuntimeConfig
    from g1_control.generator.style_stats import load_style_stats

    model_path = Path(model) if model else SHIPPED_DIR / "backbone.onnx"
    styles = load_style_stats(model_path.parent / "style_stats.json")
    inbetweener: Inbetweener
    if kind == "backbone":
        inbetweener = OnnxInbetweener(model_path)
    elif kind == "interpolation":
        from g1_control.generator.baselines import InterpolationInbetweener

        inbetweener = InterpolationInbetweener()
    else:
        from g1_control.generator.baselines import MotionMatchingInbetweener
        from g1_control.generator.features import load_split

        inbetweener = MotionMatchingInbetweener(load_split(None, "train")[0])
    config = RuntimeConfig()
    if limits is not None:
        config.spring.max_vx_mps = min(config.spring.max_vx_mps, max(-limits.vx_mps[0], limits.vx_mps[1]))
        config.spring.max_vy_mps = min(config.spring.max_vy_mps, max(-limits.vy_mps[0], limits.vy_mps[1]))
        config.spring.max_wz_radps = min(config.spring.max_wz_radps, max(-limits.wz_radps[0], limits.wz_radps[1]))
    return InbetweeningGenerator(inbetweener, styles, config), GeneratorRetargeter()
