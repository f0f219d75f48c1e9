"""Generator + retargeter pairs by name, for launch files and tools.

    velocity   the operator's velocity at the default pose; copy retargeter (no IK)
    backbone   the in-betweening generator with the trained backbone (ONNX), through the IK
    interpolation / motion_matching   the same runtime with a baseline in-betweener (for comparison)
"""

from __future__ import annotations

from pathlib import Path

from g1_control.errors import G1ControlError

GENERATORS = ("velocity", "backbone", "interpolation", "motion_matching")


def make_generator(kind: str, *, model: str | Path | None = None, limits=None):
    from g1_control.generator.velocity import CopyRetargeter, VelocityReferenceGenerator

    if kind == "velocity":
        args = (limits.max_vx_mps, limits.max_vy_mps, limits.max_wz_radps) if limits is not None else ()
        return VelocityReferenceGenerator(*args), CopyRetargeter()
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
        config.spring.max_vx_mps = min(config.spring.max_vx_mps, limits.max_vx_mps)
        config.spring.max_vy_mps = min(config.spring.max_vy_mps, limits.max_vy_mps)
        config.spring.max_wz_radps = min(config.spring.max_wz_radps, limits.max_wz_radps)
    return InbetweeningGenerator(inbetweener, styles, config), GeneratorRetargeter()
