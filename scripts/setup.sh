#!/usr/bin/env bash
# Install g1-control and everything it needs on a fresh Debian/Ubuntu machine with Python >= 3.11.
#   scripts/setup.sh          # the package, its dependencies, headless rendering libraries, the policies
#   scripts/setup.sh --test   # the same plus the test dependencies
# Safe to re-run: every step skips what is already there.
set -euo pipefail
cd "$(dirname "$0")/.."
PY=${PYTHON:-python3}
extras=""
[ "${1:-}" = "--test" ] && extras="[test]"

say() { printf '\n== %s\n' "$*" >&2; }

# Headless rendering for run videos (EGL through Mesa, OSMesa as the fallback). Optional: runs
# work without it and say so; installed only where we are root with apt.
if command -v apt-get >/dev/null 2>&1 && [ "$(id -u)" = 0 ]; then
  need=""
  for pkg in libegl1 libegl-mesa0 libgl1-mesa-dri libosmesa6; do
    dpkg -s "$pkg" >/dev/null 2>&1 || need="$need $pkg"
  done
  if [ -n "$need" ]; then
    say "apt: installing$need (headless rendering)"
    apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq $need >/dev/null
  fi
else
  say "not root or no apt: skipping the rendering libraries (videos need libegl1/libosmesa6)"
fi

# torch first and pinned: a plain 'torch' requirement would pull the multi-GB CUDA build.
if ! $PY -c 'import torch, sys; sys.exit(0 if torch.__version__.startswith("2.13.0") else 1)' 2>/dev/null; then
  say "pip: torch==2.13.0 (CPU)"
  $PY -m pip install -q --disable-pip-version-check torch==2.13.0
fi

say "pip: g1-control$extras (editable)"
$PY -m pip install -q --disable-pip-version-check -e ".$extras"

# The real robot's DDS stack: Cyclone DDS 0.10.2 from Debian + the matching Python binding built
# from source (see the script for why). Needs root with apt; without it the robot transports are
# unavailable and the simulator still works.
if command -v apt-get >/dev/null 2>&1 && [ "$(id -u)" = 0 ]; then
  say "dds: cyclonedds 0.10.2 (Debian library + Python binding)"
  PYTHON=$PY bash scripts/install_cyclonedds.sh
else
  say "not root or no apt: skipping cyclonedds (needed for the real robot and g1 sim-robot)"
fi
if [ -n "$extras" ]; then
  say "test reference: Unitree's official message definitions (unitree_sdk2, --no-deps)"
  PYTHON=$PY bash scripts/install_unitree_reference.sh
  say "test data: demo human motion capture (holosoma-retargeting wheel, verified; 102 MB once)"
  $PY -m g1_control.cli.main policies fetch --asset holosoma-demo-mocap >/dev/null
fi

say "policies: fetching the pretrained G1 policies (holosoma-inference wheel, verified)"
$PY -m g1_control.cli.main policies fetch >/dev/null
say "ready: try 'g1 launch launch/sim_walk.yaml'"
