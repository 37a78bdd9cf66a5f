#!/usr/bin/env bash
# The plugin SDK end to end: install dicestack into a scratch prefix, build the documented
# example plugin out of tree with find_package(dicestack), load it with --plugin and with
# DICESTACK_PLUGIN_PATH, list it, and train and evaluate it on the paper's recordings; check that
# it links only the regressor interface (plugin_deps.sh), and that the package still gives every
# target it gave before core/ and regressors/ were split.
set -euo pipefail
build_dir="$1"
source_dir="$2"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT

cmake --install "$build_dir" --prefix "$work/prefix" > /dev/null

# The package's targets (the names from before core/ and regressors/ were split, and the parts),
# and a program built against them with the headers it always included.
mkdir -p "$work/consumer"
cat > "$work/consumer/CMakeLists.txt" <<'CMAKE'
cmake_minimum_required(VERSION 3.25)
project(consumer LANGUAGES CXX)
find_package(dicestack REQUIRED)
foreach(t core foundation world experts baselines render datasets regressor_api regressors learners interop)
  if(NOT TARGET dicestack::${t})
    message(FATAL_ERROR "find_package(dicestack) gives no dicestack::${t}")
  endif()
endforeach()
if(NOT COMMAND dicestack_add_regressor_plugin)
  message(FATAL_ERROR "find_package(dicestack) gives no dicestack_add_regressor_plugin()")
endif()
add_executable(consumer main.cpp)
target_link_libraries(consumer PRIVATE dicestack::core dicestack::datasets)
CMAKE
cat > "$work/consumer/main.cpp" <<'CPP'
#include <dicestack/core/world.hpp>
#include <dicestack/datasets/builtin.hpp>
#include <dicestack/datasets/standardizer.hpp>

int main() {
  const dicestack::World world{dicestack::WorldConfig{}};
  const dicestack::Standardizer none;
  return world.state()[0] > 0.0 && none.dims() == 0 ? 0 : 1;
}
CPP
# DICESTACK_CONSUMER_CXX_FLAGS: set by CTest in the sanitizer build, whose libraries need ASan's runtime.
cmake -S "$work/consumer" -B "$work/consumer/build" -DCMAKE_PREFIX_PATH="$work/prefix" -DCMAKE_BUILD_TYPE=Release \
      -DCMAKE_CXX_FLAGS="${DICESTACK_CONSUMER_CXX_FLAGS:-}" > /dev/null
cmake --build "$work/consumer/build" > /dev/null
"$work/consumer/build/consumer" || { echo "FAIL: a program built against the installed targets did not run"; exit 1; }
cmake -S "$source_dir/examples/ridge_plugin" -B "$work/plugin" -DCMAKE_PREFIX_PATH="$work/prefix" \
      -DCMAKE_BUILD_TYPE=Release > /dev/null
cmake --build "$work/plugin" -j 2 > /dev/null
plugin="$work/plugin/libridge.so"
test -f "$plugin" || { echo "FAIL: plugin not built"; exit 1; }
# Built against the installed package, it still loads no simulator, optimiser or OpenCV.
bash "$source_dir/tests/regressors/plugin_deps.sh" "$plugin"

exe="$work/prefix/bin/dicestack"
export DICESTACK_CACHE_DIR="$work/cache"
"$exe" regressors --plugin "$plugin" | tee "$work/list.txt" | grep -A1 "^ridge"
grep -q "^ridge  (plugin $plugin)" "$work/list.txt" || { echo "FAIL: ridge not listed as a plugin"; exit 1; }
DICESTACK_PLUGIN_PATH="$work/plugin" "$exe" regressors --json | grep -q '"name":"ridge"' \
  || { echo "FAIL: DICESTACK_PLUGIN_PATH did not load the plugin"; exit 1; }
"$exe" bench regressors --plugin "$plugin" --regressors ridge --set lambda=2 --calls 100 | tee "$work/bench.txt"
awk '$1 == "ridge" { if ($5 > 0 && $5 < 2 && $6 > 0 && $6 < 2) ok = 1 } END { exit ok ? 0 : 1 }' "$work/bench.txt" \
  || { echo "FAIL: ridge did not train and evaluate"; exit 1; }
echo "plugin_sdk: ok"
