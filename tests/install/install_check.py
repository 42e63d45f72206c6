#!/usr/bin/python3
"""psc as users install it: `cmake --install` into a temporary prefix, and the
Debian package (cpack -G DEB) unpacked with `dpkg -x`.  For each, from a copy
of the prefix in another place and a copy of the game (nothing under the
source or build tree):

  - the installed psc names no source or build path, reports its version and
    whether NVRTC loads, checks games/sokoban.txt and builds it into a plugin
    (default target: CUDA too when NVRTC is there) in an empty plugin cache;
  - examples/cpp builds with find_package(psc) against the prefix, loads the
    plugin, steps it and reads observations (on CUDA too where a GPU is);
  - the Python package installed with Debian's pip (pip install ./python, in
    a venv that sees Debian's numpy and setuptools, no index) finds that psc
    on PATH, says so in `python3 -m psc --version`, and steps a VectorEnv;
  - and, once, without the NVRTC module (as on a machine without the CUDA
    Toolkit): psc still starts and builds CPU plugins.

    install_check.py --source SRC --build BUILD --cmake CMAKE --cpack CPACK [--cuda]
    (--cuda: the build has the NVRTC module, so the installed psc must load it)"""
import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

PYTHON = "/usr/bin/python3"  # Debian's, with its pip, setuptools and numpy
GAME = "games/sokoban.txt"


class Failure(Exception):
    pass


def run(command, what, cwd=None, env=None, timeout=300):
    done = subprocess.run([str(c) for c in command], cwd=cwd, env=env, capture_output=True, text=True, timeout=timeout)
    if done.returncode != 0:
        output = done.stdout[-2000:] + done.stderr[-3000:]
        raise Failure(f"{what} exited {done.returncode}: {' '.join(map(str, command))}\n{output}")
    return done.stdout


def expect(condition, message):
    if not condition:
        raise Failure(message)


def relocated(prefix, work):
    """A copy of the installed tree in another folder; the original is removed."""
    moved = work / "prefix"
    shutil.copytree(prefix, moved, symlinks=True)
    shutil.rmtree(prefix)
    return moved


def check_no_tree_paths(prefix, trees):
    """Nothing installed that psc reads at run time names the source or build tree."""
    stripped = prefix.parent / "stripped"
    for path in sorted(p for p in prefix.rglob("*") if p.is_file()):
        data = path.read_bytes()
        if data.startswith(b"\x7fELF") and path.suffix != ".a":
            # Debug sections name the sources they were built from; the code does not need them.
            run(["strip", "-o", stripped, path], f"strip {path.name}")
            data = stripped.read_bytes()
        elif path.suffix == ".a":
            continue  # linked into the user's program with its debug information, never read by psc
        for tree in trees:
            expect(str(tree).encode() not in data, f"{path.relative_to(prefix)} names {tree}")
    stripped.unlink(missing_ok=True)


def check_psc(prefix, work, cuda):
    psc = prefix / "bin" / "psc"
    version = run([psc, "--version"], "psc --version")
    expect(re.match(r"psc \d+\.\d+\.\d+\n", version), f"psc --version printed {version!r}")
    if cuda:
        expect("CUDA plugins: NVRTC available" in version, f"the installed psc cannot load NVRTC:\n{version}")
    game = work / Path(GAME).name
    run([psc, "check", game.name], "psc check", cwd=work)
    env = dict(os.environ, PSC_CACHE_DIR=str(work / "psc-cache"))  # empty: the plugin is really built
    run([psc, game.name, "-o", "sokoban.so"], "psc building the plugin", cwd=work, env=env)
    expect((work / "sokoban.so").read_bytes()[:4] == b"\x7fELF", "psc wrote no plugin")
    print(f"  psc: {version.splitlines()[0]}, built {GAME} into a plugin")


def check_cpp_example(prefix, source, work, cmake):
    build = work / "example"
    run([cmake, "-S", source / "examples" / "cpp", "-B", build, "-G", "Ninja", f"-DCMAKE_PREFIX_PATH={prefix}"],
        "configuring examples/cpp", cwd=work)
    run([cmake, "--build", build], "building examples/cpp", cwd=work)
    out = run([build / "rollout", "sokoban.so", "8", "50"], "examples/cpp rollout", cwd=work)
    cpu = re.search(r"^cpu: 8 envs x 50 steps, \d+ wins, (\d+) object cells observed$", out, re.M)
    expect(cpu and int(cpu.group(1)) > 0, f"examples/cpp stepped no CPU batch:\n{out}")
    cuda = re.search(r"^cuda: .*$", out, re.M)
    expect(cuda, f"examples/cpp said nothing about CUDA:\n{out}")
    print(f"  examples/cpp: {cpu.group(0)}; {cuda.group(0)}")


