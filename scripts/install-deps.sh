#!/usr/bin/env bash
# Installs the Debian 12 packages dicestack builds and tests with. Idempotent: when every
# package is already installed it changes nothing and does not touch the network.
# The Python package (python/) and its tests need pybind11, numpy, pytest, scikit-learn and
# matplotlib; HDF5 export/import needs libhdf5-dev, its tests python3-h5py; `--python` adds XGBoost's Python package, for bench/compare_python.py.
set -euo pipefail

packages=(
  cmake g++ make pkg-config
  libbox2d-dev            # physics (Box2D 2.4)
  libeigen3-dev           # linear algebra
  libopencv-core-dev libopencv-imgproc-dev libopencv-videoio-dev  # drawing; videos (a module loaded on use)
  libopencv-ml-dev        # SVR, MLP, random forest
  libxgboost-dev          # gradient-boosted trees
  xgboost                 # (libxgboost-dev's CMake config checks for its /usr/bin/xgboost)
  libnanoflann-dev        # k-NN
  libpagmo-dev            # differential evolution, basin hopping
  libnlopt-cxx-dev        # COBYLA, the local minimiser of basin hopping
  libcli11-dev            # command line
  nlohmann-json3-dev      # JSON
  libtbb-dev              # threads
  libsdl2-dev             # the interactive player
  libgif-dev              # GIF output of `dicestack render`
  zlib1g-dev              # PNG output
  libgtest-dev libgmock-dev libbenchmark-dev
  xvfb xdotool            # the headless test of `dicestack play`
  clang libclang-rt-14-dev  # scripts/fuzz.sh: clang++ and libFuzzer
  pybind11-dev python3-dev python3-numpy   # `import dicestack` (python/)
  python3-pytest python3-sklearn python3-matplotlib  # its tests and examples
  libhdf5-dev             # robomimic and Minari HDF5 export/import (dicestack_interop)
  python3-h5py            # the tests that read the exported HDF5 files
  python3-venv python3-pip python3-setuptools python3-wheel  # `pip install .` and its test
  libopenmpi-dev openmpi-bin  # running on MPI ranks (docs/scaling.md); without them the tool runs alone
  chromium chromium-driver python3-selenium  # the results pages' tests in a headless browser
)

if [ "${1:-}" = "--python" ]; then
  packages+=(python3-xgboost)
elif [ $# -gt 0 ]; then
  echo "install-deps: unknown argument '$1' (the only option is --python)" >&2
  exit 2
fi

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages present"
  exit 0
fi

sudo=""
if [ "$(id -u)" -ne 0 ]; then sudo="sudo"; fi
echo "install-deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$sudo apt-get update
$sudo apt-get install -y --no-install-recommends "${missing[@]}"
