#!/usr/bin/env bash
# Install the DDS stack the real G1 speaks: Cyclone DDS 0.10.x (C library from the distribution:
# Debian bookworm ships 0.10.2, Ubuntu 24.04 0.10.4) and the Python binding of the same version
# (PyPI ships the 0.10 bindings only as source, so it is built here).
#
# Why 0.10.x and not the 11.x wheels: the robot side runs 0.10.x, and a 0.10 process that
# discovers an 11.x one on the same domain segfaults. Every process of this project stays on 0.10.
#
# Why the CYCLONEDDS_HOME prefix: the binding's build script looks for
# $CYCLONEDDS_HOME/lib/libddsc.so, $CYCLONEDDS_HOME/include and $CYCLONEDDS_HOME/bin/idlc, while
# Debian keeps the library under /usr/lib/<multiarch>. A throw-away prefix whose include/, bin/
# and lib/ are links to Debian's directories satisfies it. The variable is set for the build only;
# at run time the binding finds libddsc through the normal loader path.
#
# Usage (CI runs exactly this as root on Debian bookworm):
#   bash scripts/install_cyclonedds.sh          # installs if missing, then checks the import
#   PYTHON=/path/to/python bash scripts/install_cyclonedds.sh
# The apt step needs root; a user whose machine already has cyclonedds-dev builds the binding
# into their own environment. Idempotent: a second run only re-checks.
set -euo pipefail

PYTHON="${PYTHON:-python}"

have_binding() {  # $1: the wanted version
    "$PYTHON" - "$1" <<'PY' 2>/dev/null
import sys
from importlib.metadata import version
import cyclonedds.idl  # noqa: F401  (fails if libddsc cannot be loaded)
sys.exit(0 if version("cyclonedds") == sys.argv[1] else 1)
PY
}

if ! dpkg -s cyclonedds-dev >/dev/null 2>&1; then
    if [ "$(id -u)" != 0 ]; then
        echo "install_cyclonedds: cyclonedds-dev is not installed and installing it needs root (apt install cyclonedds-dev cyclonedds-tools)" >&2
        exit 1
    fi
    echo "install_cyclonedds: installing the distribution's cyclonedds-dev (C library 0.10.x, idlc)"
    export DEBIAN_FRONTEND=noninteractive
    apt-get update -qq
    apt-get install -y -qq cyclonedds-dev cyclonedds-tools >/dev/null
fi
deb_version="$(dpkg-query -W -f='${Version}' cyclonedds-dev)"
case "$deb_version" in
    0.10.*) ;;
    *) echo "install_cyclonedds: error: the distribution's cyclonedds-dev is $deb_version; this project needs 0.10.x (Debian bookworm: 0.10.2, Ubuntu 24.04: 0.10.4)" >&2
       exit 1 ;;
esac
WANT="${deb_version%%[-+~]*}"  # 0.10.2-2 -> 0.10.2: the binding of the library's own version

if have_binding "$WANT"; then
    echo "install_cyclonedds: cyclonedds $WANT already installed and importable"
    exit 0
fi

multiarch="$(dpkg-architecture -qDEB_HOST_MULTIARCH 2>/dev/null || gcc -print-multiarch)"
prefix="$(mktemp -d)"
trap 'rm -rf "$prefix"' EXIT
ln -s /usr/include "$prefix/include"
ln -s /usr/bin "$prefix/bin"
ln -s "/usr/lib/$multiarch" "$prefix/lib"

echo "install_cyclonedds: building the Python binding cyclonedds==$WANT against $prefix -> /usr/lib/$multiarch"
CYCLONEDDS_HOME="$prefix" "$PYTHON" -m pip install --no-cache-dir --no-binary cyclonedds "cyclonedds==$WANT"

if ! have_binding "$WANT"; then
    echo "install_cyclonedds: error: cyclonedds $WANT was built but does not import" >&2
    exit 1
fi
echo "install_cyclonedds: cyclonedds $WANT installed"
