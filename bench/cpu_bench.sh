#!/usr/bin/env bash
# CPU steps/s of the 13 benchmark games (bench/games, made by
# bench/extract_games.py): level 0, one environment, one thread, random
# actions with auto-reset, next to the reference JS engine's steps/s on this
# kind of machine and the 10x bar (issue 3).  Prints a markdown table.
#   bench/cpu_bench.sh [psc]
# Two builds side by side, game by game (each game's two runs back to back, so
# that the machine's drift falls on both), RUNS times: DIR/cpu_bench_NAME_i.md
# for each build, the tables tools/performance_report.py's --cpu-before and
# --cpu-after read.
#   bench/cpu_bench.sh --pairs RUNS DIR OLD_PSC:OLD_NAME NEW_PSC:NEW_NAME
# GAMES (names, space-separated) limits either form to some games.
set -euo pipefail
cd "$(dirname "$0")/.."
declare -A js=([sokoban]=160000 [traveling]=156000 [notsnake]=134000 [match3]=111000 [slidings]=107000
               [dictionary]=101000 [takeheart]=70000 [zenpuzzle]=64000 [blocks]=64000 [constellationz]=46000
               [limerick]=37000 [kettle]=35000 [atlas]=26000)
games=${GAMES:-"sokoban traveling notsnake match3 slidings dictionary takeheart zenpuzzle blocks constellationz limerick kettle atlas"}
header='| game | psc CPU steps/s (batch 1, 1 thread) | JS engine steps/s | ratio |\n|---|---:|---:|---:|\n'

row() {  # row PSC GAME
    local rate
    rate=$("$1" bench "bench/games/$2.txt" --level 0 --batch 1 --threads 1 --backend cpu --repeats 5 --warmup 1 2>/dev/null |
           sed -n 's/^steps\/s: //p')
    awk -v n="$2" -v r="${rate:-0}" -v j="${js[$2]}" 'BEGIN { printf "| %s | %.0f | %d | %.1fx |\n", n, r, j, r / j }'
}

if [ "${1:-}" = --pairs ]; then
    if [ $# -ne 5 ] || [[ ! $2 =~ ^[1-9][0-9]*$ ]] || [[ $4 != *:* ]] || [[ $5 != *:* ]]; then
        echo "usage: bench/cpu_bench.sh --pairs RUNS DIR OLD_PSC:OLD_NAME NEW_PSC:NEW_NAME" >&2
        exit 2
    fi
    runs=$2 dir=$3
    mkdir -p "$dir"
    for i in $(seq "$runs"); do
        for build in "$4" "$5"; do printf "$header" > "$dir/cpu_bench_${build#*:}_$i.md"; done
        for name in $games; do
            for build in "$4" "$5"; do row "${build%%:*}" "$name" >> "$dir/cpu_bench_${build#*:}_$i.md"; done
        done
        echo "run $i of $runs done" >&2
    done
    exit 0
fi

psc=${1:-build/cli/psc}
printf "$header"
for name in $games; do row "$psc" "$name"; done
