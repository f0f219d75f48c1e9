#!/usr/bin/env bash
# Install g1-control and everything it needs on Debian/Ubuntu with Python >= 3.11.
#   scripts/setup.sh          # the package (+ training and browser-view extras), rendering libraries, the policies
#   scripts/setup.sh --test   # the same plus the test dependencies (Ray among them) and test data
# Safe to re-run: every step skips what is already there.
#
# Where it installs: into the Python that runs `python3` (or $PYTHON), or the active virtual
# environment. A distribution's own Python refuses `pip install` outside a virtual environment
# (PEP 668, "externally-managed-environment"); there this script makes one in .venv (or
# $G1_VENV), installs into it and tells you to activate it, after which the README's commands
# run as written. Steps that need root (apt) are skipped for other users, with one line saying so.
set -euo pipefail
cd "$(dirname "$0")/.."
PY=${PYTHON:-python3}
test_extras=""
# --test: the test extras, and Ray for the test that fans trials out over a local Ray (tests/test_fanout.py)
[ "${1:-}" = "--test" ] && test_extras=",test,ray"

say() { printf '\n== %s\n' "$*" >&2; }
is_root() { [ "$(id -u)" = 0 ]; }
have_apt() { command -v apt-get >/dev/null 2>&1; }
apt_install() { apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq "$@" >/dev/null; }

if ! command -v "$PY" >/dev/null 2>&1; then
  echo "setup.sh: no $PY on PATH; install Python >= 3.11 (Debian/Ubuntu: apt install python3 python3-venv)" >&2
  exit 1
fi
"$PY" -c 'import sys; sys.exit(0 if sys.version_info >= (3, 11) else 1)' || {
  echo "setup.sh: $("$PY" --version 2>&1) is too old; g1-control needs Python >= 3.11" >&2; exit 1; }

# 1. Which environment: this interpreter, unless it is externally managed (PEP 668) and no virtual
#    environment is active; then .venv.
externally_managed() {
  "$1" - <<'PY'
import os, sys, sysconfig
in_venv = sys.prefix != sys.base_prefix
marker = os.path.join(sysconfig.get_path("stdlib"), "EXTERNALLY-MANAGED")
sys.exit(0 if not in_venv and os.path.isfile(marker) else 1)
PY
}
made_venv=""
if externally_managed "$PY"; then
  venv=${G1_VENV:-.venv}
  if [ ! -x "$venv/bin/python" ]; then
    say "$("$PY" --version) at $(command -v "$PY") is externally managed (PEP 668): making a virtual environment in $venv"
    if ! "$PY" -m venv "$venv" 2>/dev/null; then
      rm -rf "$venv"
      if is_root && have_apt; then
        apt_install python3-venv
        "$PY" -m venv "$venv"
      else
        echo "setup.sh: this Python cannot make a virtual environment (Debian/Ubuntu: apt install python3-venv, as root)" >&2
        exit 1
      fi
    fi
  fi
  PY="$(cd "$venv" && pwd)/bin/python"
  made_venv="$venv"
fi
pip() { "$PY" -m pip -q --disable-pip-version-check "$@"; }
say "installing into $("$PY" -c 'import sys; print(sys.prefix)') ($("$PY" --version))"

# 2. Root-only steps (apt): headless rendering libraries for run videos (EGL through Mesa, OSMesa
#    as the fallback; optional: runs work without them and say so), with --test headless Chromium
#    (the browser-view test screenshots the viser page), and the DDS library for the robot.
apt_pkgs=""
for pkg in libegl1 libegl-mesa0 libgl1-mesa-dri libosmesa6; do
  dpkg -s "$pkg" >/dev/null 2>&1 || apt_pkgs="$apt_pkgs $pkg"
done
if [ -n "$test_extras" ] && ! command -v chromium >/dev/null 2>&1 && ! command -v chromium-browser >/dev/null 2>&1; then
  apt_pkgs="$apt_pkgs chromium"
fi
dds_lib=yes
dpkg -s cyclonedds-dev >/dev/null 2>&1 || dds_lib=""
if is_root && have_apt; then
  if [ -n "$apt_pkgs" ]; then
    say "apt:$apt_pkgs (headless rendering${test_extras:+, browser for the view test})"
    apt_install $apt_pkgs
  fi
else
  skipped="${apt_pkgs:+$apt_pkgs (videos${test_extras:+, the browser-view test})}"
  if [ -z "$dds_lib" ]; then skipped="$skipped cyclonedds-dev (robot DDS)"; fi
  if [ -n "$skipped" ]; then say "skipping what needs root and apt:$skipped; run scripts/setup.sh once as root for them"; fi
fi

# 3. torch first and pinned: a plain 'torch' requirement would pull the multi-GB CUDA build.
#    Only training (g1 train) and the tests use it; the runtime runs its networks with ONNX Runtime.
if ! "$PY" -c 'import torch, sys; sys.exit(0 if torch.__version__.startswith("2.13.0") else 1)' 2>/dev/null; then
  say "pip: torch==2.13.0 (CPU, for training and tests)"
  pip install torch==2.13.0
fi

say "pip: g1-control[train,web$test_extras] (editable)"
pip install -e ".[train,web$test_extras]"

# 4. The robot's DDS stack: Cyclone DDS 0.10.x from the distribution + the matching Python binding
#    built from source (see the script). Without it the robot transports are unavailable; the
#    simulator works.
if { is_root && have_apt; } || [ -n "$dds_lib" ]; then
  say "dds: cyclonedds 0.10.x (the distribution's library + the Python binding)"
  PYTHON=$PY bash scripts/install_cyclonedds.sh
fi
if [ -n "$test_extras" ]; then
  say "test reference: Unitree's official message definitions (unitree_sdk2, --no-deps)"
  PYTHON=$PY bash scripts/install_unitree_reference.sh
  say "test data: demo human motion capture (holosoma-retargeting wheel, verified; 102 MB once)"
  "$PY" -m g1_control.cli.main policies fetch --asset holosoma-demo-mocap >/dev/null
fi

say "policies: fetching the pretrained G1 policies (holosoma-inference wheel, verified)"
"$PY" -m g1_control.cli.main policies fetch >/dev/null

if [ -n "$made_venv" ]; then
  say "ready, in the virtual environment $(cd "$made_venv" && pwd)"
  echo "   activate it in this shell, then run the command again (setup then only re-checks):" >&2
  echo "       . $made_venv/bin/activate" >&2
else
  say "ready: try 'g1 launch sim_tour' (the whole chain, ~2 min) or 'g1 launch sim_walk' (the quick one); g1 launch --list shows the launch files"
fi
