"""Building plugins with the psc command-line compiler, with a cache.

The psc CLI caches its own compiler runs; this module adds a cache of the
finished plugin files, so that asking again for the same game and options
costs one hash and no process at all.
"""

import hashlib
import json
import os
import shutil
import subprocess
import tempfile
from pathlib import Path
from typing import Iterable, Optional


TARGETS = ("cpu", "cuda", "all")
# The IR (win conditions, object names) travels with each plugin in this file,
# so that a plugin copied to another machine can still compute shaped rewards.
IR_SUFFIX = ".ir.json"
# The game source travels with it too: text agents (psc.TextEnv) quote its rules.
SOURCE_SUFFIX = ".source.txt"

_PACKAGE_DIR = Path(__file__).resolve().parent
_REPO_ROOT = _PACKAGE_DIR.parents[1]


def _checkout_build() -> Optional[str]:
    # Only the package in a source checkout (python/psc) uses the checkout's
    # build; an installed copy (pip install ./python) finds psc on PATH.
    if _REPO_ROOT / "python" / "psc" != _PACKAGE_DIR:
        return None
    return str(_REPO_ROOT / "build" / "cli" / "psc")


def find_psc_binary(psc_binary: Optional[str] = None) -> str:
    """The psc CLI: the argument, $PSC_BINARY, <repo>/build/cli/psc (in a source checkout), then `psc` on PATH."""
    for candidate in (psc_binary, os.environ.get("PSC_BINARY"), _checkout_build()):
        if candidate and os.path.isfile(candidate) and os.access(candidate, os.X_OK):
            return candidate
    on_path = shutil.which("psc")
    if on_path:
        return on_path
    raise FileNotFoundError(
        "cannot find the psc compiler: pass psc_binary=, set PSC_BINARY, build it in <repo>/build, or put psc on PATH"
    )


def compiler_version(psc_binary: Optional[str] = None) -> str:
    """`psc --version` of the compiler find_psc_binary finds: its version, and whether it can build CUDA plugins."""
    return _run([find_psc_binary(psc_binary), "--version"], "asking psc its version").strip()


def cache_dir() -> Path:
    """$PSC_PYTHON_CACHE, else $XDG_CACHE_HOME/psc-python, else ~/.cache/psc-python."""
    explicit = os.environ.get("PSC_PYTHON_CACHE")
    if explicit:
        return Path(explicit)
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "psc-python"


def ir_path_for(plugin_path: str) -> str:
    """Where compile() puts the IR of a plugin: beside it, .so replaced by .ir.json."""
    root, ext = os.path.splitext(plugin_path)
    return (root if ext == ".so" else plugin_path) + IR_SUFFIX


def source_path_for(plugin_path: str) -> str:
    """Where compile() puts the game source of a plugin: beside it, .so replaced by .source.txt."""
    root, ext = os.path.splitext(plugin_path)
    return (root if ext == ".so" else plugin_path) + SOURCE_SUFFIX


class CompileError(RuntimeError):
    """The psc compiler refused the game; the message holds its diagnostics."""


def _run(command: list, what: str) -> str:
    done = subprocess.run(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if done.returncode != 0:
        raise CompileError(f"{what} failed ({' '.join(command)}):\n{done.stderr.strip()}")
    return done.stdout


def _binary_identity(binary: str) -> str:
    # A rebuilt psc may generate different code: its path, size and mtime go into the cache key.
    stat = os.stat(binary)
    return f"{os.path.abspath(binary)}:{stat.st_size}:{stat.st_mtime_ns}"


def _write_atomically(directory: Path, name: str, write) -> Path:
    # Write beside the final name and rename, so that concurrent builds never see half a file.
    directory.mkdir(parents=True, exist_ok=True)
    final = directory / name
    handle, temporary = tempfile.mkstemp(dir=directory, prefix=".tmp-")
    os.close(handle)
    try:
        write(temporary)
        os.replace(temporary, final)
    finally:
        if os.path.exists(temporary):
            os.unlink(temporary)
    return final


def emit_ir(game_path: str, psc_binary: Optional[str] = None, keep_going: bool = False) -> dict:
    """The game's IR as `psc GAME --emit ir --format json` prints it (cached)."""
    binary = find_psc_binary(psc_binary)
    text = Path(game_path).read_bytes()
    key = hashlib.sha1(text + f"\0ir\0{keep_going}\0{_binary_identity(binary)}".encode()).hexdigest()
    cached = cache_dir() / f"{key}{IR_SUFFIX}"
    if not cached.exists():
        command = [binary, str(game_path), "--emit", "ir", "--format", "json"] + (
            ["--keep-going"] if keep_going else []
        )
        output = _run(command, "emitting the IR")
        _write_atomically(cache_dir(), cached.name, lambda p: Path(p).write_text(output))
    return json.loads(cached.read_text())


def compile(
    game_path: str,
    levels: Optional[Iterable[int]] = None,
    target: str = "cpu",
    psc_binary: Optional[str] = None,
    keep_going: bool = False,
) -> str:
    """Builds the plugin of a game and returns its path (in the cache).

    levels: playable levels to build (numbered from 0), None for all; fewer
    levels give smaller boards and faster steps.  target: "cpu", "cuda" or
    "all" (CUDA and CPU).  The game's IR is written beside the plugin
    (ir_path_for) for shaped rewards, and the source (source_path_for) for
    text agents.
    """
    if target not in TARGETS:
        raise ValueError(f"target must be one of {TARGETS}, not {target!r}")
    binary = find_psc_binary(psc_binary)
    text = Path(game_path).read_bytes()
    level_list = None if levels is None else sorted(set(int(level) for level in levels))
    options = json.dumps(
        {"levels": level_list, "target": target, "keep_going": keep_going, "psc": _binary_identity(binary)}
    )
    key = hashlib.sha1(text + b"\0" + options.encode()).hexdigest()
    plugin = cache_dir() / f"{Path(game_path).stem}-{key}.so"
    if not plugin.exists():
        extra = ["--target", target]
        if level_list is not None:
            extra += ["--levels", ",".join(str(level) for level in level_list)]
        if keep_going:
            extra.append("--keep-going")
        ir = emit_ir(game_path, binary, keep_going)
        _write_atomically(
            cache_dir(), Path(ir_path_for(str(plugin))).name, lambda p: Path(p).write_text(json.dumps(ir))
        )
        _write_atomically(
            cache_dir(), plugin.name, lambda p: _run([binary, str(game_path), "-o", p] + extra, "building the plugin")
        )
    source = Path(source_path_for(str(plugin)))
    if not source.exists():  # also for plugins cached before sources were kept
        _write_atomically(cache_dir(), source.name, lambda p: Path(p).write_bytes(text))
    return str(plugin)
