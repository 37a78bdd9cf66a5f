#!/usr/bin/env bash
# The README's quick start. On a fresh Debian 12 machine:
#   bash scripts/quickstart.sh        installs dependencies, builds (Release), runs the main job
#   bash scripts/quickstart.sh test   installs dependencies, builds (Release), runs every test in
#                                     the Release build, whose CTest summary ends the run (CI).
#                                     DICESTACK_SANITIZE=1 first runs them all under ASan + UBSan
#                                     too (scripts/sanitize.sh, its own build in build-sanitize/):
#                                     a second build, which would take CI past its 20 minutes
set -euo pipefail
cd "$(dirname "$0")/.."
mode="${1:-run}"

bash scripts/install-deps.sh
# The Python package is built for Debian's interpreter, which owns pybind11, numpy and pytest,
# whatever `python3` comes first on PATH.
python_args=()
if [ -x /usr/bin/python3 ]; then python_args=(-DPython3_EXECUTABLE=/usr/bin/python3); fi
# Unity build: each target's sources compiled a few at a time as one file, which parses the heavy
# headers (Eigen, OpenCV, pybind11, nlohmann-json, CLI11, GoogleTest) once per batch: a clean
# build in about half the time (README, "Build time"). Incremental builds recompile a whole
# batch: developers may reconfigure with -DCMAKE_UNITY_BUILD=OFF.
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DDICESTACK_WERROR=ON -DCMAKE_UNITY_BUILD=ON "${python_args[@]}"
cmake --build build -j 2

case "$mode" in
  run)
    mkdir -p out
    ./build/apps/dicestack leaderboard --out out/leaderboard.md
    # The paper's setting: three recordings made in this world from the paper's start, then knn
    # under BC and under DaD from training starts on them, rolled out from paper starts.
    ./build/apps/dicestack record --expert tracker --demos human --start paper --episodes 3 --seed 0 --out out/paper3
    ./build/apps/dicestack leaderboard --start paper --demos out/paper3 --regressors knn \
      --learners bc,dad:starts=training:corrector=track:episodes=100:tracker_refine=0 --out out/paper-setting.md
    ;;
  test)
    if [ "${DICESTACK_SANITIZE:-0}" = 1 ]; then bash scripts/sanitize.sh --jobs 2; fi
    ctest --test-dir build --output-on-failure -j 2
    ;;
  *)
    echo "usage: bash scripts/quickstart.sh [run|test]" >&2
    exit 2
    ;;
esac
