#!/usr/bin/env bash
# The README's test command: installs dependencies, builds, runs every test; then builds the unit
# tests with AddressSanitizer + UndefinedBehaviorSanitizer and runs them.
#   tools/test.sh                  everything (what CI runs)
#   tools/test.sh --no-sanitizers  only the release build and its tests (quicker, local)
set -euo pipefail
cd "$(dirname "$0")/.."

sanitizers=1
for arg in "$@"; do
  case "$arg" in
    --no-sanitizers) sanitizers=0 ;;
    *) echo "usage: tools/test.sh [--no-sanitizers]" >&2; exit 2 ;;
  esac
done

start=$(date +%s)
tools/setup-deps.sh

echo "== release build and full test suite"
cmake --preset release >/dev/null
cmake --build --preset release
ctest --preset release
release_done=$(date +%s)

if [ "$sanitizers" -eq 1 ]; then
  # Unit tests only; the relative-pose accuracy tests are left to the release run: Ceres in a
  # Debug+ASan build runs ~100x slower and their full RANSAC budget takes many minutes there
  # (the relative-pose rejection tests still run under the sanitizers).
  echo "== ASan+UBSan build and unit tests"
  export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1
  export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
  export LSAN_OPTIONS=suppressions=$PWD/tests/lsan.supp
  cmake --preset asan >/dev/null
  cmake --build --preset asan
  ctest --preset asan
fi
end=$(date +%s)
echo "tools/test.sh: release $((release_done - start)) s, total $((end - start)) s"
