"""The in-betweening backbone (torch): a root module, then a pose module, both transformers over
the same token sequence [context frames | gap frames | target keyframe].

Root module: from the context and the target, the pelvis trajectory across the gap (a residual
over interpolation) and the transition's duration in frames, so a caller that gives a keyframe
without a time can ask how long the motion should take (MotionBricks plans root, then pose).
Pose module: joints and effector positions for every gap frame given the root trajectory.

Conditioning (COMET-style partial keyframes): every token carries its feature values and a
per-feature "given" mask, so a target may be a full pose, the root only, or chosen joints /
effector positions; a style embedding (one per styles.STYLES entry, plus "unknown") is added to
every token. Poses are continuous (not tokenised): the benchmark prints the error floor a
512-code pose codebook would impose, which is above the continuous model's error.

Everything is in normalized canonical features (features.py); `base` is the interpolation
baseline the outputs are residuals of, computed outside so the gap length is a dynamic axis of
the exported ONNX graph.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import torch
from torch import nn

from g1_control.generator import features as F
from g1_control.generator.inbetween import CONTEXT_FRAMES, MAX_GAP


@dataclass
class BackboneConfig:
    num_styles: int
    d_model: int = 64
    layers: int = 3
    heads: int = 4
    ff: int = 192
    root_d_model: int = 48
    root_layers: int = 2
    dropout: float = 0.0
    pose_refines_root: bool = True
    """The pose module also adds a correction to the root module's pelvis path. Measured with the
    first shipped model (False): the small root module left the lateral pelvis sway of walking at
    interpolation's error (2.0 vs 2.3 cm; motion matching 0.9 cm), which dominated L2P."""

    def to_dict(self) -> dict:
        return asdict(self)


