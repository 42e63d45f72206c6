#!/usr/bin/env bash
# NVRTC compile time of each benchmark game's CUDA code (level 0), per GPU
# state layout.  Usage: tools/cuda_compile_times.sh [psc] [layouts...]
set -euo pipefail
cd "$(dirname "$0")/.."
psc=${1:-build/cli/psc}
shift || true
layouts=${*:-auto registers memory}
printf '%-16s' game; for l in $layouts; do printf '%12s' "$l"; done; echo
for game in bench/games/*.txt; do
    printf '%-16s' "$(basename "$game" .txt)"
    for l in $layouts; do
        cache=$(mktemp -d)
        t=$(XDG_CACHE_HOME=$cache timeout 900 "$psc" "$game" --emit ptx --levels 0 --gpu-state "$l" 2>&1 >/dev/null |
            sed -n 's/.*CUDA compile (nvrtc) \([0-9.]*\) s.*/\1/p')
        rm -rf "$cache"
        printf '%12s' "${t:-fail}"
    done
    echo
done
