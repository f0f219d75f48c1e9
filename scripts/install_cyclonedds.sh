#!/usr/bin/env bash
# Install the DDS stack the real G1 speaks: Cyclone DDS 0.10.2 (C library from Debian) and the
# matching Python binding cyclonedds==0.10.2 (PyPI ships it only as source, so it is built here).
#
# Why 0.10.2 and not the 11.x wheels: the robot side runs 0.10.x, and a 0.10.2 process that
# discovers an 11.x one on the same domain segfaults. Every process of this project stays on 0.10.2.
#
# Why the CYCLONEDDS_HOME prefix: the binding's build script looks for
# $CYCLONEDDS_HOME/lib/libddsc.so, $CYCLONEDDS_HOME/include and $CYCLONEDDS_HOME/bin/idlc, while
# Debian keeps the library under /usr/lib/<multiarch>. A throw-away prefix whose include/, bin/
# and lib/ are links to Debian's directories satisfies it. The variable is set for the build only;
# at run time the binding finds libddsc through the normal loader path.
#
# Usage (root, Debian bookworm; CI runs exactly this):
#   bash scripts/install_cyclonedds.sh          # installs if missing, then checks the import
#   PYTHON=/path/to/python bash scripts/install_cyclonedds.sh
# Idempotent: a second run only re-checks.
set -euo pipefail

PYTHON="${PYTHON:-python}"
WANT="0.10.2"

have_binding() {
    "$PYTHON" - "$WANT" <<'PY' 2>/dev/null
import sys
from importlib.metadata import version
import cyclonedds.idl  # noqa: F401  (fails if libddsc cannot be loaded)
sys.exit(0 if version("cyclonedds") == sys.argv[1] else 1)
PY
}

if have_binding; then
    echo "install_cyclonedds: cyclonedds $WANT already installed and importable"
    exit 0
fi

if ! dpkg -s cyclonedds-dev >/dev/null 2>&1; then
    echo "install_cyclonedds: installing Debian's cyclonedds-dev (C library $WANT, idlc)"
    export DEBIAN_FRONTEND=noninteractive
    apt-get update -qq
    apt-get install -y -qq cyclonedds-dev cyclonedds-tools >/dev/null
fi
deb_version="$(dpkg-query -W -f='${Version}' cyclonedds-dev)"
case "$deb_version" in
    "$WANT"*) ;;
    *) echo "install_cyclonedds: error: Debian's cyclonedds-dev is $deb_version; this project needs $WANT (Debian bookworm ships it)" >&2
       exit 1 ;;
esac

multiarch="$(dpkg-architecture -qDEB_HOST_MULTIARCH 2>/dev/null || gcc -print-multiarch)"
prefix="$(mktemp -d)"
trap 'rm -rf "$prefix"' EXIT
ln -s /usr/include "$prefix/include"
ln -s /usr/bin "$prefix/bin"
ln -s "/usr/lib/$multiarch" "$prefix/lib"

echo "install_cyclonedds: building the Python binding cyclonedds==$WANT against $prefix -> /usr/lib/$multiarch"
CYCLONEDDS_HOME="$prefix" "$PYTHON" -m pip install --no-cache-dir --no-binary cyclonedds "cyclonedds==$WANT"

if ! have_binding; then
    echo "install_cyclonedds: error: cyclonedds $WANT was built but does not import" >&2
    exit 1
fi
echo "install_cyclonedds: cyclonedds $WANT installed"
