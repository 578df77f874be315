#!/usr/bin/env bash
# The deployed configuration (config/sss-slam.yaml) validates in every process, also with the
# command-line flags that override its keys (--file, --speed: the flag wins, the key stays known);
# a bad key or a bad flag exits 2 and names it.
#   deployed_config_test.sh CONFIG SONAR_DRIVER INS_BRIDGE SUBFRAME_BUFFER MATCHER OPTIMISER
set -u
config=$1; shift
failures=0
expect() {  # expect CODE TEXT_IN_OUTPUT COMMAND...
  local want=$1 text=$2; shift 2
  local out code
  out=$("$@" 2>&1); code=$?
  if [ "$code" -ne "$want" ] || ! grep -qF -- "$text" <<<"$out"; then
    echo "FAIL: $* -> exit $code (want $want, output should hold '$text'):"; echo "$out" | head -5
    failures=$((failures + 1))
  fi
}
for process in "$@"; do
  expect 0 "is valid" "$process" --config "$config" --check-config
  expect 2 "--bogus" "$process" --config "$config" --check-config --bogus
done
sonar_driver=$1 ins_bridge=$2
expect 0 "is valid" "$sonar_driver" --config "$config" --file /nonexistent.jsf --speed 2 --check-config
expect 0 "is valid" "$ins_bridge" --config "$config" --file /nonexistent.nmea --speed 0 --check-config
expect 2 "--speed" "$ins_bridge" --config "$config" --speed -1 --check-config
bad=$(mktemp); trap 'rm -f "$bad"' EXIT
sed 's/^  replay_speed: 1.0/  replay_speeed: 1.0/' "$config" > "$bad"
expect 2 "replay_speeed" "$sonar_driver" --config "$bad" --speed 2 --check-config
[ "$failures" -eq 0 ] && echo "deployed_config_test: all passed"
exit $((failures > 0))
