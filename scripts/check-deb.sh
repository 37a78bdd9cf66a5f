#!/usr/bin/env bash
# Builds the Debian package (cpack -G DEB) in build-deb/ and checks it: its file list holds the
# tool, the libraries, the CMake package and the Python module; apt resolves its dependencies;
# and, with --install, `apt-get install ./dicestack_*.deb` installs it on this machine, after
# which `dicestack` and `import dicestack` work from any folder (then it is removed again).
# Not part of CI (a build of its own).
#   scripts/check-deb.sh [--install] [--jobs J]
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build="$root/build-deb"
install=0 jobs=2
while [ $# -gt 0 ]; do
  case "$1" in
    --install) install=1; shift ;;
    --jobs) jobs="$2"; shift 2 ;;
    *) echo "check-deb.sh: unknown option '$1'" >&2; exit 2 ;;
  esac
done
fail() { echo "check-deb.sh: FAIL: $*" >&2; exit 1; }
python=/usr/bin/python3
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release -DCMAKE_UNITY_BUILD=ON -DDICESTACK_BUILD_TESTS=OFF \
  -DCMAKE_INSTALL_PREFIX=/usr -DDICESTACK_PYTHON_INSTALL_DIR=lib/python3/dist-packages -DPython3_EXECUTABLE=$python > /dev/null
cmake --build "$build" -j "$jobs"
(cd "$build" && rm -f dicestack_*.deb && cpack -G DEB > cpack.log) || { cat "$build/cpack.log"; fail "cpack failed"; }
deb=$(ls "$build"/dicestack_*.deb)
echo "check-deb.sh: built $deb ($(du -h "$deb" | cut -f1))"
dpkg-deb -c "$deb" | awk '{print $6}' > "$build/deb-files.txt"
lib=./usr/lib/$(dpkg-architecture -qDEB_HOST_MULTIARCH)  # GNUInstallDirs' libdir under /usr
for want in ./usr/bin/dicestack "$lib/libdicestack_learners.so.0" "$lib/cmake/dicestack/dicestackConfig.cmake" \
            ./usr/lib/python3/dist-packages/dicestack/__init__.py ./usr/include/dicestack/learners/leaderboard.hpp; do
  grep -qx "$want" "$build/deb-files.txt" || fail "the package lacks $want"
done
grep -q "^./usr/lib/python3/dist-packages/dicestack/_dicestack.*\.so$" "$build/deb-files.txt" || fail "the package lacks the compiled module"
echo "check-deb.sh: depends: $(dpkg-deb -f "$deb" Depends)"
apt-get install --simulate "$deb" > "$build/simulate.log" 2>&1 || { cat "$build/simulate.log"; fail "apt cannot resolve the package's dependencies"; }
if [ $install -eq 1 ]; then
  apt-get install -y "$deb" > "$build/install.log" 2>&1 || { cat "$build/install.log"; fail "apt-get install failed"; }
  trap 'apt-get purge -y dicestack > /dev/null 2>&1 || true' EXIT
  cd "$(mktemp -d)"
  env -u PYTHONPATH /usr/bin/dicestack --version
  env -u PYTHONPATH $python -c "import dicestack; print('import dicestack:', dicestack.__file__); dicestack.DiceStackEnv().reset(seed=1)"
  env -u PYTHONPATH /usr/bin/dicestack leaderboard --learners bc --regressors linear_svr --episodes 1 --threads 1 > board.md
  grep -q "| linear_svr | bc |" board.md || fail "the installed dicestack leaderboard has no linear_svr row"
fi
echo "check-deb.sh: ok"
