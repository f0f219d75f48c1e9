"""The in-betweening backbone (torch): one transformer over [context | gap | target] tokens, for
every G1 skeleton.

Tokens: two consecutive frames per token (10 context frames -> 5 tokens, a gap of G frames -> G/2
tokens, the target keyframe -> 1 token): motion at 30 fps is smooth over 2 frames, and halving the
tokens is what brings a replan under a millisecond on one core (attention and MLP cost scale with
the token count). Each token carries its frames' values and per-feature "given" masks:
- context frames: everything the skeleton has is given;
- gap frames: the interpolation baseline, plus joint-level goals - any subset of joints or
  effector positions (hands, feet, head) or the pelvis, at any gap frame, given with its mask
  (COMET-style partial keyframes, generalised from the target to every future frame);
- the target keyframe: a full pose, the root only, root + upper body, or any subset.
Added to every token: a position (token index), a role (context/gap/target), a style embedding
(one per styles.STYLES entry plus "unknown"), and the skeleton embedding - a linear map of the
skeleton descriptor (skeleton.py: per joint slot present / placement / axis), so one network
serves the 29-DoF G1, the 23-DoF G1 and the G1 with hands, and a slot a skeleton lacks is never
given and is zeroed in the output.

Outputs are residuals over interpolation (zero-initialised head: the untrained model is exactly
interpolation), plus the transition's duration in frames from the context and the target's root
alone (a small MLP, no positions: MotionBricks' root planner answers how long a motion takes).

Everything is in normalized canonical features (features.py); `base` (interpolation), the gap's
goals and masks come padded to an even length from learned.py, so the gap stays a dynamic axis of
the exported ONNX graph.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import torch
from torch import nn

from g1_control.generator import features as F
from g1_control.generator import skeleton as S
from g1_control.generator.inbetween import CONTEXT_FRAMES
from g1_control.generator.learned import PADDED_GAP, PATCH

CONTEXT_TOKENS = CONTEXT_FRAMES // PATCH
GAP_TOKENS = PADDED_GAP // PATCH
MAX_TOKENS = CONTEXT_TOKENS + GAP_TOKENS + 1


@dataclass
class BackboneConfig:
    num_styles: int
    d_model: int = 96
    layers: int = 3
    heads: int = 4
    ff: int = 192
    dropout: float = 0.0
    duration_hidden: int = 64
    skeletons: tuple[str, ...] = ("g1_29dof",)
    """Skeletons the model was trained on (model.json; the runtime refuses others)."""

    def to_dict(self) -> dict:
        d = asdict(self)
        d["skeletons"] = list(self.skeletons)
        return d


class _Block(nn.Module):
    """Pre-norm transformer block, written out (not nn.TransformerEncoderLayer) so the exported
    graph keeps the token count dynamic."""

    def __init__(self, d: int, heads: int, ff: int, dropout: float):
        super().__init__()
        self.heads = heads
        self.norm1 = nn.LayerNorm(d)
        self.qkv = nn.Linear(d, 3 * d)
        self.proj = nn.Linear(d, d)
        self.norm2 = nn.LayerNorm(d)
        self.mlp = nn.Sequential(nn.Linear(d, ff), nn.GELU(), nn.Linear(ff, d))
        self.drop = nn.Dropout(dropout)

    def forward(self, x, n: int | None = None, bias=None):
        """x (B, n, d). n: the token count as a Python int (exported graphs: constant reshapes),
        bias: additive attention bias on the keys (B, 1, 1, n) or None."""
        d, h = self.proj.in_features, self.heads
        n = x.shape[1] if n is None else n
        q, k, v = self.qkv(self.norm1(x)).reshape(-1, n, 3, h, d // h).permute(2, 0, 3, 1, 4)
        logits = q @ k.transpose(-1, -2) * (d // h) ** -0.5
        att = torch.softmax(logits if bias is None else logits + bias, dim=-1)
        y = (att @ v).transpose(1, 2).reshape(-1, n, d)
        x = x + self.drop(self.proj(y))
        return x + self.drop(self.mlp(self.norm2(x)))


class Backbone(nn.Module):
    feat_mean: torch.Tensor  # buffers (register_buffer below): feature normalisation
    feat_std: torch.Tensor

    def __init__(self, config: BackboneConfig):
        super().__init__()
        self.config = config
        c = config
        d = c.d_model
        self.inp = nn.Linear(2 * PATCH * F.DIM, d)
        self.pos = nn.Parameter(torch.zeros(MAX_TOKENS, d))
        self.role = nn.Parameter(torch.zeros(3, d))
        self.style = nn.Embedding(c.num_styles + 1, d)
        self.skeleton = nn.Linear(S.NUM_SLOTS * S.DESCRIPTOR_WIDTH, d)
        self.blocks = nn.ModuleList(_Block(d, c.heads, c.ff, c.dropout) for _ in range(c.layers))
        self.norm = nn.LayerNorm(d)
        self.out = nn.Linear(d, PATCH * F.DIM)
        nn.init.zeros_(self.out.weight)
        nn.init.zeros_(self.out.bias)
        nn.init.normal_(self.pos, std=0.02)
        nn.init.normal_(self.role, std=0.02)
        root_in = (CONTEXT_FRAMES + 2) * 9
        self.duration = nn.Sequential(nn.Linear(root_in, c.duration_hidden), nn.GELU(),
                                      nn.Linear(c.duration_hidden, 1))
        self.register_buffer("feat_mean", torch.zeros(F.DIM))
        self.register_buffer("feat_std", torch.ones(F.DIM))

    def forward(self, context, target, target_given, base, gap_goal, gap_given, style, skeleton, present,
                gap_len=None):
        """Raw canonical units: context (B, C, D), target (B, D) (0 where not given), target_given (B, D),
        base (B, G, D) interpolation (G even), gap_goal / gap_given (B, G, D) goals on gap frames, style
        (B,) long, skeleton (B, NUM_SLOTS * DESCRIPTOR_WIDTH) descriptor, present (B, D) {0, 1} features
        the skeleton has. Returns (frames (B, G, D), duration (B,) frames).

        gap_len (B,) long, for the exported graph: the gap inputs are then padded to PADDED_GAP frames
        and the tokens past each window's gap are masked out of attention, so every shape in the
        graph is a constant (no shape arithmetic at run time); the result on the real gap frames is
        the same function as with a gap of exactly that length (training uses that form)."""
        static = gap_len is not None
        dim = F.DIM
        n_gap = GAP_TOKENS if static else base.shape[1] // PATCH
        n_tok = CONTEXT_TOKENS + n_gap + 1
        mean, std = self.feat_mean, self.feat_std
        pres = present.unsqueeze(1)
        ctx = (context - mean) / std * pres
        tgt_given = target_given * present
        tgt = (target - mean) / std * tgt_given
        bas = (base - mean) / std * pres
        g_given = gap_given * pres
        goal = (gap_goal - mean) / std * g_given
        gap_vals = bas * (1.0 - g_given) + goal
        pair = PATCH * dim
        ctx_tok = torch.cat([ctx.reshape(-1, CONTEXT_TOKENS, pair),
                             (pres * torch.ones_like(ctx)).reshape(-1, CONTEXT_TOKENS, pair)], dim=-1)
        gap_tok = torch.cat([gap_vals.reshape(-1, n_gap, pair), g_given.reshape(-1, n_gap, pair)], dim=-1)
        zero = torch.zeros_like(tgt)
        tgt_tok = torch.cat([tgt, zero, tgt_given, zero], dim=-1).unsqueeze(1)
        x = self.inp(torch.cat([ctx_tok, gap_tok, tgt_tok], dim=1))
        # positions: context and gap tokens by index, the target at its true distance
        if static:
            used = torch.div(gap_len + (PATCH - 1), PATCH, rounding_mode="floor")
            tgt_pos = self.pos[CONTEXT_TOKENS + used]
            keys = torch.arange(GAP_TOKENS, device=x.device).unsqueeze(0) < used.unsqueeze(1)
            ones = torch.ones_like(keys[:, :1])
            keep = torch.cat([ones.expand(-1, CONTEXT_TOKENS), keys, ones], dim=1)
            bias = ((~keep).to(x.dtype) * -1e9).reshape(-1, 1, 1, n_tok)
        else:
            tgt_pos = self.pos[CONTEXT_TOKENS + n_gap].unsqueeze(0).expand(x.shape[0], -1)
            bias = None
        pos = torch.cat([self.pos[:CONTEXT_TOKENS + n_gap].unsqueeze(0).expand(x.shape[0], -1, -1),
                         tgt_pos.unsqueeze(1)], dim=1)
        roles = torch.cat([self.role[0:1].expand(CONTEXT_TOKENS, -1), self.role[1:2].expand(n_gap, -1),
                           self.role[2:3]], dim=0)
        x = x + pos + roles + (self.style(style) + self.skeleton(skeleton)).unsqueeze(1)
        for block in self.blocks:
            x = block(x, n_tok, bias)
        delta = self.out(self.norm(x[:, CONTEXT_TOKENS:CONTEXT_TOKENS + n_gap]))
        out = (bas + delta.reshape(-1, n_gap * PATCH, dim)) * std + mean
        out = out * pres
        root_in = torch.cat([ctx[..., :9].reshape(-1, CONTEXT_FRAMES * 9), tgt[:, :9], tgt_given[:, :9]], dim=-1)
        duration = nn.functional.softplus(self.duration(root_in))[:, 0] * 10.0
        return out, duration
