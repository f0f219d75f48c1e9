"""Quality report for any G1 clip, measured as an independent checker would: from each frame's root
pose and joint angles only (never the clip's contact labels or the retargeter's own bookkeeping),
against the robot's description (URDF limits, collision geometry); a table for a batch, a PNG per
clip. Per-frame geometry: retarget/clip_geometry.py.

Definitions (thresholds are parameters; defaults are the acceptance figures of issue 12):
- joint-limit violation: a (frame, joint) pair outside the URDF's position limits by more than
  `tolerance` rad.
- velocity-limit violation: a (frame, joint) pair whose speed |q[t+1] - q[t]| * fps exceeds the
  URDF's velocity limit by more than the relative `tolerance`.
- penetration: a frame where any collision geometry of any link (the URDF's meshes as convex
  hulls, its foot spheres) is more than `penetration_m` (1 cm) below the floor z = 0 or inside a
  scene shape (the clip's own scene, or the one given).
- near-ground (stance) frame: a foot's lowest collision sphere is within 2 cm of what it stands on
  (the floor or a scene shape's top under it) and moves vertically slower than 0.1 m/s; a frame is
  near-ground when either foot is.
- sliding: on a near-ground frame, the horizontal displacement of that foot's lowest sphere since the
  previous frame; a near-ground frame "slides" when it exceeds `sliding_m` (1 cm) for a stance foot.
  The sliding fraction is of near-ground frames.
- self-collision: a frame where a pair of non-adjacent links' collision geometries overlap by more
  than `penetration_m` (1 cm) (robot/collision.py: every such pair, 579 of them).
- contact preservation (clips that handle an object, clip.object): of the (frame, hand) pairs the
  source motion labels as touching the object (its wrist within 6 cm of the surface, see
  MocapRetargetConfig.object_contact_m), the share where the G1's hand point is within
  `object_contact_m` (8 cm: the label's 6 cm plus 2 cm for the robot's different arm) of the
  object's surface. Also reported: the largest such gap and the deepest hand point inside the object.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from g1_control import rotations as quat
from g1_control.motion.clip import MotionClip
from g1_control.motion.objects import ObjectShape
from g1_control.retarget.clip_geometry import ClipGeometry, measure
from g1_control.robot import description


@dataclass
class ClipMetrics:
    source: str
    num_frames: int
    duration_s: float
    joint_limit_violations: int
    """(frame, joint) pairs outside the URDF's position limits."""
    velocity_limit_violations: int
    """(frame, joint) pairs above the URDF's velocity limits."""
    max_velocity_ratio: float
    """Largest |dq| / velocity limit over the clip (<= 1 within limits)."""
    penetration_frames: int
    """Frames with any link more than penetration_m inside the floor or a scene shape."""
    penetration_fraction: float
    max_penetration_m: float
    penetration_link: str
    """The link reaching max_penetration_m ('' when nothing penetrates)."""
    near_ground_frames: int
    """Frames where a foot is near the ground and slow (geometric stance, see the module docstring)."""
    sliding_frames: int
    sliding_fraction: float
    """Of near-ground frames."""
    max_sliding_m_per_frame: float
    self_collision_frames: int
    """Frames where two non-adjacent links' collision geometries overlap by more than penetration_m."""
    max_self_penetration_m: float
    self_collision_pair: str
    """The pair reaching max_self_penetration_m ('' when none overlaps)."""
    joint_acc_rms_radps2: float
    """RMS joint acceleration: a jitter measure."""
    object_contact_frames: int = 0
    """(frame, hand) pairs where the source motion's hand is at the object (clip.object labels)."""
    object_contacts_kept: int = 0
    """Of those, pairs where the G1's hand is at the object too (see object_hand_distances)."""
    max_object_gap_m: float = 0.0
    """Largest G1 hand distance to the object's surface over the contact pairs."""
    max_object_penetration_m: float = 0.0
    """Deepest G1 hand point inside the object over the whole clip."""

    @property
    def object_contact_preserved_fraction(self) -> float | None:
        """Share of the source's hand-object contacts the G1 keeps (None: no object or no contact)."""
        return self.object_contacts_kept / self.object_contact_frames if self.object_contact_frames else None

    def passes(self, max_sliding_fraction: float = 0.01, min_object_contact_fraction: float = 0.95) -> bool:
        """The acceptance figures: no limit violation, no penetration or self-collision frame,
        sliding on at most 1 % of near-ground frames, object contacts kept."""
        kept = self.object_contact_preserved_fraction
        return (self.joint_limit_violations == 0 and self.velocity_limit_violations == 0
                and self.penetration_frames == 0 and self.self_collision_frames == 0
                and self.sliding_fraction <= max_sliding_fraction
                and (kept is None or kept >= min_object_contact_fraction))


