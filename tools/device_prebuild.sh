#!/usr/bin/env bash
# Compiles here, without a GPU, the CUDA code of the carried corpus cases named
# in IDS_FILE, and packs it as device/cache.tar.xz, which tools/gpu_check.sh
# unpacks into psc's cache: a device call then spends its time replaying, not
# compiling.  Run tools/device_bundle.sh first: the carried psc and the corpus
# path used here (/tmp/psc-corpus, as on the device) make the generated
# sources, and so the cache keys, the same there.  Each replay stops after the
# build here (no CUDA driver); the compiled code stays in the cache.
# A device call carries at most 64 MiB: the largest rule sets do not fit (at
# --fast-compile max, 23 of the slowest testsuite games came to 2 GB of PTX
# and cubin), so this is for games of middling size; give the largest the
# device's cores instead (REPLAY_JOBS in tools/gpu_check.sh).
#   tools/device_prebuild.sh IDS_FILE [FAST_COMPILE]      (JOBS: parallel builds)
set -euo pipefail
cd "$(dirname "$0")/.."
ids=$1
fast=${2:-0}
corpus=/tmp/psc-corpus
cache=$PWD/device/cache
rm -rf "$corpus" && mkdir -p "$corpus" && tar -xJf device/corpus.tar.xz -C "$corpus"
export LD_LIBRARY_PATH=$PWD/device/lib:${LD_LIBRARY_PATH:-}
/usr/bin/python3 tools/corpus_replay.py --corpus "$corpus" --suite all --ids-file "$ids" --list | xargs -P "${JOBS:-2}" -I{} sh -c \
    'XDG_CACHE_HOME="$0" timeout 1800 device/bin/psc replay "$1" --backend cuda --fast-compile "$2" --verbose 2>&1 | grep -c "CUDA compile\|CUDA code from the cache" >/dev/null && echo "built $1" || echo "FAILED $1"' \
    "$cache" {} "$fast"
(cd "$cache" && tar -cJf ../cache.tar.xz psc/*.cubin psc/*.ptx psc/*.ptxas.log)
du -sh device/cache.tar.xz
