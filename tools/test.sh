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
  asan_ctest() { ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 ctest --preset asan "$@"; }
  # LeakSanitizer's own tracer now and then dies in its leak check at exit
  # ("Tracer caught signal 11", "LeakSanitizer has encountered a fatal
  # error"; docs/robustness.md), failing a test whose run had passed.  When
  # every failed test's output holds that, those tests run once more; any
  # other failure fails here.
  only_tracer_failures() {
    local dir=build-asan/Testing/Temporary name
    [ -s "$dir/LastTestsFailed.log" ] || return 1
    while IFS=: read -r _ name; do
      awk -v t="$name" '
        index($0, " Testing: " t) && substr($0, length($0) - length(t) + 1) == t { on = 1 }
        on && /LeakSanitizer has encountered a fatal error/ { found = 1 }
        on && index($0, "\"" t "\" end time") == 1 { exit }
        END { exit !found }' "$dir/LastTest.log" || return 1
    done < "$dir/LastTestsFailed.log"
  }
  if ! asan_ctest -j "$jobs"; then
    only_tracer_failures || exit 1
    echo "test.sh: LeakSanitizer's tracer failed in $(wc -l < build-asan/Testing/Temporary/LastTestsFailed.log) test(s); running them again" >&2
    asan_ctest --rerun-failed
  fi

  # The libFuzzer targets (clang): each one's regression inputs, then 20 s of fresh fuzzing.
  cmake --preset fuzz >/dev/null
  cmake --build --preset fuzz -j "$jobs" --target psc-fuzz-frontend psc-fuzz-codegen psc-fuzz-plugin_abi
  ctest --preset fuzz -L fuzz
fi