def failures(metrics: ClipMetrics, max_sliding_fraction: float = 0.01,
             min_object_contact_fraction: float = 0.95) -> list[str]:
    """Why a clip misses the acceptance figures (ClipMetrics.passes), one phrase per figure it
    misses, with the numbers; [] when it passes."""
    m, out = metrics, []
    if m.joint_limit_violations:
        out.append(f"{m.joint_limit_violations} joint position(s) outside the URDF's limits")
    if m.velocity_limit_violations:
        out.append(f"{m.velocity_limit_violations} joint velocit(ies) above the URDF's limits (up to "
                   f"{m.max_velocity_ratio:.2f}x)")
    if m.penetration_frames:
        out.append(f"{m.penetration_fraction:.0%} of frames with a link > 1 cm inside the floor or the scene, up to "
                   f"{m.max_penetration_m * 100:.1f} cm ({m.penetration_link})")
    if m.sliding_fraction > max_sliding_fraction:
        out.append(f"{m.sliding_fraction:.0%} of stance frames sliding > 1 cm/frame (up to "
                   f"{m.max_sliding_m_per_frame * 100:.1f} cm)")
    if m.self_collision_frames:
        out.append(f"{m.self_collision_frames} self-collision frame(s), up to {m.max_self_penetration_m * 100:.1f} cm "
                   f"({m.self_collision_pair})")
    kept = m.object_contact_preserved_fraction
    if kept is not None and kept < min_object_contact_fraction:
        out.append(f"{kept:.0%} of the source's hand-object contacts kept")
    return out


def compute_metrics(clip: MotionClip, scene: tuple[ObjectShape, ...] | None = None, penetration_m: float = 0.01,
                    sliding_m: float = 0.01, tolerance: float = 1e-6, object_contact_m: float = 0.08,
                    geometry: ClipGeometry | None = None) -> ClipMetrics:
    """Metrics of `clip` against `scene` (default: the clip's own). `geometry`: a measure() of this
    clip already computed (the plot needs it too)."""
    limits = description.urdf_joint_limits()
    q = clip.joint_pos_rad
    outside = (q < limits["lower"] - tolerance) | (q > limits["upper"] + tolerance)
    speed = np.abs(np.diff(q, axis=0)) * clip.fps if clip.num_frames > 1 else np.zeros((0, q.shape[1]))
    ratio = speed / limits["velocity"]
    geo = geometry if geometry is not None else measure(clip, scene)
    pen = geo.penetration_m > penetration_m
    worst = int(geo.penetration_m.argmax())
    slides = ((geo.foot_slide_m > sliding_m) & geo.stance).any(axis=1)
    near = geo.stance.any(axis=1)
    collides = geo.self_penetration_m > penetration_m
    hit = int(geo.self_penetration_m.argmax())
    acc = np.diff(q, n=2, axis=0) * clip.fps**2 if clip.num_frames > 2 else np.zeros((1, q.shape[1]))
    contact_pairs = kept = 0
    max_gap = max_inside = 0.0
    if clip.object is not None:
        dist = object_hand_distances(clip)
        labels = clip.object.hand_contacts
        contact_pairs = int(labels.sum())
        kept = int(((dist <= object_contact_m) & labels).sum())
        max_gap = float(dist[labels].max()) if contact_pairs else 0.0
        max_inside = float(max(0.0, -dist.min()))
    return ClipMetrics(
        source=clip.source, num_frames=clip.num_frames, duration_s=clip.duration_s,
        joint_limit_violations=int(outside.sum()),
        velocity_limit_violations=int((ratio > 1.0 + tolerance).sum()),
        max_velocity_ratio=float(ratio.max()) if ratio.size else 0.0,
        penetration_frames=int(pen.sum()), penetration_fraction=float(pen.mean()),
        max_penetration_m=float(geo.penetration_m[worst]),
        penetration_link=geo.links[geo.penetration_link[worst]] if geo.penetration_link[worst] >= 0 else "",
        near_ground_frames=int(near.sum()), sliding_frames=int(slides.sum()),
        sliding_fraction=float(slides.sum() / near.sum()) if near.any() else 0.0,
        max_sliding_m_per_frame=float(geo.foot_slide_m[geo.stance].max()) if geo.stance.any() else 0.0,
        self_collision_frames=int(collides.sum()), max_self_penetration_m=float(geo.self_penetration_m[hit]),
        self_collision_pair=("/".join(geo.links[i] for i in geo.self_pair[hit]) if geo.self_pair[hit, 0] >= 0
                             else ""),
        joint_acc_rms_radps2=float(np.sqrt(np.mean(acc**2))),
        object_contact_frames=contact_pairs, object_contacts_kept=kept, max_object_gap_m=max_gap,
        max_object_penetration_m=max_inside,
    )


