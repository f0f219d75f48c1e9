#!/usr/bin/env bash
# Install Unitree's official Python SDK wheel as a TEST ORACLE only (tests/hardware/unitree_reference.py).
# --no-deps: the wheel pulls opencv and friends that nothing here needs, and it is incomplete
# (its top-level __init__ imports a missing `b2` subpackage; its native CRC library is absent),
# so the project never imports it at run time. Its message modules need cyclonedds: run
# scripts/install_cyclonedds.sh first.
set -euo pipefail
PYTHON="${PYTHON:-python}"
"$PYTHON" -m pip install --no-deps "unitree_sdk2==1.0.1"
