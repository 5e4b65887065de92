#!/usr/bin/env bash
# Installs Segue's build and run dependencies from Debian 12 packages. Safe to run
# again: when everything is present it changes nothing and needs no network.
set -euo pipefail
PACKAGES=(
  cmake ninja-build g++ pkg-config
  libtorch-dev            # LibTorch (C++ API of PyTorch)
  libmujoco-dev libqhull-dev libmujoco-samples   # MuJoCo 2.2; samples ship mujoco-testspeed
  libopenblas0-openmp     # a fast BLAS for LibTorch (else the reference BLAS is used)
  libeigen3-dev libyaml-cpp-dev libspdlog-dev libgtest-dev
  libgloo-dev             # the headers c10d's ProcessGroupGloo includes (segue --nproc)
  iproute2                # ip netns: the two-host data-parallel tests
  clang libclang-rt-14-dev   # the recipe fuzzer (libFuzzer, ASan, UBSan; tests/fuzz)
  python3-torch           # to check exported TorchScript from Python
  python3-matplotlib python3-sklearn   # segue plot, report charts, tools/tsne_actions.py
  libegl-dev libopengl-dev libgl1-mesa-dri   # segue render: EGL + Mesa's software OpenGL, headless
  ffmpeg                  # segue render: encodes the video (without it, PNG frames are written)
)
missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install_deps: all ${#PACKAGES[@]} packages present"
  exit 0
fi
SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"
echo "install_deps: installing ${missing[*]}"
$SUDO apt-get update -qq
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
echo "install_deps: done"
