#!/usr/bin/env bash
# The GPU checks, run on the device machine from the repository root with
# device/ carried (tools/device_bundle.sh makes it).  Stages, in the order given:
#   compile   NVRTC time (min and median of COMPILE_REPEATS) and ptxas resource report of each benchmark game, per
#             GPU state layout in LAYOUTS (default auto)
#   prebuild  the benchmark games' CUDA plugins built in parallel (bench then finds them cached)
#   bench     psc bench --backend cuda, batch sweep, for each benchmark game
#   replay    every carried corpus trace replayed on each of REPLAY_BACKENDS (default cuda; "cpu cuda" for
#             both), states dumped (compare backends: tools/compare_dumps.py); reports for tools/fidelity_report.py
#   sanitize  compute-sanitizer memcheck on a sample of replays, a rollout and tests/robustness/hostile_abi.py --cuda
#   fromptx   kernels loaded from PTX (PSC_CUDA_FROM_PTX=1, the other-GPU path,
#             compile units linked by the driver): a rollout and a few replays
#   python    the Python package on the GPU: zero-copy views, CUDA tests, PPO
#             (plugins prebuilt here into out/python-gpu, carried)
#   expand    search's batched expansion on the GPU (psc bench --expand), every benchmark game's
#             level 0 and sokoban's level 1, batch sweep
#   search    breadth-first and beam search with their states on the GPU against the host's
#             (tests/search/device_search_test.py, SEARCH_SECONDS a level, default 20)
#   scale     one search on the GPU of each of SCALE_LEVELS (game:level, default notsnake:0 zenpuzzle:0
#             limerick:6 atlas:8) for SCALE_SECONDS (default 60), SCALE_ALGORITHM (default bfs), with
#             SCALE_OPTIONS (more psc solve options, such as --beam-width 131072), its JSON record and
#             progress lines kept, named with SCALE_TAG where set: the whole search's rate and its largest store
#   solve     psc solve --backend cuda over every level of the benchmark games (bench/solve_report.py),
#             SOLVE_ALGORITHM (default portfolio), SOLVE_SECONDS a level (default 60), SOLVE_JOBS games at once,
#             SOLVE_PER_LEVEL=1 a psc solve (and plugin) per level
#   cpp       examples/cpp built against the installed psc in device/ (find_package): a CPU
#             and a CUDA batch of sokoban stepped with the same actions must observe the same bytes
#   fuzz      a fuzz campaign on the device machine's cores (tools/fuzz_campaign.sh --jobs $(nproc)), FUZZ_SECONDS
#             per target (default 60), FUZZ_TARGETS (default all three); needs device_bundle.sh's FUZZ=1 bundle
#   buildtime cold `psc GAME -o GAME.so --target cuda --levels 0` of each benchmark game (fresh cache), end to end,
#             host side in one compile process (PSC_COMPILE_JOBS=1) and in parallel ones (the default), in turn
#             (BUILD_JOBS="0": the default only), BUILD_REPEATS times (default 2); table in buildtime.txt
#             (with each NVRTC compile unit's seconds);
#             BUILD_VARIANTS (lines NAME=PSC) builds each game with every variant in turn, one file each
#             (buildtime_NAME.txt), so that a slow spell of the host falls on all of them
#   profile   Nsight Compute on each benchmark game's stepping kernel (PROFILE_BATCH environments, default 131072,
#             8 steps a launch, level 0; PROFILE_GAMES names some): one CSV per game in profile.tar.gz, with the
#             warp state section's summary (cycles a warp waits an instruction); bench/ncu_table.py makes the table
#   expandprofile Nsight Compute on search's expansion kernel (psc_expand_kernel) for each of EXPAND_PROFILE_LEVELS
#             (game:level, default sokoban:0 atlas:0 atlas:9 atlas:10), EXPAND_PROFILE_STATES states a launch (default
#             16384): expandprofile.tar.gz; bench/ncu_table.py --kernel psc_expand_kernel --batch CHILDREN --steps 1
#   divergence Nsight Compute's source counters of the stepping kernel, SASS instruction by instruction, for each of
#             DIVERGENCE_GAMES (default all), as profile launches it (built with -lineinfo): divergence.tar.gz;
#             bench/ncu_divergence.py makes the table; GAME_lines.csv has each SASS instruction under the line of
#             generated source it came from (bench/ncu_lines.py adds them up by line)
#   multigpu  (several GPUs) python/tests/test_multi_gpu.py; then for each of MULTI_GAMES (game:batches, batches
#             per GPU) psc bench --devices over 1 and all GPUs (one process), and examples/torchrun_rollout.py
#             on 1 and all GPUs at the last batch (one process a GPU)
# FAST_COMPILE sets psc's --fast-compile (compile, prebuild, bench, replay, sanitize);
# GPU_STATE its --gpu-state (prebuild, bench, replay); RULES its --rules (prebuild, bench, replay); GAMES limits bench to some games; REPLAY_SECONDS bounds each replayed suite,
# REPLAY_IDS (a file of case ids) limits it to some cases, REPLAY_SUITES to some suites,
# REPLAY_JOBS sets how many run at once and REPLAY_CASE_SECONDS how long each may take,
# REPLAY_VERBOSE=1 keeps each case's compile, batch and stepping times in the report;
# SANITIZE_EVERY picks every Nth carried case for the sanitizer, SANITIZE_IDS (a file of
# case ids) names them instead, SANITIZE_JOBS sets how many run at once.
# PSC names another psc to run (default device/bin/psc; another build installed under device/, say).
# Results go to $OUT (default out/gpu).   tools/gpu_check.sh compile bench
set -uo pipefail
cd "$(dirname "$0")/.."
out=${OUT:-out/gpu}
mkdir -p "$out"
export LD_LIBRARY_PATH=$PWD/device/lib:/usr/local/cuda/lib64:${LD_LIBRARY_PATH:-}
export XDG_CACHE_HOME=${XDG_CACHE_HOME:-/tmp/psc-cache}
# CUDA code compiled beforehand on the development machine (tools/device_prebuild.sh).
if [ -f device/cache.tar.xz ] && [ ! -d "$XDG_CACHE_HOME/psc" ]; then
    mkdir -p "$XDG_CACHE_HOME" && tar -xJf device/cache.tar.xz -C "$XDG_CACHE_HOME"
