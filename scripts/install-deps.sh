#!/usr/bin/env bash
# Installs every Debian 12 package mft-wbc needs. Non-interactive, idempotent, quick when all is present.
# Works as root or through sudo. Nothing else is downloaded: the project builds from these packages only.
set -euo pipefail

PACKAGES=(
  build-essential cmake ninja-build pkg-config dpkg-dev
  libeigen3-dev libyaml-cpp-dev libode-dev
  libfastrtps-dev libfastcdr-dev fastddsgen fastdds-tools
  cyclonedds-dev cyclonedds-tools
  libmrpt-obs-dev libmrpt-io-dev mrpt-apps
  libgtest-dev libgmock-dev libbenchmark-dev
  clang libclang-rt-dev    # scripts/fuzz.sh only (libFuzzer, ASan, UBSan); the build itself uses GCC
  python3 python3-yaml python3-matplotlib python3-distributed
  ffmpeg
  iproute2 nftables
  openssl
  mkdocs mkdocs-material
)

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#PACKAGES[@]} packages present"
  exit 0
fi

SUDO=""
if [ "$(id -u)" -ne 0 ]; then
  if command -v sudo >/dev/null 2>&1; then SUDO="sudo"; else
    echo "install-deps: missing packages (${missing[*]}) and not root, and no sudo" >&2; exit 1
  fi
fi
echo "install-deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
echo "install-deps: done"