def object_hand_distances(clip: MotionClip) -> np.ndarray:
    """(T, 2) distance (m) of the G1's hands (left, right rubber-hand frame origins, the points the
    retargeter puts at the human's wrists) to the surface of clip.object; negative inside."""
    import pinocchio as pin

    from g1_control.ik.configuration import ik_model

    if clip.object is None:
        raise ValueError(f"clip '{clip.source}' has no object")
    model = ik_model()
    points = []
    for side in ("left", "right"):
        frame = model.frames[model.getFrameId(f"{side}_rubber_hand")]
        # The hand is fixed to the wrist yaw link, whose frame is its joint's (placement identity).
        link = next(f.name for f in model.frames if f.type == pin.FrameType.BODY
                    and f.parentJoint == frame.parentJoint and f.placement.isIdentity())
        parent = clip.body_index(link)
        offset = frame.placement.translation  # in the joint's (= link's) frame
        rot = quat.to_matrix(clip.body_quat_wxyz[:, parent])
        points.append(np.einsum("tij,j->ti", rot, offset) + clip.body_pos_w_m[:, parent])
    return clip.object.distance(np.stack(points, axis=1))


TABLE_COLUMNS = (("source", "clip", "{}"), ("num_frames", "frames", "{:d}"),
                 ("joint_limit_violations", "jlim", "{:d}"), ("velocity_limit_violations", "vlim", "{:d}"),
                 ("max_velocity_ratio", "v/vmax", "{:.2f}"), ("penetration_fraction", "pen>1cm", "{:.2%}"),
                 ("max_penetration_m", "pen max m", "{:.3f}"), ("sliding_fraction", "slide>1cm", "{:.2%}"),
                 ("max_sliding_m_per_frame", "slide max m", "{:.3f}"), ("self_collision_frames", "self>1cm", "{:d}"),
                 ("max_self_penetration_m", "self max m", "{:.3f}"),
                 ("object_contact_preserved_fraction", "obj contact kept", "{:.1%}"),
                 ("max_object_gap_m", "obj gap max m", "{:.3f}"), ("joint_acc_rms_radps2", "acc rms", "{:.1f}"))


def _cell(metrics: ClipMetrics, key: str, fmt: str) -> str:
    value = getattr(metrics, key)
    if key == "max_object_gap_m" and not metrics.object_contact_frames:
        value = None
    return "-" if value is None else fmt.format(value)


def format_table(rows: list[ClipMetrics]) -> str:
    """A plain-text table of a batch, one line per clip."""
    header = [h for _, h, _ in TABLE_COLUMNS]
    body = [[_cell(m, key, fmt) for key, _, fmt in TABLE_COLUMNS] for m in rows]
    widths = [max(len(r[i]) for r in [header] + body) for i in range(len(header))]
    lines = ["  ".join(c.ljust(w) for c, w in zip(header, widths))]
    lines.append("  ".join("-" * w for w in widths))
    lines += ["  ".join(c.ljust(w) for c, w in zip(r, widths)) for r in body]
    return "\n".join(lines)


