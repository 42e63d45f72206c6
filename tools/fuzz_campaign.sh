#!/usr/bin/env bash
# Runs psc's libFuzzer targets (fuzz/): first every regression input of a
# target (tests/fuzz/regressions/TARGET/), then a fresh run of SECONDS seeded
# from the bundled games, the reference corpus' games and the regression
# inputs.  Prints each target's executions and the total; new crashes, hangs,
# leaks and sanitizer reports are saved under the findings folder and make the
# script fail.
#
# Usage: tools/fuzz_campaign.sh [--build DIR] [--seconds N] [--jobs N] [--corpus-sample N]
#                               [--seeds DIR] [--work DIR] [TARGET...]
#   --build DIR          the fuzz build (cmake --preset fuzz; default build-fuzz)
#   --seconds N          fresh fuzzing per target (default 60; 0: regressions only)
#   --jobs N             fuzzing processes per target at once, sharing the generated inputs (default 1)
#   --corpus-sample N    seed with N corpus games only (default: all of them)
#   --seeds DIR          seed games from this folder instead of the corpus (as fuzz/seed_corpus.py writes them)
#   --work DIR           where generated inputs and findings go (default DIR/fuzz-work)
#   TARGET               frontend, codegen, plugin_abi (default: all three)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=$root/build-fuzz
seconds=60
jobs=1
sample=0
seed_dir=""
work=""
targets=()
while (($#)); do
  case $1 in
    --build) build=$(cd "$2" && pwd); shift 2 ;;
    --seconds) seconds=$2; shift 2 ;;
    --jobs) jobs=$2; shift 2 ;;
    --corpus-sample) sample=$2; shift 2 ;;
    --seeds) seed_dir=$(cd "$2" && pwd); shift 2 ;;
    --work) work=$2; shift 2 ;;
    -h|--help) sed -n '2,19p' "$0"; exit 0 ;;
    *) targets+=("$1"); shift ;;
  esac
done
((${#targets[@]})) || targets=(frontend codegen plugin_abi)
work=${work:-$build/fuzz-work}
corpus=${PSC_CORPUS_DIR:-$root/../shared/corpus}
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1}

total=0
failed=0
for target in "${targets[@]}"; do
  binary=$build/fuzz/psc-fuzz-$target
  [ -x "$binary" ] || { echo "error: $binary is not built (cmake --preset fuzz && cmake --build --preset fuzz)"; exit 2; }
  regressions=$root/tests/fuzz/regressions/$target
  findings=$work/findings/$target
  generated=$work/generated/$target
  seeds=$work/seeds/$target
  mkdir -p "$findings" "$generated" "$regressions"
  # The same limits for replays and fresh runs: an input over them is a
  # finding.  Code generation of a large game takes seconds under ASan, so its
  # inputs (and seeds) are cut shorter, and given longer: the largest corpus
  # games take 30-84 s each under ASan with 16 jobs on 16 cores
  # (docs/robustness.md), which a 30 s limit reported as timeouts.
  max_len=65536
  timeout=30
  [ "$target" = codegen ] && max_len=16384 && timeout=120
  limits=(-timeout=$timeout -rss_limit_mb=4096 -max_len=$max_len)

  inputs=("$regressions"/*)
  if [ -e "${inputs[0]}" ]; then
    if ! "$binary" "${limits[@]}" "${inputs[@]}" > "$work/$target.regressions.log" 2>&1; then
      echo "FAIL $target: a regression input fails again (log: $work/$target.regressions.log)"
      failed=1
      continue
    fi
    echo "ok   $target: ${#inputs[@]} regression inputs"
  fi
  ((seconds > 0)) || continue

  rm -rf "$seeds"
  mkdir -p "$seeds"
  dictionary=()
  if [ "$target" != plugin_abi ]; then  # the ABI target's inputs are call sequences, not games
    dictionary=(-dict="$root/fuzz/puzzlescript.dict")
    cp "$root"/games/*.txt "$seeds"/
    if [ -n "$seed_dir" ]; then
      cp "$seed_dir"/* "$seeds"/
    elif [ -d "$corpus" ]; then
      sample_option=()
      ((sample > 0)) && sample_option=(--sample "$sample")
      python3 "$root/fuzz/seed_corpus.py" "$corpus" "$seeds" "${sample_option[@]}" > /dev/null
    fi
  fi
  # Crashes, sanitizer reports, leaks, hangs and out-of-memory inputs; slow
  # units (over 10 s) are kept there too, for information.
  findings_list() { find "$findings" -maxdepth 1 -type f \( -name 'crash-*' -o -name 'leak-*' -o -name 'timeout-*' -o -name 'oom-*' \) | sort; }
  before=$(findings_list)
  status=0
  pids=()
  # Each job adds what it finds to $generated and picks up the others' finds (libFuzzer's -reload).
  for ((job = 0; job < jobs; job++)); do
    "$binary" "${limits[@]}" -max_total_time="$seconds" -print_final_stats=1 -artifact_prefix="$findings/" \
      "${dictionary[@]}" "$generated" "$seeds" "$regressions" > "$work/$target.$job.log" 2>&1 &
    pids+=($!)
  done
  for pid in "${pids[@]}"; do wait "$pid" || status=$?; done
  runs=0
  for ((job = 0; job < jobs; job++)); do
    job_runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$work/$target.$job.log" | tail -n 1)
    runs=$((runs + ${job_runs:-0}))
  done
  total=$((total + runs))
  # LeakSanitizer's own tracer sometimes dies in the leak check at exit,
  # after the fuzzing loop has finished; libFuzzer then saves the unit in
  # hand as a crash.  Such a unit that passes when run again is set aside
  # (tool-failures/) with a warning; any other finding fails.
  new_findings=()
  while IFS= read -r f; do [ -n "$f" ] && new_findings+=("$f"); done < <(comm -13 <(echo "$before") <(findings_list))
  if ((${#new_findings[@]})) && grep -q "LeakSanitizer has encountered a fatal error" "$work/$target".*.log &&
     grep -q "^Done [0-9]* runs" "$work/$target".*.log; then
    reproduced=0
    for f in "${new_findings[@]}"; do
      "$binary" "${limits[@]}" "$f" > "$work/$target.rerun.$(basename "$f").log" 2>&1 || reproduced=1
    done
    if ((reproduced == 0)); then
      mkdir -p "$work/tool-failures/$target"
      mv "${new_findings[@]}" "$work/tool-failures/$target/"
      echo "WARN $target: LeakSanitizer's tracer failed in the leak check at exit; the unit saved does not fail again (set aside in $work/tool-failures/$target)"
      new_findings=()
      status=0
    fi
  fi
  if ((status != 0 || ${#new_findings[@]} > 0)); then
    echo "FAIL $target: $runs executions in ${seconds} s x $jobs jobs; new findings in $findings (logs: $work/$target.*.log)"
    failed=1
  else
    echo "ok   $target: $runs executions in ${seconds} s x $jobs jobs"
  fi
done
echo "total: $total executions"
exit $failed
