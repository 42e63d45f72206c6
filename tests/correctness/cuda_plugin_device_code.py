#!/usr/bin/python3
"""A CUDA plugin carries its game's device code: the cubin and the PTX of
every compile unit, each followed by a NUL byte, the same bytes that psc
compiled (`--emit ptx`, the cache), in symbols the plugin does not export; and
its CPU backend loads and answers without a GPU.

    cuda_plugin_device_code.py PSC GAME [--cuda-units N]"""
import argparse
import ctypes
import glob
import os
import re
import subprocess
import sys
import tempfile


def symbol_bytes(plugin, symbol, size):
    """`size` bytes of the plugin file at `symbol` (nm address, mapped to a file offset)."""
    address = None
    for line in subprocess.run(["nm", plugin], capture_output=True, text=True, check=True).stdout.splitlines():
        parts = line.split()
        if len(parts) == 3 and parts[2] == symbol:
            address = int(parts[0], 16)
    if address is None:
        raise SystemExit(f"FAIL: {plugin} has no symbol {symbol}")
    for line in subprocess.run(["readelf", "-SW", plugin], capture_output=True, text=True, check=True).stdout.splitlines():
        parts = line.replace("[ ", "[").split()
        if len(parts) > 5 and parts[1].startswith(".") and all(c in "0123456789abcdef" for c in parts[3] + parts[4] + parts[5]):
            start, offset, length = int(parts[3], 16), int(parts[4], 16), int(parts[5], 16)
            if parts[2] != "NOBITS" and start <= address < start + length:
                with open(plugin, "rb") as f:
                    f.seek(address - start + offset)
                    return f.read(size)
    raise SystemExit(f"FAIL: {symbol} is in no section of {plugin}")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("psc")
    ap.add_argument("game")
    ap.add_argument("--cuda-units", default="0")
    a = ap.parse_args()
    failures = []
    with tempfile.TemporaryDirectory() as tmp:
        env = dict(os.environ, XDG_CACHE_HOME=tmp)
        options = ["--levels", "0", "--gpu-state", "memory", "--cuda-units", a.cuda_units]
        plugin = os.path.join(tmp, "game.so")
        subprocess.run([a.psc, a.game, "-o", plugin, "--target", "cuda"] + options, env=env, check=True)
        emitted = subprocess.run([a.psc, a.game, "--emit", "ptx"] + options, env=env, check=True, capture_output=True).stdout
        # --emit ptx heads each unit with a comment line when there are several.
        units = [u for u in re.split(rb"// ---- compile unit \d+ of \d+\n", emitted) if u]
        ptx = b"\0".join(units)
        cubins = glob.glob(os.path.join(tmp, "psc", "*.cubin"))
        if len(cubins) != 1:
            raise SystemExit(f"FAIL: expected one cached cubin, found {cubins}")
        with open(cubins[0], "rb") as f:
            cubin = f.read()
        if not cubin.startswith(b"\x7fELF"):
            failures.append("the cached cubin is not an ELF image")
        if symbol_bytes(plugin, "psc_device_cubin", len(cubin) + 1) != cubin + b"\0":
            failures.append("psc_device_cubin differs from the compiled cubin")
        if not ptx or symbol_bytes(plugin, "psc_device_ptx", len(ptx) + 1) != ptx + b"\0":
            failures.append("psc_device_ptx differs from --emit ptx")
        exported = subprocess.run(["nm", "-D", plugin], capture_output=True, text=True, check=True).stdout
        if any(name in exported for name in ("psc_device_cubin", "psc_device_ptx")):
            failures.append("the plugin exports its device code symbols")
        library = ctypes.CDLL(plugin)
        library.psc_abi_version.restype = ctypes.c_uint32
        if library.psc_abi_version() == 0:
            failures.append("psc_abi_version() returned 0")
        if a.cuda_units != "0" and len(units) != int(a.cuda_units):
            failures.append(f"{len(units)} PTX units, not {a.cuda_units}")
        print(f"{os.path.basename(a.game)}: cubin {len(cubin)} bytes, PTX {len(ptx)} bytes in {len(units)} unit(s)")
    for f in failures:
        print("FAIL:", f)
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
