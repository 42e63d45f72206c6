"""psc's compilers never outlive it and never run unbounded.

Usage: compiler_processes.py PSC GAME

While psc builds GAME's CPU plugin, psc is killed (SIGTERM, SIGINT, SIGKILL):
every process it started (the compiler driver and what that started) must be
gone within a few seconds.  A compiler over the time limit
(PSC_COMPILE_TIMEOUT) or the memory limit (PSC_COMPILE_MEMORY_MB) is stopped
with an error that names the limit.  Most cases use a stand-in compiler (a
script that starts a child and sleeps), one the real C++ compiler.  Where psc
has NVRTC, which runs in a forked copy of psc, the same holds for it: a kill
leaves no copy behind, and PSC_COMPILE_TIMEOUT stops it."""
import os
import signal
import stat
import subprocess
import sys
import tempfile
import time

PSC, GAME = sys.argv[1], sys.argv[2]
FAILURES = []

SLOW_COMPILER = """#!/bin/sh
# A compiler that never finishes, with a child of its own (as c++ has cc1plus).
sleep 1000 &
wait
"""


def check(ok, what):
    print(f"{'ok  ' if ok else 'FAIL'} {what}")
    if not ok:
        FAILURES.append(what)


def processes():
    """{pid: (ppid, state, command)} of every process."""
    out = {}
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            with open(f"/proc/{entry}/stat") as f:
                text = f.read()
            with open(f"/proc/{entry}/cmdline", "rb") as f:
                command = f.read().replace(b"\0", b" ").decode("utf-8", "replace")
        except OSError:
            continue
        fields = text[text.rindex(")") + 2:].split()
        out[int(entry)] = (int(fields[1]), fields[0], command)
    return out


def descendants(pid):
    table = processes()
    found, frontier = set(), {pid}
    while frontier:
        frontier = {p for p, (ppid, _, _) in table.items() if ppid in frontier} - found
        found |= frontier
    return found


def alive(pids):
    """Those of pids still running (zombies waiting for a reaper count as gone)."""
    table = processes()
    return {p for p in pids if p in table and table[p][1] != "Z"}


def start_build(env, tmp):
    return subprocess.Popen([PSC, GAME, "-o", os.path.join(tmp, "game.so"), "--target", "cpu"], env=env,
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)


def wait_for(predicate, seconds):
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        value = predicate()
        if value:
            return value
        time.sleep(0.05)
    return predicate()


def killed_build(name, env, tmp, sig, marker):
    """Starts a build, waits until a process whose command has `marker` runs
    under psc, sends psc `sig`, and checks that all psc started is gone."""
    psc = start_build(env, tmp)
    started = wait_for(lambda: {p for p in descendants(psc.pid) if marker in processes().get(p, (0, "", ""))[2]}, 60)
    children = descendants(psc.pid)
    check(bool(started), f"{name}: the compiler ({marker}) started under psc")
    psc.send_signal(sig)
    psc.wait(timeout=30)
    left = wait_for(lambda: not alive(children), 5) or alive(children)
    check(left is True, f"{name}: psc's {len(children)} processes are gone after {signal.Signals(sig).name}"
          + ("" if left is True else f" (still running: {sorted(left)})"))


def nvrtc_cases(tmp):
    env = dict(os.environ, PSC_CACHE_DIR=os.path.join(tmp, "cache-nvrtc"))
    env.pop("CXX", None)
    start = time.monotonic()
    r = subprocess.run([PSC, GAME, "-o", os.path.join(tmp, "game-cuda.so"), "--target", "cuda"],
                       env=dict(env, PSC_COMPILE_TIMEOUT="0.2"), capture_output=True, text=True, timeout=120)
    seconds = time.monotonic() - start
    check(r.returncode != 0 and "NVRTC stopped at the compile time limit of 0.2 s" in r.stderr and seconds < 10,
          f"NVRTC over PSC_COMPILE_TIMEOUT=0.2 is stopped with an error naming the limit ({seconds:.1f} s)"
          + ("" if "NVRTC stopped" in r.stderr else f": {r.stderr[-300:]}"))
    # A kill while NVRTC compiles: its forked copy of psc goes too.
    psc = subprocess.Popen([PSC, GAME, "-o", os.path.join(tmp, "game-cuda.so"), "--target", "cuda"], env=env,
                           stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    forked = wait_for(lambda: descendants(psc.pid), 60)
    check(bool(forked), "NVRTC's forked copy of psc runs under psc")
    psc.send_signal(signal.SIGTERM)
    psc.wait(timeout=30)
    left = wait_for(lambda: not alive(forked), 5) or alive(forked)
    check(left is True, "NVRTC's forked copy is gone after SIGTERM" + ("" if left is True else f" (still running: {sorted(left)})"))


def main():
    with tempfile.TemporaryDirectory() as tmp:
        slow = os.path.join(tmp, "slow-compiler")
        with open(slow, "w") as f:
            f.write(SLOW_COMPILER)
        os.chmod(slow, stat.S_IRWXU)
        env = dict(os.environ, PSC_CACHE_DIR=os.path.join(tmp, "cache"), CXX=slow)
        for sig in (signal.SIGTERM, signal.SIGINT, signal.SIGKILL):
            killed_build("stand-in compiler", env, tmp, sig, "sleep 1000")

        start = time.monotonic()
        r = subprocess.run([PSC, GAME, "-o", os.path.join(tmp, "game.so"), "--target", "cpu"],
                           env=dict(env, PSC_COMPILE_TIMEOUT="1"), capture_output=True, text=True, timeout=60)
        seconds = time.monotonic() - start
        check(r.returncode != 0 and "time limit of 1 s" in r.stderr and "PSC_COMPILE_TIMEOUT" in r.stderr and seconds < 10,
              f"a compiler over PSC_COMPILE_TIMEOUT=1 is stopped with an error naming the limit ({seconds:.1f} s)")
        leftover = [p for p, (_, state, command) in processes().items() if state != "Z" and slow in command]
        check(not leftover, "nothing of the stopped compiler is left")

        real = dict(os.environ, PSC_CACHE_DIR=os.path.join(tmp, "cache-real"))
        real.pop("CXX", None)
        killed_build("real compiler", real, tmp, signal.SIGTERM, "cc1plus")

        r = subprocess.run([PSC, GAME, "-o", os.path.join(tmp, "game.so"), "--target", "cpu"],
                           env=dict(real, PSC_COMPILE_MEMORY_MB="64"), capture_output=True, text=True, timeout=300)
        check(r.returncode != 0 and "memory limit of 64 MB" in r.stderr and "PSC_COMPILE_MEMORY_MB" in r.stderr,
              "a compiler over PSC_COMPILE_MEMORY_MB=64 fails with an error naming the limit")
        if "NVRTC available" in subprocess.run([PSC, "--version"], capture_output=True, text=True).stdout:
            nvrtc_cases(tmp)
    print(f"{len(FAILURES)} failure(s)")
    return 1 if FAILURES else 0


if __name__ == "__main__":
    sys.exit(main())