class _Block(nn.Module):
    """Pre-norm transformer block. Written out (not nn.TransformerEncoderLayer) because the
    TorchScript ONNX exporter bakes that layer's sequence length into its reshapes, and the
    gap length must stay a dynamic axis of the exported graph."""

    def __init__(self, d: int, heads: int, ff: int, dropout: float):
        super().__init__()
        self.heads = heads
        self.norm1 = nn.LayerNorm(d)
        self.qkv = nn.Linear(d, 3 * d)
        self.proj = nn.Linear(d, d)
        self.norm2 = nn.LayerNorm(d)
        self.mlp = nn.Sequential(nn.Linear(d, ff), nn.GELU(), nn.Linear(ff, d))
        self.drop = nn.Dropout(dropout)

    def forward(self, x):
        b, n, d = x.shape
        h = self.heads
        q, k, v = self.qkv(self.norm1(x)).reshape(b, n, 3, h, d // h).permute(2, 0, 3, 1, 4)
        att = torch.softmax(q @ k.transpose(-1, -2) * (d // h) ** -0.5, dim=-1)
        y = (att @ v).transpose(1, 2).reshape(b, n, d)
        x = x + self.drop(self.proj(y))
        return x + self.drop(self.mlp(self.norm2(x)))


class _TokenModule(nn.Module):
    """Tokens (values ++ given-mask) + position + role + style -> transformer -> per-token vectors."""

    def __init__(self, in_dim: int, d: int, heads: int, ff: int, layers: int, num_styles: int, dropout: float):
        super().__init__()
        self.inp = nn.Linear(2 * in_dim, d)
        self.pos = nn.Parameter(torch.zeros(CONTEXT_FRAMES + MAX_GAP + 1, d))
        self.role = nn.Parameter(torch.zeros(3, d))
        self.style = nn.Embedding(num_styles + 1, d)
        self.blocks = nn.ModuleList(_Block(d, heads, ff, dropout) for _ in range(layers))
        self.norm = nn.LayerNorm(d)
        nn.init.normal_(self.pos, std=0.02)
        nn.init.normal_(self.role, std=0.02)

    def forward(self, values, given, style, gap: int):
        _b, length, _ = values.shape
        x = self.inp(torch.cat([values, given], dim=-1))
        # positions: context 0..C-1, gap C..C+G-1, target at C+G (its true distance in frames)
        x = x + self.pos[:length]
        roles = torch.cat([self.role[0:1].expand(CONTEXT_FRAMES, -1), self.role[1:2].expand(gap, -1),
                           self.role[2:3]], dim=0)
        x = x + roles + self.style(style)[:, None, :]
        for block in self.blocks:
            x = block(x)
        return self.norm(x)


class Backbone(nn.Module):
    feat_mean: torch.Tensor  # buffers (register_buffer below): feature normalisation
    feat_std: torch.Tensor

    def __init__(self, config: BackboneConfig):
        super().__init__()
        self.config = config
        c = config
        self.root = _TokenModule(9, c.root_d_model, max(1, c.heads // 2), 2 * c.root_d_model, c.root_layers,
                                 c.num_styles, c.dropout)
        self.root_out = nn.Linear(c.root_d_model, 9)
        self.duration_out = nn.Linear(c.root_d_model, 1)
        self.pose = _TokenModule(F.DIM, c.d_model, c.heads, c.ff, c.layers, c.num_styles, c.dropout)
        self.pose_out = nn.Linear(c.d_model, F.DIM if c.pose_refines_root else F.DIM - 9)
        for head in (self.root_out, self.pose_out):
            nn.init.zeros_(head.weight)
            nn.init.zeros_(head.bias)
        self.register_buffer("feat_mean", torch.zeros(F.DIM))
        self.register_buffer("feat_std", torch.ones(F.DIM))

    def forward(self, context, target, target_given, base, style):
        """All in raw canonical units: context (B, C, D), target (B, D), target_given (B, D) in {0, 1},
        base (B, G, D) interpolation baseline, style (B,) long. Returns (frames (B, G, D), duration (B,))."""
        gap = base.shape[1]
        mean, std = self.feat_mean, self.feat_std
        ctx = (context - mean) / std
        tgt = (target - mean) / std * target_given
        bas = (base - mean) / std
        ones_c = torch.ones_like(ctx)
        zeros_g = torch.zeros_like(bas)
        # root module
        rv = torch.cat([ctx[..., :9], bas[..., :9], tgt[:, None, :9]], dim=1)
        rg = torch.cat([ones_c[..., :9], zeros_g[..., :9], target_given[:, None, :9]], dim=1)
        rh = self.root(rv, rg, style, gap)
        root = bas[..., :9] + self.root_out(rh[:, CONTEXT_FRAMES:CONTEXT_FRAMES + gap])
        # Duration from context + target alone: in the pass above the target token's position
        # is the gap itself (measured: the head then just read it back, 0.02 frames "error").
        # Here the target sits right after the context, so the time must come from the motion.
        dv = torch.cat([ctx[..., :9], tgt[:, None, :9]], dim=1)
        dg = torch.cat([ones_c[..., :9], target_given[:, None, :9]], dim=1)
        dh = self.root(dv, dg, style, 0)
        duration = nn.functional.softplus(self.duration_out(dh[:, -1]))[:, 0] * 10.0
        # pose module: the planned root counts as given on the gap tokens
        gap_vals = torch.cat([root, bas[..., 9:]], dim=-1)
        gap_given = torch.cat([torch.ones_like(root), zeros_g[..., 9:]], dim=-1)
        pv = torch.cat([ctx, gap_vals, tgt[:, None]], dim=1)
        pg = torch.cat([ones_c, gap_given, target_given[:, None]], dim=1)
        ph = self.pose(pv, pg, style, gap)
        delta = self.pose_out(ph[:, CONTEXT_FRAMES:CONTEXT_FRAMES + gap])
        if self.config.pose_refines_root:
            root = root + delta[..., :9]
            delta = delta[..., 9:]
        out = torch.cat([root, bas[..., 9:] + delta], dim=-1) * std + mean
        return out, duration
