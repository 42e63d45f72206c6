#!/usr/bin/python3
"""--gpu-state shared (templates/cuda_kernels.h): the stepping kernel keeps its
environment's copy in dynamic shared memory instead of on its stack.  Checks,
from the PTX and ptxas's report (no GPU needed), that the shared layout's
psc_run_kernel addresses the extern shared array and has a smaller stack
frame than the memory layout's, which does not declare the array at all.

    cuda_shared_state.py PSC GAME..."""
import os
import re
import subprocess
import sys
import tempfile

SHARED_ARRAY = re.compile(r"\.extern \.shared \.align \d+ \.b8 \w*psc_shared_envs\w*\[\];")


def run_kernel_ptx(ptx):
    """The body of psc_run_kernel in the PTX text."""
    start = ptx.find(".entry psc_run_kernel(")
    if start < 0:
        return ""
    end = ptx.find("\n}\n", start)
    return ptx[start:end if end >= 0 else len(ptx)]


def run_kernel_stack(report):
    """psc_run_kernel's stack frame in bytes, from ptxas's -v report."""
    lines = report.splitlines()
    for i, line in enumerate(lines):
        if "Function properties for psc_run_kernel" in line and i + 1 < len(lines):
            m = re.search(r"(\d+) bytes stack frame", lines[i + 1])
            if m:
                return int(m.group(1))
    return None


def emit(psc, game, state, cache):
    r = subprocess.run([psc, game, "--emit", "ptx", "--levels", "0", "--gpu-state", state, "--verbose"],
                       capture_output=True, text=True, timeout=300, env=dict(os.environ, XDG_CACHE_HOME=cache))
    if r.returncode != 0:
        raise SystemExit(f"FAIL: {game} --gpu-state {state}: psc exited {r.returncode}\n{r.stderr[-2000:]}")
    return r.stdout, r.stderr


def main():
    psc, games = sys.argv[1], sys.argv[2:]
    failures = []
    with tempfile.TemporaryDirectory() as cache:
        for game in games:
            name = os.path.basename(game)
            shared_ptx, shared_report = emit(psc, game, "shared", cache)
            memory_ptx, memory_report = emit(psc, game, "memory", cache)
            if not SHARED_ARRAY.search(shared_ptx):
                failures.append(f"{name}: the shared layout's PTX declares no psc_shared_envs")
            if "psc_shared_envs" not in run_kernel_ptx(shared_ptx):
                failures.append(f"{name}: the shared layout's psc_run_kernel does not use psc_shared_envs")
            if "psc_shared_envs" in memory_ptx:
                failures.append(f"{name}: the memory layout's PTX mentions psc_shared_envs")
            shared_stack, memory_stack = run_kernel_stack(shared_report), run_kernel_stack(memory_report)
            if shared_stack is None or memory_stack is None:
                failures.append(f"{name}: no stack frame for psc_run_kernel in ptxas's report")
            elif shared_stack >= memory_stack:
                failures.append(f"{name}: psc_run_kernel's stack frame is {shared_stack} bytes with the shared layout, "
                                f"{memory_stack} with the memory layout")
            else:
                print(f"{name}: psc_run_kernel stack frame {memory_stack} -> {shared_stack} bytes")
    for f in failures:
        print("FAIL:", f)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