def check_python(prefix, python_source, work):
    venv = work / "venv"
    run([PYTHON, "-m", "venv", "--without-pip", "--system-site-packages", venv], "creating a venv")
    python = venv / "bin" / "python"
    run([python, "-m", "pip", "install", "--no-build-isolation", "--no-index", python_source], "pip install ./python")
    env = {k: v for k, v in os.environ.items() if k not in ("PSC_BINARY", "PYTHONPATH")}
    env.update(PATH=f"{prefix / 'bin'}{os.pathsep}{os.environ.get('PATH', '')}",
               PSC_PYTHON_CACHE=str(work / "python-cache"), PSC_CACHE_DIR=str(work / "psc-cache"))
    version = run([python, "-m", "psc", "--version"], "python3 -m psc --version", cwd=work, env=env)
    expect(f"psc compiler: {prefix / 'bin' / 'psc'}\n" in version, f"the Python package uses another psc:\n{version}")
    expect(str(venv) in version.splitlines()[0], f"python3 -m psc ran another copy of the package:\n{version}")
    script = """
import numpy as np, psc
env = psc.VectorEnv("sokoban.txt", 4, levels=0, seed=0, max_episode_steps=50)
obs, info = env.reset(seed=0)
first = obs.copy()
for _ in range(20):
    obs, reward, terminated, truncated, info = env.step(np.full(4, 3, dtype=np.int32))
assert obs.shape == first.shape and obs.any() and not np.array_equal(obs, first), "the environments did not move"
print(obs.shape)
env.close()
"""
    shape = run([python, "-c", script], "stepping psc.VectorEnv", cwd=work, env=env).strip()
    print(f"  python: pip-installed psc.VectorEnv stepped, observations {shape}")


def check_without_cuda(prefix, work):
    """Where the CUDA Toolkit's libraries cannot be loaded (the module gone stands in for them), psc
    still starts, says why it builds no CUDA code, and builds CPU plugins by default."""
    (prefix / "lib" / "psc" / "libpsc_nvrtc.so").unlink(missing_ok=True)
    psc = prefix / "bin" / "psc"
    version = run([psc, "--version"], "psc --version without NVRTC")
    cuda = version.splitlines()[1]
    expect(cuda.startswith("CUDA plugins: ") and "NVRTC available" not in cuda, f"psc --version printed {version!r}")
    env = dict(os.environ, PSC_CACHE_DIR=str(work / "psc-cache"))
    run([psc, "sokoban.txt", "-o", "sokoban-cpu.so"], "psc building a plugin without NVRTC", cwd=work, env=env)
    out = run([work / "example" / "rollout", "sokoban-cpu.so", "2", "5"], "examples/cpp without NVRTC", cwd=work)
    expect("cuda: not built into this plugin" in out, f"the plugin built without NVRTC has CUDA code:\n{out}")
    print(f"  without NVRTC: {cuda}; CPU plugin built and stepped")


def check_prefix(label, prefix, args, python_source, work):
    print(f"{label}: {prefix}")
    shutil.copy(args.source / GAME, work)
    check_no_tree_paths(prefix, [args.source, args.build])
    check_psc(prefix, work, args.cuda)
    check_cpp_example(prefix, args.source, work, args.cmake)
    check_python(prefix, python_source, work)


def deb_package(args, tmp):
    out = tmp / "deb"
    run([args.cpack, "-G", "DEB", "--config", args.build / "CPackConfig.cmake", "-B", out], "cpack -G DEB",
        cwd=args.build)
    debs = sorted(out.glob("*.deb"))
    expect(len(debs) == 1, f"cpack made {[d.name for d in debs]}")
    depends = run(["dpkg-deb", "-f", debs[0], "Depends"], "dpkg-deb -f").strip()
    for package in ("libc6", "libstdc++6", "libfmt", "libantlr4-runtime", "g++"):
        expect(re.search(rf"(^|, ){re.escape(package)}", depends), f"{debs[0].name} lacks {package}: {depends}")
    root = tmp / "deb-root"
    run(["dpkg", "-x", debs[0], root], "dpkg -x")
    print(f"{debs[0].name}: Depends: {depends}")
    return root / "usr"


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--source", type=Path, required=True)
    parser.add_argument("--build", type=Path, required=True)
    parser.add_argument("--cmake", required=True)
    parser.add_argument("--cpack", required=True)
    parser.add_argument("--cuda", action="store_true")
    args = parser.parse_args()
    args.source, args.build = args.source.resolve(), args.build.resolve()
    with tempfile.TemporaryDirectory(prefix="psc-install-") as name:
        tmp = Path(name)
        # pip builds in the folder it is given: a copy keeps the source tree clean.
        python_source = tmp / "python-source"
        shutil.copytree(args.source / "python" / "psc", python_source / "psc",
                        ignore=shutil.ignore_patterns("__pycache__"))
        shutil.copy(args.source / "python" / "pyproject.toml", python_source)
        try:
            run([args.cmake, "--install", args.build, "--prefix", tmp / "staging"], "cmake --install")
            work = tmp / "installed"
            work.mkdir()
            check_prefix("cmake --install", relocated(tmp / "staging", work), args, python_source, work)
            deb_prefix = deb_package(args, tmp)
            work = tmp / "debian"
            work.mkdir()
            prefix = relocated(deb_prefix, work)
            check_prefix("dpkg -x", prefix, args, python_source, work)
            check_without_cuda(prefix, work)
        except (Failure, subprocess.TimeoutExpired) as failure:
            print(f"FAIL: {failure}")
            return 1
    print("PASS")
    return 0


if __name__ == "__main__":
    sys.exit(main())
