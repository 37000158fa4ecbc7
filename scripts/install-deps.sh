#!/usr/bin/env bash
# Installs, with apt-get, every Debian 12 package pixelgym needs to build, test and run.
# Packages already installed are skipped; nothing is downloaded when all are present.
# Runs apt-get directly as root, through sudo otherwise. Exits non-zero with a message
# naming the packages when they cannot be installed.
set -euo pipefail

PACKAGES=(
  # toolchain
  cmake g++ make pkg-config ccache
  # make deb: dpkg-shlibdeps, which finds the Debian packages the installed programs load
  dpkg-dev
  # make format-check (clang-format 14 on Debian 12)
  clang-format
  # engine: physics, URDF parsing, mesh import, linear algebra
  libbullet-dev liburdfdom-dev libconsole-bridge-dev libtinyxml-dev libassimp-dev libeigen3-dev
  # render: off-screen OpenGL (llvmpipe) through OSMesa or EGL (loaded at run time: libegl1,
  # Mesa's EGL driver and llvmpipe's DRI driver; headers in libegl-dev), and PNG files
  libosmesa6-dev libegl-dev libegl1 libegl-mesa0 libgl1-mesa-dri libpng-dev
  # wrappers: resize, colour conversion, H.264 video
  libopencv-dev
  # examples: the PPO trainer; OpenBLAS (pthreads) takes over libblas.so.3 from the reference
  # BLAS Debian's LibTorch links by default: several times faster convolutions and linear layers
  # on a CPU (see docs/training.md)
  libtorch-dev libopenblas0-pthread
  # the distributed trainer: Gloo's headers for c10d's ProcessGroupGloo (in libtorch_cpu)
  libgloo-dev
  # command line, JSON
  libcli11-dev nlohmann-json3-dev
  # the Python binding (python/) and its pytest suite (tests/python/), for Debian's python3
  python3-dev pybind11-dev python3-numpy python3-pytest
  # pip install . and make wheel (pip), and the wheel test's venv (python3 -m venv)
  python3-pip python3-venv
  # tests and benchmarks; ffmpeg for ffprobe, which the RecordVideo tests read clips back with
  libgtest-dev libgmock-dev libbenchmark-dev ffmpeg
)

is_installed() {
  [ "$(dpkg-query -W -f='${Status}' "$1" 2>/dev/null)" = "install ok installed" ]
}

missing=()
for package in "${PACKAGES[@]}"; do
  is_installed "$package" || missing+=("$package")
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#PACKAGES[@]} packages present"
  exit 0
fi

if ! command -v apt-get >/dev/null 2>&1; then
  echo "install-deps: apt-get not found; pixelgym's install script supports Debian 12." >&2
  echo "install-deps: install these packages by hand: ${missing[*]}" >&2
  exit 1
fi

if [ "$(id -u)" -eq 0 ]; then
  as_root=()
elif command -v sudo >/dev/null 2>&1; then
  as_root=(sudo)
else
  echo "install-deps: not root and sudo is not available; cannot install: ${missing[*]}" >&2
  exit 1
fi

echo "install-deps: installing ${#missing[@]} missing packages: ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
if ! "${as_root[@]}" apt-get update -qq; then
  echo "install-deps: 'apt-get update' failed; check the network and apt sources." >&2
  exit 1
fi
if ! "${as_root[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"; then
  echo "install-deps: 'apt-get install' failed for: ${missing[*]}" >&2
  exit 1
fi

still_missing=()
for package in "${missing[@]}"; do
  is_installed "$package" || still_missing+=("$package")
done
if [ ${#still_missing[@]} -ne 0 ]; then
  echo "install-deps: still not installed after apt-get: ${still_missing[*]}" >&2
  exit 1
fi
echo "install-deps: done"
