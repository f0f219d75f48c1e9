#!/usr/bin/env bash
# After a test process died of a signal (exit status >= 128, e.g. 139 for SIGSEGV): print the native
# stack of every thread from its core file, which Python's faulthandler cannot show (it prints the
# Python frames only; the crash itself is in C: Cyclone DDS, MuJoCo, ONNX Runtime). .ci/run enables
# core files (ulimit -c unlimited) and calls this with the test command's exit status.
# The kernel writes the core into the crashing process's working directory: the repository, or a test's
# tmp_path the code chdir'ed into (a deploy's run folder: stop 37's crash), so both are searched.
# Usage: scripts/ci_native_backtrace.sh STATUS [DIR ...]   (default: . and pytest's base temp directories)
status=${1:-0}
shift || true
dirs=("$@")
if [ ${#dirs[@]} -eq 0 ]; then
    dirs=(. "${TMPDIR:-/tmp}/pytest-of-$(id -un)")
fi
if [ "$status" -lt 128 ]; then
    exit 0
fi
echo "== the tests died of signal $((status - 128)): native backtraces from the core file"
cores=$(find "${dirs[@]}" -maxdepth 5 -type f \( -name core -o -name 'core.[0-9]*' \) -mmin -120 2>/dev/null)
if [ -z "$cores" ]; then
    echo "no core file in ${dirs[*]} (core_pattern: $(cat /proc/sys/kernel/core_pattern 2>/dev/null), ulimit -c $(ulimit -c))"
    exit 0
fi
if ! command -v gdb >/dev/null 2>&1; then
    (apt-get install -y -q gdb >/dev/null 2>&1 || { apt-get update -q >/dev/null 2>&1 && apt-get install -y -q gdb >/dev/null 2>&1; }) \
        || { echo "gdb could not be installed: no native backtrace"; exit 0; }
fi
for core in $cores; do
    echo "-- $core"
    gdb -q -batch -ex "set pagination off" -ex "info threads" -ex "thread apply all bt 25" "$(python3 -c "import sys; print(sys.executable)")" "$core" 2>&1 \
        | grep -v "^\[New LWP\|^warning: \|^Download" | head -400
    rm -f "$core"
done
