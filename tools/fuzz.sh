#!/usr/bin/env bash
# Builds the libFuzzer targets with clang (everything instrumented) and fuzzes each parser.
#   tools/fuzz.sh [SECONDS_PER_TARGET]   (default 300)
# New inputs land in build/fuzz/corpus/<target>; crashes in build/fuzz/crash-<target>-*.
# Copy a crashing input into tests/<component>/corpus/ once fixed: CI replays that corpus.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-300}
tools/setup-deps.sh
CC=clang CXX=clang++ cmake -S . -B build/fuzz -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DSSS_FUZZ=ON \
  -DSSS_BUILD_BENCHMARKS=OFF >/dev/null
for target in jsf_fuzz nmea_fuzz xtf_fuzz; do
  if ! cmake --build build/fuzz --target "$target" 2>/dev/null; then
    echo "fuzz: no target $target yet, skipped"
    continue
  fi
  component=${target%_fuzz}
  case "$component" in jsf) dir=edgetech ;; nmea) dir=ins ;; *) dir=$component ;; esac
  mkdir -p "build/fuzz/corpus/$target"
  binary=$(find build/fuzz -name "$target" -type f -perm -u+x | head -1)
  echo "== $target for $seconds s"
  "$binary" "build/fuzz/corpus/$target" "tests/$dir/corpus" -max_total_time="$seconds" -max_len=8192 \
    -print_final_stats=1 -artifact_prefix="build/fuzz/crash-$target-" 2>&1 | tail -15
done
