#!/usr/bin/env bash
# Installs every Debian 12 package Lumar needs to build, run and test.
# Safe to re-run: packages already present are skipped by apt-get.
# Usage: scripts/install-deps.sh [--fuzz]   (--fuzz: also clang and libFuzzer, for scripts/fuzz.sh)
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config
  libopencv-dev                      # calibration, video I/O, image processing
  libopencv-contrib-dev              # ChArUco boards (aruco)
  libembree-dev                      # ray queries (Embree 3)
  libopenimageio-dev                 # EXR / HDR environment maps
  libglfw3-dev libglm-dev libepoxy-dev libegl-dev libegl1-mesa-dev libx11-dev
  libgl1-mesa-dri libegl-mesa0 libglx-mesa0   # Mesa llvmpipe: OpenGL 4.5 core without a GPU
  libserial-dev libusb-1.0-0-dev libv4l-dev
  libtbb-dev
  libcli11-dev nlohmann-json3-dev libspdlog-dev libfmt-dev
  libassimp-dev                      # OBJ, PLY, glTF meshes
  libmeshoptimizer-dev               # coarser versions of the objects, drawn when small on screen
  libcgal-dev                        # closed solids around open scans (alpha wrapping): lumar solidify
  zlib1g-dev
  libjpeg-dev                        # MJPEG frames decoded as the camera's own (capture/jpeg_decoder.h)
  libgtest-dev libgmock-dev libbenchmark-dev
  libimgui-dev libstb-dev            # Dear ImGui (with its GLFW and OpenGL 3 backends): the window's panels
  xvfb xauth xdotool                 # window tests under xvfb-run, driven by xdotool
  python3                            # JSON checks in the command-line tests
)
case "${1:-}" in
  "") ;;
  --fuzz) packages+=(clang-14 libclang-rt-14-dev) ;;  # libFuzzer, ASan and UBSan runtimes
  *) echo "install-deps: unknown argument '$1'; usage: scripts/install-deps.sh [--fuzz]" >&2; exit 2 ;;
esac

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages present"
  exit 0
fi
echo "install-deps: installing ${#missing[@]} missing packages: ${missing[*]}"
SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
