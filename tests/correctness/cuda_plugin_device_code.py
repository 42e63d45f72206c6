#!/usr/bin/python3
"""A CUDA plugin carries its game's device code: the cubin and the PTX of
every compile unit, the same bytes that psc compiled (`--emit ptx`, the
cache), and the kernels' stack bound, in a section the loader does not map
(.psc_device, runtime/plugin_host/DeviceImage.h), kept by `strip`; and its
CPU backend loads and answers without a GPU.

    cuda_plugin_device_code.py PSC GAME [--cuda-units N]"""
import argparse
import ctypes
import glob
import os
import re
import struct
import subprocess
import sys
import tempfile


def device_section(plugin):
    """The plugin's .psc_device section (runtime/plugin_host/DeviceImage.h), decoded:
    (stack bytes, cubin, [each unit's PTX]); and whether the loader maps it."""
    dump = os.path.join(os.path.dirname(plugin), "device.bin")
    subprocess.run(["objcopy", "--dump-section", f".psc_device={dump}", plugin, dump + ".so"], check=True)
    with open(dump, "rb") as f:
        data = f.read()
    if data[:8] != b"pscdev1\0":
        raise SystemExit(f"FAIL: {plugin}'s .psc_device section does not start with psc's mark")
    stack, cubin_bytes, units = struct.unpack_from("<3Q", data, 8)
    sizes = struct.unpack_from(f"<{units}Q", data, 32)
    at = 32 + 8 * units
    cubin = data[at:at + cubin_bytes]
    at += cubin_bytes
    ptx = []
    for size in sizes:
        if data[at + size:at + size + 1] != b"\0":
            raise SystemExit(f"FAIL: a PTX unit of {plugin}'s device section is not followed by a NUL")
        ptx.append(data[at:at + size])
        at += size + 1
    if at != len(data):
        raise SystemExit(f"FAIL: {len(data) - at} bytes after the last PTX unit")
    flags = None
    for line in subprocess.run(["readelf", "-SW", plugin], capture_output=True, text=True, check=True).stdout.splitlines():
        parts = line.replace("[ ", "[").split()
        if len(parts) > 2 and parts[1] == ".psc_device":
            flags = parts[7] if len(parts) > 10 else ""
    return stack, cubin, ptx, flags


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
        stack, section_cubin, section_ptx, flags = device_section(plugin)
        if section_cubin != cubin:
            failures.append("the device section's cubin differs from the compiled cubin")
        if section_ptx != units:
            failures.append("the device section's PTX differs from --emit ptx")
        if flags is None or "A" in flags:
            failures.append(f"the device section is missing or loaded with the plugin (flags {flags!r})")
        if not 0 < stack < 512 * 1024:
            failures.append(f"the device section's stack bound {stack} is not a kernel stack's")
        stripped = os.path.join(tmp, "stripped.so")
        subprocess.run(["strip", "-o", stripped, plugin], check=True)
        if device_section(stripped)[1] != cubin:
            failures.append("strip dropped or changed the device section")
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