fi
psc=${PSC:-$PWD/device/bin/psc}
# Nsight Compute's metrics of kernel $1's second launch (the first warms up), the clocks as they are
# (METHOD.md), as CSV on stdout, for the command that follows: the profile and expandprofile stages.
ncu_metrics() {
    local kernel=$1
    shift
    local metrics=gpu__time_duration.sum,launch__registers_per_thread,launch__grid_size,launch__block_size,launch__stack_size
    metrics+=,sm__warps_active.avg.pct_of_peak_sustained_active,sm__maximum_warps_per_active_cycle_pct,sm__warps_launched.sum
    metrics+=,smsp__issue_active.avg.pct_of_peak_sustained_active,smsp__inst_executed.sum,smsp__thread_inst_executed.sum
    metrics+=,smsp__sass_average_branch_targets_threads_uniform.pct,smsp__thread_inst_executed_per_inst_executed.ratio
    metrics+=,l1tex__t_bytes_pipe_lsu_mem_local_op_ld.sum,l1tex__t_bytes_pipe_lsu_mem_local_op_st.sum,dram__bytes.sum
    metrics+=,smsp__average_warp_latency_issue_stalled_long_scoreboard.ratio,smsp__average_warp_latency_issue_stalled_barrier.ratio
    timeout 300 ncu --clock-control none --kernel-name "$kernel" --launch-skip 1 --launch-count 1 \
        --metrics "$metrics" --section WarpStateStats --csv --print-units base "$@"
}
corpus=/tmp/psc-corpus
if [ ! -f $corpus/INDEX.json ]; then mkdir -p $corpus && tar -xJf device/corpus.tar.xz -C $corpus; fi
jobs=$(nproc)
python=$(command -v python3)
batches=${BATCHES:-1,1024,16384,131072,1048576,4194304}
fast=(${FAST_COMPILE:+--fast-compile "$FAST_COMPILE"})
state=(${GPU_STATE:+--gpu-state "$GPU_STATE"})
rules=(${RULES:+--rules "$RULES"})

