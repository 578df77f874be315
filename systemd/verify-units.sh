#!/usr/bin/env bash
# Checks the systemd units as installed: installs BUILD_DIR into a staging root (DESTDIR, as a
# package build does), runs `systemd-analyze verify` on every sss-slam unit there, and checks the
# chain's own rules. ctest runs it (Systemd.VerifyInstalledUnits) after the full build.
#   systemd/verify-units.sh BUILD_DIR        (CMAKE=/path/to/cmake to pick the cmake)
set -euo pipefail

build=${1:?usage: verify-units.sh BUILD_DIR}
if ! command -v systemd-analyze >/dev/null; then
  echo "verify-units: systemd-analyze not found: run tools/setup-deps.sh (Debian package systemd)"
  exit 1
fi

work=$(mktemp -d "${TMPDIR:-/tmp}/sss-slam-units.XXXXXX")
trap 'rm -rf "$work"' EXIT
stage=$work/root
if ! DESTDIR=$stage "${CMAKE:-cmake}" --install "$build" >"$work/install.log" 2>&1; then
  cat "$work/install.log"
  echo "verify-units: cmake --install failed (every installed target must be built first)"
  exit 1
fi

failures=0
fail() {
  echo "FAIL: $*"
  failures=$((failures + 1))
}

mapfile -t targets < <(find "$stage" -path '*/systemd/system/sss-slam.target')
if [ ${#targets[@]} -ne 1 ]; then
  echo "verify-units: expected one installed sss-slam.target under $stage, found ${#targets[@]}"
  exit 1
fi
unit_dir=$(dirname "${targets[0]}")
mapfile -t services < <(cd "$unit_dir" && ls sss-*.service)
echo "verify-units: ${#services[@]} services + sss-slam.target in /${unit_dir#"$stage"/}: ${services[*]}"

# A real root has systemd's own units (sysinit.target, network-online.target, ...), which the
# default dependencies pull in: borrow this machine's, never over ours.
for host_dir in /usr/lib/systemd/system /lib/systemd/system; do
  [ -d "$host_dir" ] || continue
  mkdir -p "$stage/usr/lib/systemd/system"
  for entry in "$host_dir"/*; do
    name=${entry##*/}
    case $name in sss-*) continue ;; esac
    [ -e "$stage/usr/lib/systemd/system/$name" ] || cp -a "$entry" "$stage/usr/lib/systemd/system/"
  done
done

# Programs from other packages (lcm-logger from liblcm-bin) would be there too: borrow this
# machine's. Ours (sss-*) must come from the install.
for service in "${services[@]}"; do
  program=$(sed -n 's/^ExecStart=[-@+!:]*\([^ ]*\).*/\1/p' "$unit_dir/$service")
  case ${program##*/} in sss-*) continue ;; esac
  if [ ! -e "$stage$program" ] && [ -x "$program" ]; then
    mkdir -p "$stage$(dirname "$program")" && cp "$program" "$stage$program"
    echo "verify-units: $service runs $program, not ours: copied in from this machine"
  fi
done

# 1. systemd-analyze verify: unknown keys, bad values, missing binaries. It warns and still exits
# 0 on most of these, so any line naming one of our units is a failure.
unit_paths=()
for unit in "${services[@]}" sss-slam.target; do unit_paths+=("/${unit_dir#"$stage"/}/$unit"); done
verify_status=0
verify_output=$(systemd-analyze verify --root="$stage" --man=no --generators=no "${unit_paths[@]}" 2>&1) ||
  verify_status=$?
while IFS= read -r line; do
  [ -n "$line" ] || continue
  if [[ $line =~ sss-[a-z-]+\.(service|target) ]]; then
    fail "systemd-analyze verify: $line"
  else
    echo "note (not an sss-slam unit): $line"
  fi
done <<<"$verify_output"
[ "$verify_status" -eq 0 ] || fail "systemd-analyze verify exited with $verify_status"

# Values of KEY= lines in a unit (one per line).
values() { sed -n "s/^$2=//p" "$1"; }

# 2. The target wants every service, and only installed ones.
target=$unit_dir/sss-slam.target
wants=" $(values "$target" Wants | tr '\n' ' ') "
for service in "${services[@]}"; do
  [[ $wants == *" $service "* ]] || fail "sss-slam.target does not Want $service"
done
for wanted in $wants; do
  case $wanted in
    sss-*) [ -f "$unit_dir/$wanted" ] || fail "sss-slam.target Wants $wanted, which is not installed" ;;
  esac
