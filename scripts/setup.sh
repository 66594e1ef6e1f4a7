#!/usr/bin/env bash
# Installs everything quadval needs from Debian 12 packages. Idempotent; run as root
# (or with sudo available). Set QUADVAL_SKIP_APT=1 to skip (e.g. on a machine you manage).
set -euo pipefail
[ "${QUADVAL_SKIP_APT:-0}" = 1 ] && exit 0

packages=(
  build-essential cmake pkg-config
  libeigen3-dev liblemon-dev libcli11-dev nlohmann-json3-dev libfmt-dev libmuparser-dev
  libgmp-dev zlib1g-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  gmsh libgmsh-dev python3-gmsh python3-vtk9 python3-networkx python3-numpy
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
[ ${#missing[@]} -eq 0 ] && { echo "setup: all packages present"; exit 0; }

SUDO=""
[ "$(id -u)" -ne 0 ] && SUDO=sudo
echo "setup: installing ${missing[*]}"
$SUDO apt-get update -qq
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
