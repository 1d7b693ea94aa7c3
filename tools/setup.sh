#!/usr/bin/env bash
# Installs everything Cohort needs to build and test, from the distribution's packages.
# Idempotent: packages already present are left alone. Works as root or through sudo.
# Supported: Debian 12 (bookworm) and Ubuntu 24.04 (noble). CUDA is optional and not installed here.
set -euo pipefail

PACKAGES=(
  build-essential cmake ninja-build pkg-config git
  libembree-dev libtbb-dev            # BVH builds (rtcBuildBVH) and the Embree 3 CPU tracer
  libopenimageio-dev openimageio-tools  # texture loading, EXR/PNG output, oiiotool
  libglfw3-dev libgl-dev              # gameplay viewer (optional at build time)
  libglm-dev                          # host-side vector maths
  ocl-icd-opencl-dev opencl-headers pocl-opencl-icd clinfo   # OpenCL tracer, PoCL on the CPU
  libgtest-dev libgmock-dev           # tests
  libcli11-dev nlohmann-json3-dev libzip-dev libspdlog-dev libfmt-dev   # CLI, JSON, .pk4, logging
  python3 python3-pip xvfb xauth    # viewer test under a virtual display; pip fetches OIDN
  ccache                              # compile cache (used when present; speeds rebuilds and worktrees)
  clang libclang-rt-dev               # the parsers' libFuzzer targets (tools/fuzz.sh; CI runs them bounded)
  libopenmpi-dev openmpi-bin          # remote tracers over MPI (cohort node, mpi:N); optional at build time
)

if [ -r /etc/os-release ]; then . /etc/os-release; else ID=unknown; VERSION_ID=; fi
case "${ID}:${VERSION_ID}" in
  debian:12|ubuntu:24.04) ;;
  *) echo "setup.sh: this script supports Debian 12 and Ubuntu 24.04; found '${PRETTY_NAME:-unknown}'." >&2
     echo "setup.sh: install the equivalents of: ${PACKAGES[*]}" >&2
     exit 1 ;;
esac

if ! command -v apt-get >/dev/null; then
  echo "setup.sh: apt-get not found; cannot install packages." >&2; exit 1
fi

SUDO=""
if [ "$(id -u)" -ne 0 ]; then
  if command -v sudo >/dev/null && sudo -n true 2>/dev/null; then SUDO="sudo"
  else echo "setup.sh: needs root or passwordless sudo to install packages." >&2; exit 1; fi
fi

missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "setup.sh: all ${#PACKAGES[@]} packages already installed."
else
  echo "setup.sh: installing ${#missing[@]} package(s): ${missing[*]}"
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

# Intel Open Image Denoise (the optional denoiser) is not packaged by Debian: its prebuilt libraries come
# from PyPI, into third_party/oidn (not committed).
"$(dirname "$0")/fetch_oidn.sh"
echo "setup.sh: done."
