#!/usr/bin/env bash
# Installs every Debian package arcsim needs to build, test, benchmark and render.
# Idempotent: returns at once when everything is present. Run as root (or with sudo available).
set -euo pipefail

PACKAGES=(
  g++ make pkg-config
  libeigen3-dev            # dense/sparse linear algebra, CholmodSupport
  libsuitesparse-dev       # CHOLMOD sparse Cholesky
  libopenblas0-serial      # fast BLAS for CHOLMOD's supernodal factorisation; single-threaded, so results do
                           # not depend on the thread count (determinism)
  libnlopt-dev libnlopt-cxx-dev  # impact-zone constrained optimisation
  libjsoncpp-dev           # scene files
  libpng-dev               # replay frames
  libosmesa6-dev           # off-screen OpenGL rendering
  libgtest-dev             # tests
  libbenchmark-dev         # benchmarks
  libomp-dev               # OpenMP runtime (clang's libomp for the fuzz build; g++ ships libgomp)
  clang libclang-rt-14-dev # libFuzzer and the sanitizers for `make fuzz` (fuzz/)
)

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  exit 0
fi

echo "dependencies: installing ${missing[*]}" >&2
SUDO=""
if [ "$(id -u)" -ne 0 ]; then
  if command -v sudo >/dev/null 2>&1; then SUDO="sudo"; else
    echo "dependencies: need root to install: ${missing[*]} (run: apt-get install ${missing[*]})" >&2
    exit 1
  fi
fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
echo "dependencies: done" >&2
