#!/usr/bin/env bash
# NVRTC compile time of each benchmark game's CUDA code (level 0), one fresh
# compile per column; a column is a GPU state layout and a --fast-compile
# level, LAYOUT/LEVEL.  Run it on an otherwise idle machine.
#   tools/cuda_compile_times.sh [psc] [columns...]   (default: auto/0 auto/min auto/mid)
set -euo pipefail
cd "$(dirname "$0")/.."
psc=${1:-build/cli/psc}
shift || true
columns=${*:-auto/0 auto/min auto/mid}
printf '%-16s' game; for c in $columns; do printf '%14s' "$c"; done; echo
for game in bench/games/*.txt; do
    printf '%-16s' "$(basename "$game" .txt)"
    for c in $columns; do
        cache=$(mktemp -d)
        t=$(XDG_CACHE_HOME=$cache timeout 900 "$psc" "$game" --emit ptx --levels 0 --gpu-state "${c%/*}" \
            --fast-compile "${c#*/}" 2>&1 >/dev/null | sed -n 's/.*CUDA compile (nvrtc[^)]*) \([0-9.]*\) s.*/\1/p')
        rm -rf "$cache"
        printf '%14s' "${t:-fail}"
    done
    echo
done
