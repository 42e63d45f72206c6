#!/usr/bin/python3
"""Register caps of the GPU code (codegen/CppSource.cpp, PSC_UNIT_MAX_REGISTERS):
the memory layout over boards too large to unroll (more than 8 words) is
compiled at 80 registers a thread, in every compile unit and as one program,
by NVRTC and by nvcc; the memory layout over boards that unroll has no cap.
Every entry kernel ptxas compiles must report the cap (no GPU needed).

    cuda_register_caps.py PSC GAME

GAME's own levels must be small (at most 8 words a board); the test gives it a
level of 24 x 30 cells (12 words) instead."""
import os
import re
import shutil
import subprocess
import sys
import tempfile

from cuda_large_levels import walled_level, with_level

CAP = 80
ENTRIES = {"psc_run_kernel", "psc_reset_kernel", "psc_observe_kernel"}


def build(psc, game, options, cache):
    """(the CUDA source's cap, the compile's --verbose output) of one build."""
    source = subprocess.run([psc, game, "--emit", "cuda"] + options, capture_output=True, text=True, timeout=120)
    cap = re.search(r"^#define PSC_UNIT_MAX_REGISTERS (\d+)", source.stdout, re.M)
    ptx = subprocess.run([psc, game, "--emit", "ptx", "--verbose"] + options, capture_output=True, text=True, timeout=600,
                         env=dict(os.environ, XDG_CACHE_HOME=cache))
    if source.returncode != 0 or ptx.returncode != 0 or not cap:
        return None, source.stderr[-800:] + ptx.stderr[-800:]
    return int(cap.group(1)), ptx.stderr


def check(psc, game, options, expected, failures, cache):
    what = f"{os.path.basename(game)} {' '.join(options)}".strip()
    cap, log = build(psc, game, options, cache)
    if cap is None:
        failures.append(f"{what}: the build failed: {log}")
        return
    if cap != expected:
        failures.append(f"{what}: PSC_UNIT_MAX_REGISTERS {cap}, expected {expected}")
    flags = re.findall(r"-maxrregcount=(\d+)", log)
    overrides = re.findall(r"Overriding maximum register limit \d+ for '(\w+)' with\s+(\d+)", log)
    capped = {entry for entry, registers in overrides if int(registers) == expected}
    if expected:
        if not flags or any(int(f) != expected for f in flags):
            failures.append(f"{what}: compiler options {flags}, expected -maxrregcount={expected}")
        if not ENTRIES <= capped or len(capped) != len({e for e, _ in overrides}):
            failures.append(f"{what}: ptxas capped {sorted(overrides)}, expected every entry at {expected}")
    elif flags or overrides:
        failures.append(f"{what}: capped at {flags} {overrides}, expected no cap")
    print(f"{what}: cap {cap}, ptxas capped {len(overrides)} entry kernels")


def main():
    psc, game = sys.argv[1], sys.argv[2]
    failures = []
    with tempfile.TemporaryDirectory() as work:
        large = os.path.join(work, "large.txt")
        with open(large, "w") as f:
            f.write(with_level(open(game).read(), walled_level(24, 30, "P")))
        cache = os.path.join(work, "cache")
        check(psc, large, [], CAP, failures, cache)
        check(psc, large, ["--cuda-units", "1"], CAP, failures, cache)
        if shutil.which("nvcc") or os.path.exists("/usr/local/cuda/bin/nvcc"):
            check(psc, large, ["--compiler", "nvcc"], CAP, failures, cache)
        else:
            failures.append("nvcc not found: the nvcc build's cap is not checked")
        check(psc, game, ["--gpu-state", "memory"], 0, failures, cache)
    for f in failures:
        print("FAIL", f)
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
