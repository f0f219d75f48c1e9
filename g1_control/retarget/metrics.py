"""Quality report for any G1 clip: penetration, foot sliding, joint-limit and velocity-limit
violations, smoothness; a PNG plot per clip and a table for a batch.

Definitions (thresholds are parameters, defaults as in the project's acceptance figures):
- penetration depth of a frame: how far the lowest foot collision sphere (from the URDF) is below
  the ground z = 0, or how deep a foot sphere is inside a static scene shape (clip.scene, e.g. the
  boxes of a climb), whichever is more; a frame "penetrates" when deeper than `penetration_m` (1 cm).
- sliding of a stance foot: horizontal displacement of its sole point between two consecutive
  frames that are both labelled stance; a stance frame "slides" when that exceeds `sliding_m`
  (1 cm per frame).
- joint-limit violation: a joint angle outside g1.Q_MIN_RAD/Q_MAX_RAD by more than `tolerance`.
- velocity-limit violation: a per-frame joint speed |q[t+1] - q[t]| * fps above
  g1.VELOCITY_LIMIT_RADPS by more than `tolerance`.
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
from g1_control.robot import g1


@dataclass
class ClipMetrics:
    source: str
    num_frames: int
    duration_s: float
    joint_limit_violations: int
    """(frame, joint) pairs outside the position limits."""
    velocity_limit_violations: int
    """(frame, joint) pairs above the velocity limits."""
    max_velocity_ratio: float
    """Largest |dq| / velocity limit over the clip (<= 1 within limits)."""
    penetration_frames: int
    penetration_fraction: float
    penetration_duration_s: float
    max_penetration_m: float
    stance_frames: int
    sliding_frames: int
    sliding_fraction: float
    """Of stance frames."""
    sliding_duration_s: float
    max_sliding_m_per_frame: float
    joint_acc_rms_radps2: float
    """RMS joint acceleration: a jitter measure."""
    self_collision_frames: int = 0
    """Frames where a body-part sphere pair (arms vs torso, leg vs leg; ik.limits.self_collision_limit)
    overlaps by more than `penetration_m`."""
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

    def passes(self, max_penetration_fraction: float = 0.01, max_sliding_fraction: float = 0.02,
               min_object_contact_fraction: float = 0.95) -> bool:
        kept = self.object_contact_preserved_fraction
        return (self.joint_limit_violations == 0 and self.velocity_limit_violations == 0
                and self.penetration_fraction <= max_penetration_fraction
                and self.sliding_fraction <= max_sliding_fraction
                and (kept is None or kept >= min_object_contact_fraction))


@dataclass
class FootSeries:
    lowest_height_m: np.ndarray
    """(T, 2) lowest sphere bottom of each foot above the ground."""
    sole_xy_m: np.ndarray
    """(T, 2, 2) sole point of each foot, horizontal."""
    slide_m: np.ndarray
    """(T, 2) horizontal sole displacement from the previous frame (0 at frame 0)."""
    scene_depth_m: np.ndarray
    """(T, 2) deepest point of each foot inside a scene shape (clip.scene; 0 when none)."""


def foot_series(clip: MotionClip) -> FootSeries:
    from g1_control.ik.configuration import foot_contact_points

    spheres = foot_contact_points()
    t = clip.num_frames
    lowest = np.empty((t, 2))
    sole = np.empty((t, 2, 2))
    inside = np.zeros((t, 2))
    for side, link in enumerate(g1.FOOT_BODIES):
        b = clip.body_index(link)
        rot = quat.to_matrix(clip.body_quat_wxyz[:, b])
        pos = clip.body_pos_w_m[:, b]
        centres = np.array([c for c, _ in spheres[link]])
        radii = np.array([r for _, r in spheres[link]])
        world = np.einsum("tij,kj->tki", rot, centres) + pos[:, None, :]
        lowest[:, side] = (world[:, :, 2] - radii).min(axis=1)
        sole[:, side] = world[:, :, :2].mean(axis=1)
        for shape in clip.scene:  # a sphere is inside a shape by its radius minus its centre's distance
            inside[:, side] = np.maximum(inside[:, side], (radii - shape.signed_distance(world)).max(axis=1))
    slide = np.zeros((t, 2))
    slide[1:] = np.linalg.norm(np.diff(sole, axis=0), axis=-1)
    return FootSeries(lowest, sole, slide, inside)


def compute_metrics(clip: MotionClip, penetration_m: float = 0.01, sliding_m: float = 0.01,
                    tolerance: float = 1e-6, object_contact_m: float = 0.08) -> ClipMetrics:
    q = clip.joint_pos_rad
    below = q < (g1.Q_MIN_RAD - tolerance)
    above = q > (g1.Q_MAX_RAD + tolerance)
    speed = np.abs(np.diff(q, axis=0)) * clip.fps if clip.num_frames > 1 else np.zeros((0, q.shape[1]))
    ratio = speed / g1.VELOCITY_LIMIT_RADPS
    vel_viol = speed > g1.VELOCITY_LIMIT_RADPS * (1 + tolerance)
    feet = foot_series(clip)
    depth = np.maximum(0.0, np.maximum(-feet.lowest_height_m.min(axis=1), feet.scene_depth_m.max(axis=1)))
    pen = depth > penetration_m
    stance = clip.contacts.copy()
    stance[0] = False
    stance[1:] &= clip.contacts[:-1]  # both frames of the step are stance
    slides = (feet.slide_m > sliding_m) & stance
    n_stance = int(stance.sum())
    sliding_frames = int(slides.any(axis=1).sum())
    stance_frames = int(stance.any(axis=1).sum())
    acc = np.diff(q, n=2, axis=0) * clip.fps**2 if clip.num_frames > 2 else np.zeros((1, q.shape[1]))
    collisions = int((self_collision_distances(clip).min(axis=1) < -penetration_m).sum())
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
        joint_limit_violations=int(below.sum() + above.sum()),
        velocity_limit_violations=int(vel_viol.sum()),
        max_velocity_ratio=float(ratio.max()) if ratio.size else 0.0,
        penetration_frames=int(pen.sum()), penetration_fraction=float(pen.mean()),
        penetration_duration_s=float(pen.sum() / clip.fps), max_penetration_m=float(depth.max()),
        stance_frames=stance_frames if n_stance else 0, sliding_frames=sliding_frames,
        sliding_fraction=float(sliding_frames / stance_frames) if stance_frames else 0.0,
        sliding_duration_s=float(sliding_frames / clip.fps),
        max_sliding_m_per_frame=float(feet.slide_m[stance].max()) if n_stance else 0.0,
        joint_acc_rms_radps2=float(np.sqrt(np.mean(acc**2))), self_collision_frames=collisions,
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


def self_collision_distances(clip: MotionClip) -> np.ndarray:
    """(T, pairs) surface distances (m) of the default self-collision sphere pairs."""
    from g1_control.ik.configuration import Configuration
    from g1_control.ik.limits.self_collision_limit import SelfCollisionLimit
    from g1_control.robot import description

    conf = Configuration()
    limit = SelfCollisionLimit()
    out = np.empty((clip.num_frames, len(limit.pairs)))
    for k in range(clip.num_frames):
        quat_k = clip.root_quat_wxyz[k] / np.linalg.norm(clip.root_quat_wxyz[k])
        conf.update(description.pinocchio_q(clip.root_pos_w_m[k], quat_k, clip.joint_pos_rad[k]), check=False)
        out[k] = limit.distances(conf)
    return out


TABLE_COLUMNS = (("source", "clip", "{}"), ("num_frames", "frames", "{:d}"),
                 ("joint_limit_violations", "jlim", "{:d}"), ("velocity_limit_violations", "vlim", "{:d}"),
                 ("max_velocity_ratio", "v/vmax", "{:.2f}"), ("penetration_fraction", "pen>1cm", "{:.2%}"),
                 ("max_penetration_m", "pen max m", "{:.4f}"), ("sliding_fraction", "slide>1cm", "{:.2%}"),
                 ("max_sliding_m_per_frame", "slide max m", "{:.4f}"), ("self_collision_frames", "self-coll", "{:d}"),
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


def plot_metrics(clip: MotionClip, path: str | Path, metrics: ClipMetrics | None = None) -> Path:
    """PNG: foot heights with stance shading, stance sliding, velocity ratio, joint-limit margin."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    metrics = metrics or compute_metrics(clip)
    feet = foot_series(clip)
    t = np.arange(clip.num_frames) / clip.fps
    rows = 5 if clip.object is not None else 4
    fig, axes = plt.subplots(rows, 1, figsize=(10, 9 + 2 * (rows - 4)), sharex=True)
    for side, name, color in ((0, "left", "tab:blue"), (1, "right", "tab:orange")):
        axes[0].plot(t, feet.lowest_height_m[:, side] * 100, color=color, label=f"{name} foot")
        axes[0].fill_between(t, 0, 2, where=clip.contacts[:, side], color=color, alpha=0.15, step="mid")
        slide = np.where(clip.contacts[:, side], feet.slide_m[:, side] * 100, np.nan)
        axes[1].plot(t, slide, color=color, label=f"{name} stance")
    axes[0].axhline(-1, color="red", lw=0.8, ls="--")
    axes[0].set_ylabel("lowest point (cm)")
    axes[0].legend(loc="upper right")
    axes[1].axhline(1, color="red", lw=0.8, ls="--")
    axes[1].set_ylabel("stance slide (cm/frame)")
    if clip.num_frames > 1:
        ratio = np.abs(np.diff(clip.joint_pos_rad, axis=0)) * clip.fps / g1.VELOCITY_LIMIT_RADPS
        axes[2].plot(t[1:], ratio.max(axis=1), color="k")
    axes[2].axhline(1, color="red", lw=0.8, ls="--")
    axes[2].set_ylabel("max |dq| / limit")
    margin = np.minimum(clip.joint_pos_rad - g1.Q_MIN_RAD, g1.Q_MAX_RAD - clip.joint_pos_rad).min(axis=1)
    axes[3].plot(t, margin, color="k")
    axes[3].axhline(0, color="red", lw=0.8, ls="--")
    axes[3].set_ylabel("min limit margin (rad)")
    if clip.object is not None:
        dist = object_hand_distances(clip)
        for side, name, color in ((0, "left", "tab:blue"), (1, "right", "tab:orange")):
            axes[4].plot(t, dist[:, side] * 100, color=color, label=f"G1 {name} hand")
            axes[4].fill_between(t, 0, 8, where=clip.object.hand_contacts[:, side], color=color, alpha=0.15,
                                 step="mid")
        axes[4].axhline(8, color="red", lw=0.8, ls="--")
        axes[4].set_ylim(-5, 40)
        axes[4].set_ylabel(f"hand to {clip.object.shape.name} (cm)")
        axes[4].legend(loc="upper right")
    axes[-1].set_xlabel("time (s)")
    fig.suptitle(f"{clip.source}: pen>1cm {metrics.penetration_fraction:.2%}, slide>1cm {metrics.sliding_fraction:.2%}, "
                 f"jlim {metrics.joint_limit_violations}, vlim {metrics.velocity_limit_violations}"
                 + (f", object contacts kept {metrics.object_contact_preserved_fraction:.1%}"
                    if metrics.object_contact_preserved_fraction is not None else ""))
    fig.tight_layout()
    path = Path(path)
    fig.savefig(path, dpi=80)
    plt.close(fig)
    return path
