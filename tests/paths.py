"""Where the tests find the repository's files (never the working directory)."""

from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
LAUNCH_DIR = REPO / "launch"
