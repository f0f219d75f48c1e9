"""The library on disk: `clips/*.npz` (MotionClip npz, g1_control.motion.formats.clip_npz) and
`index.json` listing every clip with its style, split, source and frame count.

Split: "train" or "test", decided per clip (never per frame), and a mirrored clip always shares
the split of its original, so no held-out motion leaks into training through its mirror image.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

from g1_control.errors import G1ControlError
from g1_control.motion.clip import MotionClip

INDEX_NAME = "index.json"
SPLITS = ("train", "test")


def default_library_dir() -> Path:
    """Where `g1 library build` writes the library and its readers look by default."""
    from g1_control.assets import cache_dir

    return cache_dir() / "library"


class LibraryError(G1ControlError):
    """A motion library that is missing, stale or malformed."""


@dataclass(frozen=True)
class ClipEntry:
    name: str
    file: str
    style: str
    split: str
    source: str
    mirrored: bool
    num_frames: int


class MotionLibrary:
    def __init__(self, root: str | Path):
        self.root = Path(root)
        path = self.root / INDEX_NAME
        if not path.is_file():
            raise LibraryError(f"{self.root}: no {INDEX_NAME}; build the library with `g1 library build`")
        try:
            self.index = json.loads(path.read_text())
            self.entries = [ClipEntry(**e) for e in self.index["clips"]]
        except (json.JSONDecodeError, KeyError, TypeError) as exc:
            raise LibraryError(f"{path}: malformed library index ({exc})") from None
        self.fps = float(self.index["fps"])
        self._cache: dict[str, MotionClip] = {}

    def select(self, split: str | None = None, styles: tuple[str, ...] | None = None) -> list[ClipEntry]:
        if split is not None and split not in SPLITS:
            raise LibraryError(f"unknown split '{split}'; expected one of {SPLITS}")
        return [e for e in self.entries if (split is None or e.split == split)
                and (styles is None or e.style in styles)]

    def load(self, entry: ClipEntry) -> MotionClip:
        from g1_control.motion.formats.clip_npz import read_clip_npz

        if entry.name not in self._cache:
            self._cache[entry.name] = read_clip_npz(self.root / entry.file)
        return self._cache[entry.name]

    def clips(self, split: str | None = None, styles: tuple[str, ...] | None = None) -> list[MotionClip]:
        return [self.load(e) for e in self.select(split, styles)]

    @property
    def styles(self) -> list[str]:
        return sorted({e.style for e in self.entries})

    def summary(self) -> str:
        rows: dict[str, dict[str, list[int]]] = {}
        for e in self.entries:
            r = rows.setdefault(e.style, {"train": [0, 0], "test": [0, 0]})
            r[e.split][0] += 1
            r[e.split][1] += e.num_frames
        lines = [f"{'style':<12} {'train clips':>11} {'frames':>7} {'test clips':>10} {'frames':>7}"]
        for style in sorted(rows):
            r = rows[style]
            lines.append(f"{style:<12} {r['train'][0]:>11} {r['train'][1]:>7} {r['test'][0]:>10} {r['test'][1]:>7}")
        total = sum(e.num_frames for e in self.entries)
        lines.append(f"{len(self.entries)} clips, {total} frames ({total / self.fps / 60:.1f} min at {self.fps:g} fps), "
                     f"{len(rows)} styles")
        return "\n".join(lines)
