#!/usr/bin/env bash
# CPU steps/s of the 13 benchmark games (bench/games, made by
# bench/extract_games.py): level 0, one environment, one thread, random
# actions with auto-reset, next to the reference JS engine's steps/s on this
# kind of machine and the 10x bar (issue 3).  Prints a markdown table.
#   bench/cpu_bench.sh [psc]
set -euo pipefail
cd "$(dirname "$0")/.."
psc=${1:-build/cli/psc}
declare -A js=([sokoban]=160000 [traveling]=156000 [notsnake]=134000 [match3]=111000 [slidings]=107000
               [dictionary]=101000 [takeheart]=70000 [zenpuzzle]=64000 [blocks]=64000 [constellationz]=46000
               [limerick]=37000 [kettle]=35000 [atlas]=26000)
echo "| game | psc CPU steps/s (batch 1, 1 thread) | JS engine steps/s | ratio |"
echo "|---|---:|---:|---:|"
for name in sokoban traveling notsnake match3 slidings dictionary takeheart zenpuzzle blocks constellationz limerick kettle atlas; do
    rate=$("$psc" bench "bench/games/$name.txt" --level 0 --batch 1 --threads 1 --backend cpu --repeats 5 --warmup 1 2>/dev/null |
           sed -n 's/^steps\/s: //p')
    awk -v n="$name" -v r="${rate:-0}" -v j="${js[$name]}" 'BEGIN { printf "| %s | %.0f | %d | %.1fx |\n", n, r, j, r / j }'
done