done

# 3. Every service: part of the target, restarted on failure, the service user, hardened; every
# process (all but the stock lcm-logger) notifies READY and pings the watchdog.
sysusers=$(cat "$stage"/usr/lib/sysusers.d/sss-slam.conf "$stage"/usr/local/lib/sysusers.d/sss-slam.conf 2>/dev/null || true)
expect() {  # KEY VALUE, of $unit
  values "$unit" "$1" | grep -qx -- "$2" || fail "$service: no $1=$2"
}
for service in "${services[@]}"; do
  unit=$unit_dir/$service
  expect PartOf sss-slam.target
  expect WantedBy sss-slam.target
  expect Restart on-failure
  expect ProtectSystem strict
  expect NoNewPrivileges yes
  user=$(values "$unit" User)
  [ -n "$user" ] || fail "$service: no User="
  grep -q "^u $user " <<<"$sysusers" || fail "$service: User=$user is not in the installed sysusers.d/sss-slam.conf"
  if [ "$service" != sss-lcm-logger.service ]; then
    expect Type notify
    expect NotifyAccess main
    [ -n "$(values "$unit" WatchdogSec)" ] || fail "$service: no WatchdogSec="
  fi

  # The environment the unit runs with: Environment= defaults, then the environment file.
  declare -A env=()
  while IFS= read -r assignment; do
    assignment=${assignment#\"} && assignment=${assignment%\"}
    env[${assignment%%=*}]=${assignment#*=}
  done < <(values "$unit" Environment)
  env_file=$(values "$unit" EnvironmentFile)
  env_file=${env_file#-}
  if [ ! -f "$stage$env_file" ]; then
    fail "$service: EnvironmentFile $env_file is not installed"
  else
    while IFS= read -r assignment; do
      value=${assignment#*=} && value=${value#\"} && value=${value%\"}
      env[${assignment%%=*}]=$value
    done < <(grep -E '^[A-Z_][A-Z0-9_]*=' "$stage$env_file")
  fi

  # 4. The process accepts its ExecStart command line and the installed configuration: run it
  # from the staging root with --check-config appended (absolute paths mapped into the stage).
  [ "$service" != sss-lcm-logger.service ] || continue
  command=()
  for word in $(values "$unit" ExecStart); do
    expanded=""
    while [[ $word =~ \$\{([A-Za-z_][A-Za-z0-9_]*)\} ]]; do  # ${NAME}, as systemd expands it
      name=${BASH_REMATCH[1]}
      [ -n "${env[$name]+set}" ] || fail "$service: ExecStart uses \${$name}, which nothing sets"
      expanded+=${word%%"${BASH_REMATCH[0]}"*}${env[$name]:-}
      word=${word#*"${BASH_REMATCH[0]}"}
    done
    word=$expanded$word
    if [[ $word == /* && -e $stage$word ]]; then word=$stage$word; fi
    command+=("$word")
  done
  if ! check_output=$("${command[@]}" --check-config 2>&1); then
    fail "$service: '${command[*]#"$stage"} --check-config' failed: $check_output"
  fi
done

# 5. Hardening does not regress: systemd's exposure score (0 safe .. 10 exposed, the threshold in
# tenths) stays at most 3.0; the units score 1.7-1.9 (network access and the INS bridge's ttys).
for service in "${services[@]}"; do
  if ! security_output=$(systemd-analyze security --offline=yes --root="$stage" --threshold=30 --no-pager \
                         "/${unit_dir#"$stage"/}/$service" 2>&1); then
    fail "$service: systemd-analyze security exposure above 3.0: $(tail -n 1 <<<"$security_output")"
  fi
done

if [ "$failures" -gt 0 ]; then
  echo "verify-units: $failures failures"
  exit 1
fi
echo "verify-units: all units pass"
