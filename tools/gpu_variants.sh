#!/usr/bin/env bash
# Side-by-side GPU benchmarks of code-generation variants, run on the device
# machine with device/ carried: each variant is "NAME=BINARY [psc bench
# options...]" (BINARY under device/bin), each game a bench/games name.
#   VARIANTS=("units=psc" "whole=psc --cuda-units 1") GAMES="slidings takeheart" tools/gpu_variants.sh
# (VARIANTS is read as a newline-separated list.)  Results: $OUT/variants/NAME/GAME.txt
# and a table of best steps/s and batch-1 steps/s, $OUT/variants/summary.txt, with each
# build's NVRTC seconds and kernels' stack bound beside it in $OUT/variants/builds.txt.
# A game's run per variant stops after GAME_SECONDS (default 300; "fail" in the table):
# a large corpus level at a large batch can take longer than a device call.
set -uo pipefail
cd "$(dirname "$0")/.."
out=${OUT:-out/gpu}/variants
mkdir -p "$out"
export LD_LIBRARY_PATH=$PWD/device/lib:/usr/local/cuda/lib64:${LD_LIBRARY_PATH:-}
export XDG_CACHE_HOME=${XDG_CACHE_HOME:-/tmp/psc-cache}
batches=${BATCHES:-1,16384,131072,1048576}
printf '%-16s' game > "$out/summary.txt"
while IFS= read -r v; do [ -n "$v" ] && printf '%28s' "${v%%=*} best/batch1" >> "$out/summary.txt"; done <<< "$VARIANTS"
echo >> "$out/summary.txt"
for game in $GAMES; do
    printf '%-16s' "$game" >> "$out/summary.txt"
    while IFS= read -r v; do
        [ -n "$v" ] || continue
        name=${v%%=*}
        read -r binary options <<< "${v#*=}"
        mkdir -p "$out/$name"
        result="$out/$name/$game.txt"
        timeout "${GAME_SECONDS:-300}" device/bin/$binary bench "bench/games/$game.txt" --backend cuda --batch "$batches" \
            --repeats "${REPEATS:-5}" --warmup 1 $options --verbose > "$result" 2>&1
        best=$(sed -n 's/^steps\/s: //p' "$result")
        single=$(awk '$1 == 1 && NF == 6 {print $3}' "$result")
        printf '%28s' "${best:-fail}/${single:-?}" >> "$out/summary.txt"
        nvrtc=$(sed -n 's/^psc: CUDA compile (nvrtc, .*) \([0-9.]*\) s$/\1/p' "$result" | head -1)
        stack=$(sed -n 's/.*kernels. stack: at most \([0-9]*\) bytes.*/\1/p' "$result" | head -1)
        echo "$game $name nvrtc ${nvrtc:-?} s stack ${stack:-?} B" >> "$out/builds.txt"
    done <<< "$VARIANTS"
    echo >> "$out/summary.txt"
done
cat "$out/summary.txt"
