#!/usr/bin/env bash
# Installs dependencies, builds psc (a normal build and an ASan+UBSan build)
# and runs every test with CTest in both, then the fuzz targets briefly (clang
# build).  Usage: tools/test.sh [--no-sanitizers]
set -euo pipefail
cd "$(dirname "$0")/.."

tools/install-deps.sh
jobs=$(nproc)

cmake --preset default >/dev/null
cmake --build --preset default -j "$jobs"
ctest --preset default -j "$jobs"

if [ "${1:-}" != "--no-sanitizers" ]; then
  cmake --preset asan >/dev/null
  cmake --build --preset asan -j "$jobs"
  ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 ctest --preset asan -j "$jobs"

  # The libFuzzer targets (clang): each one's regression inputs, then 20 s of fresh fuzzing.
  cmake --preset fuzz >/dev/null
  cmake --build --preset fuzz -j "$jobs" --target psc-fuzz-frontend psc-fuzz-codegen psc-fuzz-plugin_abi
  ctest --preset fuzz -L fuzz
fi