def plot_metrics(clip: MotionClip, path: str | Path, metrics: ClipMetrics | None = None,
                 geometry: ClipGeometry | None = None, scene: tuple[ObjectShape, ...] | None = None) -> Path:
    """PNG: foot height over its support with stance shading, stance sliding, penetration and
    self-collision depth, velocity ratio, joint-limit margin (and the hands' distance to a handled object)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    geo = geometry if geometry is not None else measure(clip, scene)
    metrics = metrics or compute_metrics(clip, scene, geometry=geo)
    limits = description.urdf_joint_limits()
    t = np.arange(clip.num_frames) / clip.fps
    rows = 6 if clip.object is not None else 5
    fig, axes = plt.subplots(rows, 1, figsize=(10, 11 + 2 * (rows - 5)), sharex=True)
    for side, name, color in ((0, "left", "tab:blue"), (1, "right", "tab:orange")):
        axes[0].plot(t, (geo.foot_bottom_m[:, side] - geo.foot_support_m[:, side]) * 100, color=color,
                     label=f"{name} foot")
        axes[0].fill_between(t, 0, 2, where=geo.stance[:, side], color=color, alpha=0.15, step="mid")
        slide = np.where(geo.stance[:, side], geo.foot_slide_m[:, side] * 100, np.nan)
        axes[1].plot(t, slide, color=color, label=f"{name} near ground")
    axes[0].axhline(2, color="grey", lw=0.8, ls=":")
    axes[0].set_ylim(-3, 20)
    axes[0].set_ylabel("lowest sphere over\nsupport (cm)")
    axes[0].legend(loc="upper right")
    axes[1].axhline(1, color="red", lw=0.8, ls="--")
    axes[1].set_ylabel("near-ground\nslide (cm/frame)")
    axes[1].legend(loc="upper right")
    axes[2].plot(t, geo.penetration_m * 100, color="k", label="into floor / scene")
    axes[2].plot(t, geo.self_penetration_m * 100, color="tab:red", label="self-collision")
    axes[2].axhline(1, color="red", lw=0.8, ls="--")
    axes[2].set_ylabel("depth (cm)")
    axes[2].legend(loc="upper right")
    if clip.num_frames > 1:
        ratio = np.abs(np.diff(clip.joint_pos_rad, axis=0)) * clip.fps / limits["velocity"]
        axes[3].plot(t[1:], ratio.max(axis=1), color="k")
    axes[3].axhline(1, color="red", lw=0.8, ls="--")
    axes[3].set_ylabel("max |dq| / limit")
    margin = np.minimum(clip.joint_pos_rad - limits["lower"], limits["upper"] - clip.joint_pos_rad).min(axis=1)
    axes[4].plot(t, margin, color="k")
    axes[4].axhline(0, color="red", lw=0.8, ls="--")
    axes[4].set_ylabel("min limit margin (rad)")
    if clip.object is not None:
        dist = object_hand_distances(clip)
        for side, name, color in ((0, "left", "tab:blue"), (1, "right", "tab:orange")):
            axes[5].plot(t, dist[:, side] * 100, color=color, label=f"G1 {name} hand")
            axes[5].fill_between(t, 0, 8, where=clip.object.hand_contacts[:, side], color=color, alpha=0.15,
                                 step="mid")
        axes[5].axhline(8, color="red", lw=0.8, ls="--")
        axes[5].set_ylim(-5, 40)
        axes[5].set_ylabel(f"hand to {clip.object.shape.name} (cm)")
        axes[5].legend(loc="upper right")
    axes[-1].set_xlabel("time (s)")
    fig.suptitle(f"{clip.source}: pen>1cm {metrics.penetration_fraction:.2%}, self>1cm "
                 f"{metrics.self_collision_frames} frames, slide>1cm {metrics.sliding_fraction:.2%}, "
                 f"jlim {metrics.joint_limit_violations}, vlim {metrics.velocity_limit_violations}"
                 + (f", object contacts kept {metrics.object_contact_preserved_fraction:.1%}"
                    if metrics.object_contact_preserved_fraction is not None else ""))
    fig.tight_layout()
    path = Path(path)
    fig.savefig(path, dpi=80)
    plt.close(fig)
    return path