for stage in "$@"; do
    echo "== $stage"
    case $stage in
    compile)
        # Fresh NVRTC compiles per game and layout (empty cache), COMPILE_REPEATS
        # of them (default 3; the first call also loads NVRTC from disk), the
        # last log kept: min and median compile time, the compile units, and
        # the stepping kernel's registers, stack and spills.
        mkdir -p "$out/compile"
        for layout in ${LAYOUTS:-auto}; do
            for game in bench/games/*.txt; do
                name=$(basename "$game" .txt)
                log="$out/compile/$name.$layout.log"
                times=()
                for _ in $(seq "${COMPILE_REPEATS:-3}"); do
                    XDG_CACHE_HOME=$(mktemp -d) "$psc" "$game" --emit ptx --levels 0 --gpu-state "$layout" --verbose "${fast[@]}" \
                        2>"$log" >/dev/null
                    times+=("$(sed -n 's/.*CUDA compile (nvrtc[^)]*) \([0-9.]*\) s.*/\1/p' "$log")")
                done
                printf '%-16s %-9s min %6s s  median %6s s  %-8s %s\n' "$name" "$layout" \
                    $(printf '%s\n' "${times[@]}" | sort -g | awk '{t[NR] = $1} END {print t[1], t[int((NR + 1) / 2)]}') \
                    "$(sed -n 's/.*CUDA compile (nvrtc, [a-z]* layout, \([0-9]*\) units).*/\1 units/p' "$log")" \
                    "$(grep -A3 "entry function 'psc_run_kernel'" "$log" | grep -E 'stack frame|Used' | sed 's/.*ptxas[ a-z]*: *\.* *//' | tr '\n' ' ')"
            done
        done | tee "$out/compile_times.txt"
        ;;
    prebuild)
        # Builds the benchmark plugins in parallel into the cache that bench reads.
        ls bench/games/*.txt | xargs -P "$jobs" -I{} sh -c 'p=$0 g=$1; shift; "$p" "$g" -o "/tmp/$(basename "$g" .txt).so" --target cuda --levels 0 "$@"' \
            "$psc" {} "${fast[@]}" "${state[@]}" "${rules[@]}"
        ;;
    bench)
        dir="$out/bench${GPU_STATE:+-$GPU_STATE}${RULES:+-rules-$RULES}"
        mkdir -p "$dir"
        for name in ${GAMES:-$(cd bench/games && ls *.txt | sed 's/.txt$//')}; do
            game=bench/games/$name.txt
            "$psc" bench "$game" --backend cuda --batch "$batches" --repeats 5 --warmup 1 "${fast[@]}" "${state[@]}" \
                "${rules[@]}" > "$dir/$name.txt" 2>&1
            echo "$name: $(tail -1 "$dir/$name.txt")"
        done
        ;;
    replay)
        for backend in ${REPLAY_BACKENDS:-cuda}; do
            for suite in ${REPLAY_SUITES:-testsuite scraped}; do
                timeout "${REPLAY_SECONDS:-3000}" $python tools/corpus_replay.py --psc "$psc" --corpus $corpus --suite $suite --backend $backend "${fast[@]}" "${state[@]}" "${rules[@]}" \
                    --jobs "${REPLAY_JOBS:-$jobs}" --timeout "${REPLAY_CASE_SECONDS:-300}" --dumps /tmp/psc-dumps/$backend/$suite --json "$out/${suite}_$backend.json" ${REPLAY_IDS:+--ids-file "$REPLAY_IDS"} \
                    ${REPLAY_VERBOSE:+--verbose} | tail -5
            done
        done
        ;;
    sanitize)
        # Cases side by side (each compiles first, most of its time).  A line
        # per case goes to sanitize.txt as it ends, the full reports into
        # sanitize.tar.gz (few files come back from a device call).
        logs=$(mktemp -d)
        summary="$out/sanitize.txt"
        : > "$summary"
        if [ -n "${SANITIZE_IDS:-}" ]; then
            cases=$($python tools/corpus_replay.py --corpus $corpus --suite all --ids-file "$SANITIZE_IDS" --list)
        else
            cases=$($python -c "import json; d=json.load(open('$corpus/INDEX.json')); print(' '.join('$corpus/' + e['path'] for e in d[::${SANITIZE_EVERY:-60}]))")
        fi
        printf '%s\n' $cases | xargs -P "${SANITIZE_JOBS:-$jobs}" -I{} sh -c 'p=$0 c=$1 logs=$2 summary=$3; shift 3
            log="$logs/$(basename "$c" .json).txt"
            compute-sanitizer --tool memcheck --error-exitcode 9 "$p" replay "$c" --backend cuda "$@" > "$log" 2>&1
            rc=$?
            echo "$(basename "$c" .json): exit $rc $(grep -o "ERROR SUMMARY: [0-9]* errors\?" "$log")" >> "$summary"' \
            "$psc" {} "$logs" "$summary" "${fast[@]}"
        compute-sanitizer --tool memcheck --error-exitcode 9 "$psc" bench bench/games/sokoban.txt --backend cuda \
            --batch 1,1000 --steps 50 --repeats 1 --warmup 0 > "$logs/bench_sokoban.txt" 2>&1
        echo "bench sokoban: exit $? $(grep -o 'ERROR SUMMARY: [0-9]* errors\?' "$logs/bench_sokoban.txt")" >> "$summary"
        # Hostile calls on a CUDA batch too: keys no state has, expanded on the GPU.  Its
        # calls provoke the driver's errors on purpose (host memory where device memory
        # belongs), which memcheck would count: only memory errors are counted here.
        compute-sanitizer --tool memcheck --report-api-errors no --error-exitcode 9 $python tests/robustness/hostile_abi.py \
            "$psc" games/sokoban.txt --cuda > "$logs/hostile_abi_cuda.txt" 2>&1
        echo "hostile_abi --cuda: exit $? $(tail -1 "$logs/hostile_abi_cuda.txt") $(grep -o 'ERROR SUMMARY: [0-9]* errors\?' "$logs/hostile_abi_cuda.txt" | sort | uniq -c | tr '\n' ' ')" >> "$summary"
        cat "$summary"
        tar -czf "$out/sanitize.tar.gz" -C "$logs" .
        ;;
    fromptx)
        mkdir -p "$out/fromptx"
        PSC_CUDA_FROM_PTX=1 "$psc" bench bench/games/atlas.txt --backend cuda --batch 1,4096 --steps 200 --repeats 3 \
            --warmup 1 --verbose > "$out/fromptx/bench_atlas.txt" 2>&1
        echo "atlas from PTX: exit $? $(tail -1 "$out/fromptx/bench_atlas.txt")"
        for id in ${FROMPTX_CASES:-}; do
            PSC_CUDA_FROM_PTX=1 "$psc" replay "$corpus/$id" --backend cuda > "$out/fromptx/$(basename "$id" .json).txt" 2>&1
            echo "$id from PTX: exit $? $(tail -1 "$out/fromptx/$(basename "$id" .json).txt")"
        done
        ;;
    python)
        export PYTHONUNBUFFERED=1
        $python examples/gpu_zero_copy.py --plugin out/python-gpu/gems.so 2>&1 | tee "$out/python_zero_copy.txt"
        PSC_CUDA_PLUGIN=out/python-gpu/gems.so PSC_BINARY="$psc" $python -m pytest python/tests/test_cuda.py -v -rs -p no:cacheprovider \
            2>&1 | tee "$out/python_test_cuda.txt" | tail -15
        $python examples/ppo.py --plugin out/python-gpu/sokoban.so --csv "$out/ppo_log.csv" \
            --time-limit "${PPO_SECONDS:-170}" 2>&1 | tee "$out/ppo.txt" | tail -8
        ;;
    expand)
        mkdir -p "$out/expand"
        for spec in ${EXPAND_LEVELS:-$(cd bench/games && ls *.txt | sed 's/.txt$/:0/') sokoban:1}; do
            name=${spec%:*}
            level=${spec#*:}
            "$psc" bench "bench/games/$name.txt" --expand --level "$level" --backend cuda --batch "${EXPAND_BATCHES:-1024,16384,262144,1048576}" \
                --repeats 5 --warmup 1 "${fast[@]}" > "$out/expand/$name.L$level.txt" 2>&1
            echo "$name level $level: $(tail -1 "$out/expand/$name.L$level.txt")"
        done
        ;;
    search)
        $python tests/search/device_search_test.py "$psc" "${SEARCH_SECONDS:-20}" > "$out/device_search_test.txt" 2>&1
        echo "device_search_test: exit $?, $(tail -1 "$out/device_search_test.txt")"
        grep FAIL "$out/device_search_test.txt" | head -20
        ;;
    scale)
        mkdir -p "$out/scale"
        for spec in ${SCALE_LEVELS:-notsnake:0 zenpuzzle:0 limerick:6 atlas:8}; do
            name=${spec%:*}
            level=${spec#*:}
            run="$out/scale/$name.L$level${SCALE_TAG:+.$SCALE_TAG}"
            "$psc" solve "bench/games/$name.txt" --level "$level" --backend cuda --algorithm "${SCALE_ALGORITHM:-bfs}" \
                --time-limit "${SCALE_SECONDS:-60}" ${SCALE_OPTIONS:-} --format json > "$run.json" 2> "$run.progress"
            tr '\r' '\n' < "$run.progress" | grep -v '^$' > "$run.lines"
            mv "$run.lines" "$run.progress"
            echo "$name level $level${SCALE_TAG:+ ($SCALE_TAG)}: $(cat "$run.json") $(tail -1 "$run.progress")"
        done
        ;;
    solve)
        $python bench/solve_report.py run --psc "$psc" --backend cuda --time-limit "${SOLVE_SECONDS:-60}" \
            --algorithm "${SOLVE_ALGORITHM:-portfolio}" ${SOLVE_GAMES:+--games "$SOLVE_GAMES"} --jobs "${SOLVE_JOBS:-1}" ${SOLVE_PER_LEVEL:+--per-level} \
            --out "$out/solve_cuda_${SOLVE_ALGORITHM:-portfolio}.jsonl"
        ;;
    fuzz)
        [ -d device/build-fuzz ] || tar -xJf device/build-fuzz.tar.xz -C device
        seeds=/tmp/psc-fuzz-seeds
        mkdir -p $seeds && tar -xJf device/fuzz-seeds.tar.xz -C $seeds
        # The ABI target's plugins built once, not by each of its jobs.
        plugins=()
        for game in sokoban rigid ice; do
            "$psc" "games/$game.txt" -o "/tmp/psc-fuzz-$game.so" --target cpu && plugins+=("/tmp/psc-fuzz-$game.so")
        done
        # One target at a time, its findings packed as it ends (a cut call still brings back the earlier ones).
        for target in ${FUZZ_TARGETS:-frontend codegen plugin_abi}; do
            PSC_FUZZ_PLUGINS=$(IFS=:; echo "${plugins[*]}") \
                tools/fuzz_campaign.sh --build device/build-fuzz --work /tmp/psc-fuzz-work --seeds $seeds --jobs "$jobs" \
                --seconds "${FUZZ_SECONDS:-60}" "$target" 2>&1 | tee -a "$out/fuzz.txt"
            if [ -n "$(find /tmp/psc-fuzz-work/findings -type f 2>/dev/null)" ]; then
                tar -czf "$out/fuzz-findings.tar.gz" -C /tmp/psc-fuzz-work findings
            fi
        done
        ;;
    buildtime)
        variants=${BUILD_VARIANTS:-"=$psc"}
        rm -f "$out"/buildtime*.txt
        for _ in $(seq "${BUILD_REPEATS:-2}"); do
            for game in bench/games/*.txt; do
                name=$(basename "$game" .txt)
                while IFS= read -r variant; do
                    [ -n "$variant" ] || continue
                    vname=${variant%%=*}
                    file=$out/buildtime${vname:+_$vname}.txt
                    for jobs in ${BUILD_JOBS:-1 0}; do
                        cache=$(mktemp -d)
                        start=$(date +%s.%N)
                        PSC_COMPILE_JOBS=$jobs XDG_CACHE_HOME=$cache "${variant#*=}" "$game" -o "$cache/$name.so" --target cuda \
                            --levels 0 --verbose "${fast[@]}" > "$cache/log" 2>&1
                        status=$?
                        end=$(date +%s.%N)
                        nvrtc=$(sed -n 's/.*CUDA compile (nvrtc[^)]*) \([0-9.]*\) s.*/\1/p' "$cache/log")
                        host=$(sed -n 's/.*plugin .* (built in \([0-9.]*\) s.*/\1/p' "$cache/log")
                        units=$(sed -n 's/.*unit seconds: //p' "$cache/log")
                        printf '%-16s jobs %-2s exit %s  total %6.2f s  nvrtc %6s s  host %6s s  units %s\n' "$name" "${jobs/0/all}" \
                            "$status" "$(awk "BEGIN {print $end - $start}")" "$nvrtc" "$host" "$units" | tee -a "$file"
                        rm -rf "$cache"
                    done
                done <<< "$variants"
            done
        done
        ;;
    profile)
        # The stepping kernel (ncu_metrics).
        mkdir -p "$out/profile"
        for name in ${PROFILE_GAMES:-$(basename -s .txt bench/games/*.txt)}; do
            game=bench/games/$name.txt
            ncu_metrics psc_run_kernel "$psc" bench "$game" --backend cuda --batch "${PROFILE_BATCH:-131072}" --steps 8 --repeats 1 --warmup 1 \
                "${fast[@]}" "${state[@]}" > "$out/profile/$name.csv" 2> "$out/profile/$name.err"
            echo "$name: ncu exit $?, $(grep -c psc_run_kernel "$out/profile/$name.csv") metric rows"
        done
        tar -czf "$out/profile.tar.gz" -C "$out" profile && rm -rf "$out/profile"
        ;;
    expandprofile)
        # The expansion kernel (ncu_metrics); the bench's first call is its first launch.
        mkdir -p "$out/expandprofile"
        for spec in ${EXPAND_PROFILE_LEVELS:-sokoban:0 atlas:0 atlas:9 atlas:10}; do
            name=${spec%:*}
            level=${spec#*:}
            ncu_metrics psc_expand_kernel "$psc" bench "bench/games/$name.txt" --expand --level "$level" --backend cuda \
                --batch "${EXPAND_PROFILE_STATES:-16384}" --repeats 1 --warmup 0 "${fast[@]}" \
                > "$out/expandprofile/$name.L$level.csv" 2> "$out/expandprofile/$name.L$level.err"
            echo "$name level $level: ncu exit $?, $(grep -c psc_expand_kernel "$out/expandprofile/$name.L$level.csv") metric rows"
        done
        tar -czf "$out/expandprofile.tar.gz" -C "$out" expandprofile && rm -rf "$out/expandprofile"
        ;;
    divergence)
        mkdir -p "$out/divergence"
        for game in ${DIVERGENCE_GAMES:-$(basename -s .txt bench/games/*.txt)}; do
            XDG_CACHE_HOME=/tmp/psc-divergence-cache PSC_NVRTC_OPTIONS=-lineinfo timeout 300 \
                ncu --clock-control none --kernel-name psc_run_kernel --launch-skip 1 --launch-count 1 \
                --section SourceCounters -o "/tmp/psc-divergence-$game" -f \
                "$psc" bench "bench/games/$game.txt" --backend cuda --batch "${PROFILE_BATCH:-131072}" --steps 8 --repeats 1 \
                --warmup 1 "${fast[@]}" "${state[@]}" > "$out/divergence/$game.log" 2>&1
            echo "$game: ncu exit $?"
            ncu --import "/tmp/psc-divergence-$game.ncu-rep" --page source --csv --print-source sass \
                > "$out/divergence/${game}_sass.csv" 2>> "$out/divergence/$game.log"
            ncu --import "/tmp/psc-divergence-$game.ncu-rep" --page source --csv --print-source cuda,sass \
                > "$out/divergence/${game}_lines.csv" 2>> "$out/divergence/$game.log"
        done
        tar -czf "$out/divergence.tar.gz" -C "$out" divergence && rm -rf "$out/divergence"
        ;;
    multigpu)
        # Results in one archive, multigpu.tar.gz (a device call brings back a few files only).
        mkdir -p "$out/multigpu"
        gpus=$(nvidia-smi -L | wc -l)
        all=$(seq -s, 0 $((gpus - 1)))
        export PSC_BINARY=$psc PYTHONUNBUFFERED=1
        $python -m pytest python/tests/test_multi_gpu.py -v -rs -p no:cacheprovider 2>&1 |
            tee "$out/multigpu/test_multi_gpu.txt" | tail -6
        for spec in ${MULTI_GAMES:-sokoban:1048576,4194304 slidings:1048576,4194304 atlas:262144,1048576}; do
            name=${spec%%:*}
            batches=${spec#*:}
            for devices in 0 "$all"; do
                "$psc" bench "bench/games/$name.txt" --backend cuda --devices "$devices" --batch "$batches" --repeats 5 \
                    --warmup 1 "${fast[@]}" > "$out/multigpu/bench_$name.${devices//,/-}.txt" 2>&1
                echo "$name devices $devices, one process: $(tail -1 "$out/multigpu/bench_$name.${devices//,/-}.txt")"
            done
            for n in 1 "$gpus"; do
                timeout 300 $python -m torch.distributed.run --nproc-per-node "$n" examples/torchrun_rollout.py \
                    --game "bench/games/$name.txt" --num-envs "${batches##*,}" --steps 20 \
                    --json "$out/multigpu/torchrun_$name.$n.json" > "$out/multigpu/torchrun_$name.$n.txt" 2>&1
                echo "$name torchrun $n: $(grep -E 'steps/s|FAIL|Error' "$out/multigpu/torchrun_$name.$n.txt" | tail -2)"
            done
        done
        tar -czf "$out/multigpu.tar.gz" -C "$out" multigpu && rm -rf "$out/multigpu"
        ;;
    cpp)
        "$psc" games/sokoban.txt -o /tmp/sokoban-all.so --target all &&
            cmake -S examples/cpp -B /tmp/psc-example -G Ninja -DCMAKE_PREFIX_PATH="$PWD/device" > /dev/null &&
            cmake --build /tmp/psc-example > /dev/null &&
            /tmp/psc-example/rollout /tmp/sokoban-all.so 1024 200 2>&1 | tee "$out/cpp_example.txt"
        echo "cpp: exit $?"
        ;;
    *) echo "unknown stage $stage"; exit 2 ;;
    esac
done
