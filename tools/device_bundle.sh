#!/usr/bin/env bash
# Gathers what the GPU checks need on the device machine into device/ (git-ignored;
# name it in the device call's `carry`): psc installed (bin/psc, and the NVRTC
# module it loads from lib/psc), the shared libraries it needs that the device
# image lacks, and the corpus cases to replay
# (every testsuite trace and a spread sample of scraped traces), compressed.
# INCLUDE_IDS (a file of case ids) adds those cases to the sample.
# With FUZZ=1, also the fuzz targets of build-fuzz (stripped, and compressed:
# a device call carries at most 64 MiB with the working tree) and their seed
# games, for gpu_check.sh's fuzz stage.
#   tools/device_bundle.sh [SCRAPED_SAMPLE]      (default 400)
set -euo pipefail
cd "$(dirname "$0")/.."
sample=${1:-400}
corpus=../shared/corpus
rm -rf device && mkdir -p device/lib
cmake --install build --prefix device --strip > /dev/null
git describe --always --dirty > device/COMMIT
for lib in libantlr4-runtime.so.4.9 libfmt.so.9; do cp "$(ldconfig -p | awk -v l=$lib '$1 == l {print $NF; exit}')" device/lib/; done
stage=$(mktemp -d)
/usr/bin/python3 - "$corpus" "$stage" "$sample" "${INCLUDE_IDS:-}" <<'PY'
import json, os, shutil, sys
sys.path.insert(0, "tools")
corpus, stage, sample = sys.argv[1], sys.argv[2], int(sys.argv[3])
included = set(open(sys.argv[4]).read().split()) if sys.argv[4] else set()
index = json.load(open(os.path.join(corpus, "INDEX.json")))
traces = [e for e in index if e["kind"] == "trace"]
from corpus_replay import sample_cases
chosen = [e for e in traces if e["suite"] == "testsuite"]
chosen += sample_cases([e for e in traces if e["suite"] == "scraped"], sample)
chosen += [e for e in traces if e["id"] in included and e not in chosen]
for e in chosen:
    os.makedirs(os.path.dirname(os.path.join(stage, e["path"])), exist_ok=True)
    shutil.copy(os.path.join(corpus, e["path"]), os.path.join(stage, e["path"]))
json.dump(chosen, open(os.path.join(stage, "INDEX.json"), "w"))
print(f"{len(chosen)} cases")
PY
tar -cJf device/corpus.tar.xz -C "$stage" .
rm -rf "$stage"
if [ "${FUZZ:-0}" = 1 ]; then
    targets=$(mktemp -d)
    mkdir -p "$targets/build-fuzz/fuzz"
    for target in build-fuzz/fuzz/psc-fuzz-*; do strip -o "$targets/$target" "$target"; done
    tar -cJf device/build-fuzz.tar.xz -C "$targets" build-fuzz
    rm -rf "$targets"
    seeds=$(mktemp -d)
    /usr/bin/python3 fuzz/seed_corpus.py "$corpus" "$seeds" > /dev/null
    tar -cJf device/fuzz-seeds.tar.xz -C "$seeds" .
    rm -rf "$seeds"
fi
du -sh device
