#!/usr/bin/env bash
# Installs every Debian package sss-slam needs to build, test and run: the single list.
# Idempotent: when everything is already installed it only checks (no apt-get at all).
set -euo pipefail

PACKAGES=(
  # toolchain
  build-essential cmake ninja-build pkg-config git ccache
  # maths, vision, optimisation
  libeigen3-dev libopencv-dev libceres-dev libsuitesparse-dev
  libnanoflann-dev libgeographiclib-dev
  # middleware: LCM (lcm-gen, lcm-logger, lcm-logplayer) and Cyclone DDS (idlc)
  liblcm-dev liblcm-bin libglib2.0-dev cyclonedds-dev cyclonedds-tools
  # configuration, logging, service integration
  libyaml-cpp-dev libspdlog-dev libfmt-dev libsystemd-dev systemd nlohmann-json3-dev
  # command lines of every program
  libcli11-dev
  # survey products: GeoTIFF rasters (gdalinfo for checking them by hand)
  libgdal-dev gdal-bin
  # tests, benchmarks, fuzzing (clang's libFuzzer runtime)
  libgtest-dev libgmock-dev libbenchmark-dev clang libclang-rt-14-dev
  # tools: python for the report and plotting scripts
  python3 python3-numpy python3-matplotlib
)

# LCM needs socket receive buffers that hold a multi-megabyte subframe (systemd/60-sss-slam.conf
# sets the same on an installed vehicle). Raised, never lowered; skipped where /proc/sys is
# read-only (containers), where the LCM udpm test then says so.
raise_rmem_max() {
  local want=16777216 have
  have=$(cat /proc/sys/net/core/rmem_max 2>/dev/null || echo 0)
  if [ "$have" -lt "$want" ]; then
    if [ "$(id -u)" -eq 0 ]; then
      echo "$want" > /proc/sys/net/core/rmem_max 2>/dev/null || echo "setup-deps: cannot raise net.core.rmem_max (is /proc/sys read-only?)"
    else
      sudo sysctl -q -w net.core.rmem_max="$want" || echo "setup-deps: cannot raise net.core.rmem_max"
    fi
  fi
}

missing=()
for pkg in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$pkg")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "setup-deps: all ${#PACKAGES[@]} packages present"
  raise_rmem_max
  exit 0
fi

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
echo "setup-deps: installing ${#missing[@]} missing packages: ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -q
$SUDO apt-get install -y -q --no-install-recommends "${missing[@]}"
raise_rmem_max
