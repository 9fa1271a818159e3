#!/usr/bin/env bash
# Installs the Debian packages the project needs. Idempotent: does nothing
# (and needs no network) when everything is already installed.
set -euo pipefail

PACKAGES=(
  build-essential cmake ninja-build pkg-config git ca-certificates
  libeigen3-dev libsuitesparse-dev libmetis-dev libopenblas-dev libcgal-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  python3 python3-dev python3-meshio python3-numpy python3-matplotlib
  pybind11-dev python3-pybind11
  libcli11-dev nlohmann-json3-dev openmpi-bin libopenmpi-dev
)
# Optional extras: the FCL baseline of the collision benchmark.
OPTIONAL=(libfcl-dev)

missing=()
for p in "${PACKAGES[@]}" "${OPTIONAL[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done
[ ${#missing[@]} -eq 0 ] && exit 0

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
echo "[icd] installing: ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
# Required packages must install; optional ones may be unavailable.
req=()
for p in "${missing[@]}"; do
  case " ${OPTIONAL[*]} " in *" $p "*) ;; *) req+=("$p");; esac
done
if [ ${#req[@]} -gt 0 ]; then
  $SUDO apt-get install -y -qq --no-install-recommends "${req[@]}" >/dev/null
fi
for p in "${OPTIONAL[@]}"; do
  case " ${missing[*]} " in
    *" $p "*) $SUDO apt-get install -y -qq --no-install-recommends "$p" >/dev/null \
                || echo "[icd] optional package $p not installed (FCL baseline skipped)";;
  esac
done
