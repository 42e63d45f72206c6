"""Every exported function of a plugin, called with null, out-of-range and
wrong-size arguments, returns an error code with a message, never undefined
behaviour; two threads stepping different batches at once see their own
results and their own error messages.

Usage: hostile_abi.py PSC GAME [--cuda]

The CPU-only plugin of GAME is checked on the CPU backend, and its CUDA
entry points must answer PSC_ERROR_BACKEND_UNAVAILABLE.  With --cuda, the
plugin with both backends (and search's kernels) is built too: on a machine
without a GPU, creating a CUDA batch must fail with BACKEND_UNAVAILABLE or
DEVICE and a message; with one, its batch answers hostile keys as the CPU's
(tools/gpu_check.sh sanitize runs this under compute-sanitizer).

Calls that could bring the process down run in a child process.  KNOWN_BUGS
lists the cases that fail today (the plugin's code is in templates/, see
docs/robustness.md): they are run and reported as XFAIL, and one that starts
to pass fails the test until it is taken off the list."""
import ctypes
import os
import resource
import subprocess
import sys
import tempfile
import threading
from ctypes import byref, c_int32, c_size_t, c_uint8, c_uint64, c_void_p

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "python"))
from psc import _abi  # noqa: E402

S = {name: code for code, name in _abi.STATUS_NAMES.items()}
OK, NULL, ABI, BAD_ARG, BAD_ENV, BAD_LEVEL, BAD_ACTION, BAD_STATE, SMALL, UNAVAILABLE, OOM, DEVICE = (
    S["PSC_OK"], S["PSC_ERROR_NULL_POINTER"], S["PSC_ERROR_ABI_VERSION"], S["PSC_ERROR_BAD_ARGUMENT"],
    S["PSC_ERROR_BAD_ENV"], S["PSC_ERROR_BAD_LEVEL"], S["PSC_ERROR_BAD_ACTION"], S["PSC_ERROR_BAD_STATE"],
    S["PSC_ERROR_BUFFER_TOO_SMALL"], S["PSC_ERROR_BACKEND_UNAVAILABLE"], S["PSC_ERROR_OUT_OF_MEMORY"],
    S["PSC_ERROR_DEVICE"])
INT32_MAX, INT32_MIN = 2**31 - 1, -(2**31)

# Cases that fail today, by name; see docs/robustness.md ("Open findings").
KNOWN_BUGS = set()

FAILURES = []
XFAILS = []


class Plugin:
    def __init__(self, path):
        self.lib = ctypes.CDLL(path)
        _abi.bind(self.lib)
        self.info = self.lib.psc_get_game_info().contents

    def error(self):
        return (self.lib.psc_last_error() or b"").decode()

    def options(self, **fields):
        o = _abi.BatchOptions(struct_size=ctypes.sizeof(_abi.BatchOptions), backend=_abi.BACKEND_CPU, num_envs=2,
                              threads=1, undo_depth=2)
        for k, v in fields.items():
            setattr(o, k, v)
        return o

    def create(self, **fields):
        b = c_void_p()
        status = self.lib.psc_batch_create(byref(self.options(**fields)), byref(b))
        if status != OK:
            raise RuntimeError(f"psc_batch_create: {self.error()}")
        return b


def record(ok, name, detail=""):
    known = name in KNOWN_BUGS
    if known and not ok:
        XFAILS.append(name)
        print(f"XFAIL {name}{detail}")
    elif known and ok:
        FAILURES.append(name + " (passes now: take it off KNOWN_BUGS)")
        print(f"XPASS {name}")
    else:
        print(f"{'ok   ' if ok else 'FAIL '} {name}{detail}")
        if not ok:
            FAILURES.append(name)


def expect(plugin, name, status, wanted):
    """status must be one of wanted, and an error must come with a message."""
    wanted = (wanted,) if isinstance(wanted, int) else wanted
    message = plugin.error() if status != OK else ""
    ok = status in wanted and (status == OK or bool(message))
    shown = _abi.STATUS_NAMES.get(status, str(status))
    record(ok, f"{name}: {shown}" + (f" ({message})" if message and not ok else ""))


def in_child(name, code, plugin_path, limit_bytes=0):
    """Runs `code` (Python, with `lib`, `_abi` and the names of this module) in
    a child process; the case passes when it exits 0 (the code asserts)."""
    program = (f"import sys; sys.path.insert(0, {os.path.dirname(os.path.abspath(__file__))!r})\n"
               "from hostile_abi import *\n"
               f"p = Plugin({plugin_path!r}); lib = p.lib\n" + code)

    def limit():
        if limit_bytes:
            resource.setrlimit(resource.RLIMIT_AS, (limit_bytes, limit_bytes))

    r = subprocess.run([sys.executable, "-c", program], capture_output=True, text=True, timeout=120, preexec_fn=limit)
    detail = "" if r.returncode == 0 else f" (exit {r.returncode}: {(r.stderr.strip().splitlines() or [''])[-1][:150]})"
    record(r.returncode == 0, name, detail)


def batch_creation(p, path):
    lib = p.lib
    b = c_void_p()
    expect(p, "batch_create(NULL options)", lib.psc_batch_create(None, byref(b)), NULL)
    expect(p, "batch_create(NULL batch)", lib.psc_batch_create(byref(p.options()), None), NULL)
    for size in (0, ctypes.sizeof(_abi.BatchOptions) - 4, ctypes.sizeof(_abi.BatchOptions) + 4, 2**32 - 1):
        expect(p, f"batch_create with struct_size {size}", lib.psc_batch_create(byref(p.options(struct_size=size)), byref(b)),
               ABI)
    for field, value in (("num_envs", 0), ("num_envs", -1), ("num_envs", INT32_MIN), ("undo_depth", -1),
                         ("auto_reset", -1), ("auto_reset", 3), ("max_episode_steps", -1),
                         ("again_mode", -1), ("again_mode", 2)):
        expect(p, f"batch_create with {field} {value}", lib.psc_batch_create(byref(p.options(**{field: value})), byref(b)),
               BAD_ARG)
    for backend in (-1, 2, INT32_MAX):
        expect(p, f"batch_create with backend {backend}", lib.psc_batch_create(byref(p.options(backend=backend)), byref(b)),
               (BAD_ARG, UNAVAILABLE))
    for device in (-1, INT32_MAX):
        expect(p, f"batch_create of a CUDA batch on device {device}",
               lib.psc_batch_create(byref(p.options(backend=_abi.BACKEND_CUDA, device=device)), byref(b)),
               (BAD_ARG, UNAVAILABLE, DEVICE))
    if not p.info.backends & (1 << _abi.BACKEND_CUDA):
        expect(p, "batch_create of a CUDA batch in a CPU-only plugin",
               lib.psc_batch_create(byref(p.options(backend=_abi.BACKEND_CUDA)), byref(b)), UNAVAILABLE)
    lib.psc_batch_destroy(None)
    record(True, "batch_destroy(NULL) returns")
    # Sizes no machine holds: an error, not an abort.
    in_child("batch_create with more environments than memory holds",
             "import ctypes\nb = ctypes.c_void_p()\n"
             "s = lib.psc_batch_create(ctypes.byref(p.options(num_envs=INT32_MAX, undo_depth=0)), ctypes.byref(b))\n"
             "assert s == OOM and p.error(), s\n", path, limit_bytes=4 << 30)
    in_child("batch_create with num_envs and undo_depth of INT32_MAX",
             "import ctypes\nb = ctypes.c_void_p()\n"
             "s = lib.psc_batch_create(ctypes.byref(p.options(num_envs=INT32_MAX, undo_depth=INT32_MAX)), ctypes.byref(b))\n"
             "assert s in (OOM, BAD_ARG) and p.error(), s\n", path, limit_bytes=4 << 30)
    in_child("batch_create with more threads than the system gives",
             "import ctypes\nb = ctypes.c_void_p()\n"
             "s = lib.psc_batch_create(ctypes.byref(p.options(threads=100000)), ctypes.byref(b))\n"
             "assert s in (OOM, BAD_ARG) and p.error(), s\n", path, limit_bytes=2 << 30)


def batch_calls(p, path):
    lib, info = p.lib, p.info
    b = p.create()
    n = c_int32()
    expect(p, "batch_size(NULL batch)", lib.psc_batch_size(None, byref(n)), NULL)
    expect(p, "batch_size(NULL num_envs)", lib.psc_batch_size(b, None), NULL)
    expect(p, "batch_size", lib.psc_batch_size(b, byref(n)), OK)
    record(n.value == 2, "batch_size gives num_envs")

    I32x2 = c_int32 * 2
    U64x2 = c_uint64 * 2
    levels, seeds = I32x2(0, 0), U64x2(1, 2)
    expect(p, "reset(NULL batch)", lib.psc_reset(None, None, 2, levels, seeds), NULL)
    expect(p, "reset(NULL levels)", lib.psc_reset(b, None, 2, None, seeds), NULL)
    expect(p, "reset(NULL seeds)", lib.psc_reset(b, None, 2, levels, None), NULL)
    expect(p, "reset without env_ids, count 1 of 2", lib.psc_reset(b, None, 1, levels, seeds), BAD_ARG)
    expect(p, "reset without env_ids, count -1", lib.psc_reset(b, None, -1, levels, seeds), BAD_ARG)
    for env in (2, -1, INT32_MAX, INT32_MIN):
        expect(p, f"reset of environment {env}", lib.psc_reset(b, I32x2(env, 0), 1, levels, seeds), BAD_ENV)
    for level in (-1, info.level_count, INT32_MAX, INT32_MIN):
        expect(p, f"reset to level {level}", lib.psc_reset(b, None, 2, I32x2(level, 0), seeds), BAD_LEVEL)
    expect(p, "reset of no environments (env_ids, count 0)", lib.psc_reset(b, I32x2(0, 0), 0, levels, seeds), OK)
    expect(p, "reset of all with seed 2^64-1", lib.psc_reset(b, None, 2, levels, U64x2(2**64 - 1, 0)), OK)

    expect(p, "reset_entry(NULL batch)", lib.psc_reset_entry(None, 0, 0, b"s"), NULL)
    expect(p, "reset_entry(NULL seed)", lib.psc_reset_entry(b, 0, 0, None), NULL)
    for env in (2, -1, INT32_MAX):
        expect(p, f"reset_entry of environment {env}", lib.psc_reset_entry(b, env, 0, b"s"), BAD_ENV)
    for entry in (-1, INT32_MIN):
        expect(p, f"reset_entry to entry {entry}", lib.psc_reset_entry(b, 0, entry, b"s"), BAD_LEVEL)
    expect(p, "reset_entry with a seed of 100000 bytes", lib.psc_reset_entry(b, 0, 0, b"7" * 100000), (OK, BAD_ARG))
    expect(p, "reset_entry with a seed that is not UTF-8", lib.psc_reset_entry(b, 0, 0, b"\xff\xfe\x80"), (OK, BAD_ARG))
    # Past the last entry the game is over (the reference shows its end);
    # the environment must stay usable.
    in_child("reset_entry past the last entry, then step and dump",
             "import ctypes\nb = p.create()\n"
             "for e in (p.info.entry_count, p.info.entry_count + 1, INT32_MAX):\n"
             "    s = lib.psc_reset_entry(b, 0, e, b's')\n"
             "    assert s in (OK, BAD_LEVEL), s\n"
             "    assert lib.psc_step(b, (ctypes.c_int32 * 2)(0, 7), None) == OK\n"
             "    need = ctypes.c_size_t()\n"
             "    lib.psc_dump_state(b, 0, None, 0, ctypes.byref(need))\n"
             "    buf = ctypes.create_string_buffer(need.value)\n"
             "    assert lib.psc_dump_state(b, 0, buf, need.value, None) == OK\n", path)
    expect(p, "reset_entry back to entry 0", lib.psc_reset_entry(b, 0, 0, b"s"), OK)

    for name in ("start_cut_off", "start_won"):
        query = getattr(lib, "psc_" + name)
        flag = ctypes.c_uint8(7)
        expect(p, f"{name}(NULL batch)", query(None, 0, ctypes.byref(flag)), NULL)
        expect(p, f"{name}(NULL flag)", query(b, 0, None), NULL)
        for env in (2, -1, INT32_MAX, INT32_MIN):
            expect(p, f"{name} of environment {env}", query(b, env, ctypes.byref(flag)), BAD_ENV)
        expect(p, name, query(b, 0, ctypes.byref(flag)), OK)
        record(flag.value in (0, 1), f"{name} writes 0 or 1")
    expect(p, "set_deadline(NULL batch)", lib.psc_set_deadline(None, 1.0), NULL)
    for seconds in (-1.0, float("nan"), float("inf"), 1e300):
        expect(p, f"set_deadline({seconds})", lib.psc_set_deadline(b, seconds), BAD_ARG)
    expect(p, "set_deadline(0): none", lib.psc_set_deadline(b, 0.0), OK)

    expect(p, "step(NULL batch)", lib.psc_step(None, I32x2(0, 0), None), NULL)
    expect(p, "step(NULL actions)", lib.psc_step(b, None, None), NULL)
    for action in (8, -1, INT32_MAX, INT32_MIN):
        expect(p, f"step with action {action}", lib.psc_step(b, I32x2(0, action), None), BAD_ACTION)
    results = (_abi.StepResult * 2)()
    expect(p, "step", lib.psc_step(b, I32x2(3, 7), results), OK)

    per_env = info.object_count * info.max_height * info.max_width
    obs = (c_uint8 * (2 * per_env))()
    expect(p, "observe(NULL batch)", lib.psc_observe(None, obs, len(obs)), NULL)
    expect(p, "observe(NULL buffer)", lib.psc_observe(b, None, len(obs)), NULL)
    for size in (0, 1, len(obs) - 1):
        expect(p, f"observe into {size} of {len(obs)} bytes", lib.psc_observe(b, obs, size), SMALL)
    expect(p, "observe", lib.psc_observe(b, obs, len(obs)), OK)

    bufs = _abi.Buffers()
    expect(p, "get_buffers(NULL batch)", lib.psc_get_buffers(None, byref(bufs)), NULL)
    expect(p, "get_buffers(NULL buffers)", lib.psc_get_buffers(b, None), NULL)
    expect(p, "get_buffers", lib.psc_get_buffers(b, byref(bufs)), OK)
    record(bufs.device == -1 and bufs.num_envs == 2, "get_buffers: host memory, num_envs")
    actions = ctypes.cast(bufs.actions, ctypes.POINTER(c_int32))
    actions[0], actions[1] = 0, 99
    expect(p, "step_buffers with action 99 in the buffer", lib.psc_step_buffers(b), BAD_ACTION)
    actions[1] = 1
    expect(p, "step_buffers(NULL)", lib.psc_step_buffers(None), NULL)
    expect(p, "step_buffers", lib.psc_step_buffers(b), OK)

    many = (c_int32 * 6)(0, 1, 2, 3, 4, 7)
    expect(p, "step_many(NULL batch)", lib.psc_step_many(None, 3, many, None, None, None, None), NULL)
    expect(p, "step_many(NULL actions)", lib.psc_step_many(b, 3, None, None, None, None, None), NULL)
    expect(p, "step_many with -1 steps", lib.psc_step_many(b, -1, many, None, None, None, None), BAD_ARG)
    expect(p, "step_many with INT32_MIN steps", lib.psc_step_many(b, INT32_MIN, many, None, None, None, None), BAD_ARG)
    expect(p, "step_many with action 8 in step 2", lib.psc_step_many(b, 3, (c_int32 * 6)(0, 1, 2, 3, 8, 0), None, None,
                                                                     None, None), BAD_ACTION)
    expect(p, "step_many with 0 steps", lib.psc_step_many(b, 0, many, None, None, None, None), OK)
    expect(p, "step_many", lib.psc_step_many(b, 3, many, None, None, None, None), OK)

    expect(p, "set_stream(NULL batch)", lib.psc_set_stream(None, None), NULL)
    expect(p, "set_stream on a CPU batch", lib.psc_set_stream(b, c_void_p(0x1234)), (OK, BAD_ARG))
    expect(p, "synchronize(NULL)", lib.psc_synchronize(None), NULL)
    expect(p, "synchronize on a CPU batch", lib.psc_synchronize(b), OK)

    stats = _abi.RolloutStats()
    expect(p, "rollout(NULL batch)", lib.psc_rollout(None, 1, 0, byref(stats)), NULL)
    expect(p, "rollout with -1 steps", lib.psc_rollout(b, -1, 0, byref(stats)), BAD_ARG)
    expect(p, "rollout(NULL stats)", lib.psc_rollout(b, 2, 0, None), OK)
    expect(p, "rollout with seed 2^64-1", lib.psc_rollout(b, 2, 2**64 - 1, byref(stats)), OK)
    record(stats.steps == 4, "rollout counts its steps")

    record(lib.psc_state_size(None) == 0, "state_size(NULL) is 0")
    size = lib.psc_state_size(b)
    state = (c_uint8 * size)()
    expect(p, "save_state(NULL batch)", lib.psc_save_state(None, 0, state, size), NULL)
    expect(p, "save_state(NULL buffer)", lib.psc_save_state(b, 0, None, size), NULL)
    for env in (2, -1, INT32_MIN):
        expect(p, f"save_state of environment {env}", lib.psc_save_state(b, env, state, size), BAD_ENV)
    for small in (0, size - 1):
        expect(p, f"save_state into {small} of {size} bytes", lib.psc_save_state(b, 0, state, small), SMALL)
    expect(p, "save_state", lib.psc_save_state(b, 0, state, size), OK)
    expect(p, "load_state(NULL batch)", lib.psc_load_state(None, 0, state, size), NULL)
    expect(p, "load_state(NULL buffer)", lib.psc_load_state(b, 0, None, size), NULL)
    expect(p, "load_state of environment 2", lib.psc_load_state(b, 2, state, size), BAD_ENV)
    expect(p, f"load_state of {size - 1} bytes", lib.psc_load_state(b, 0, state, size - 1), SMALL)
    expect(p, "load_state of zeros", lib.psc_load_state(b, 1, (c_uint8 * size)(), size), BAD_STATE)
    other = p.create(undo_depth=5)
    other_state = (c_uint8 * lib.psc_state_size(other))()
    lib.psc_save_state(other, 0, other_state, len(other_state))
    expect(p, "load_state of a state with another undo depth", lib.psc_load_state(b, 0, other_state, len(other_state)),
           BAD_STATE)
    lib.psc_batch_destroy(other)
    expect(p, "load_state", lib.psc_load_state(b, 1, state, size), OK)
    in_child("load_state of a state whose header is valid and whose body is not",
             "import ctypes\nb = p.create()\nsize = lib.psc_state_size(b)\n"
             "state = (ctypes.c_uint8 * size)()\nassert lib.psc_save_state(b, 0, state, size) == OK\n"
             "for i in range(56, size):\n    state[i] = 0xff\n"
             "s = lib.psc_load_state(b, 0, state, size)\n"
             "if s == OK:\n"
             "    lib.psc_step(b, (ctypes.c_int32 * 2)(0, 0), None)\n"
             "    need = ctypes.c_size_t()\n    lib.psc_dump_state(b, 0, None, 0, ctypes.byref(need))\n"
             "assert s == BAD_STATE and p.error(), s\n", path, limit_bytes=4 << 30)

    key = (c_uint8 * p.info.state_key_bytes)()
    expect(p, "canonical_keys(NULL batch)", lib.psc_canonical_keys(None, key, 1, None), NULL)
    expect(p, "canonical_keys(NULL keys)", lib.psc_canonical_keys(b, None, 1, None), NULL)
    expect(p, "canonical_keys of -1 keys", lib.psc_canonical_keys(b, key, -1, None), BAD_ARG)
    expect(p, "canonical_keys of no keys", lib.psc_canonical_keys(b, key, 0, None), OK)
    keys_outside_the_level(p)
    state_outside_its_level(p)

    needed = c_size_t()
    expect(p, "dump_state(NULL batch)", lib.psc_dump_state(None, 0, None, 0, byref(needed)), NULL)
    expect(p, "dump_state of environment 2", lib.psc_dump_state(b, 2, None, 0, byref(needed)), BAD_ENV)
    expect(p, "dump_state(NULL buffer) gives the size", lib.psc_dump_state(b, 0, None, 0, byref(needed)), SMALL)
    text = ctypes.create_string_buffer(needed.value)
    expect(p, f"dump_state into {needed.value - 1} bytes", lib.psc_dump_state(b, 0, text, needed.value - 1, None), SMALL)
    expect(p, "dump_state(NULL needed)", lib.psc_dump_state(b, 0, text, needed.value, None), OK)
    record(len(text.value) + 1 == needed.value, "dump_state's size includes the NUL")
    lib.psc_batch_destroy(b)


def expand(p, b, key, actions, cuda):
    """psc_expand of one key: (status, flags, hashes, estimates); on a CUDA
    batch through device memory."""
    lib = p.lib
    n = len(actions)
    children = (c_uint64 * (n * len(key)))()
    flags, hashes, estimates = (c_uint8 * n)(), (c_uint64 * n)(*[5] * n), (c_int32 * n)(*[5] * n)
    host = [key, children, flags, hashes, estimates]
    if not cuda:
        return lib.psc_expand(b, 0, key, 1, actions, n, children, flags, hashes, estimates), flags, hashes, estimates
    device = []
    for buffer in [actions] + host:
        d = c_void_p()
        expect(p, "device_alloc", lib.psc_device_alloc(b, ctypes.sizeof(buffer), byref(d)), OK)
        expect(p, "copy to the device", lib.psc_copy(b, d, buffer, ctypes.sizeof(buffer)), OK)
        device.append(d)
    # Host memory where device memory belongs is refused, not launched on.
    expect(p, "expand on a CUDA batch with host actions", lib.psc_expand(b, 0, device[1], 1, actions, n, *device[2:]), BAD_ARG)
    expect(p, "expand on a CUDA batch with host keys", lib.psc_expand(b, 0, key, 1, device[0], n, *device[2:]), BAD_ARG)
    status = lib.psc_expand(b, 0, device[1], 1, device[0], n, *device[2:])
    expect(p, "synchronize", lib.psc_synchronize(b), OK)
    for buffer, d in zip([actions] + host, device):
        expect(p, "copy from the device", lib.psc_copy(b, buffer, d, ctypes.sizeof(buffer)), OK)
        lib.psc_device_free(b, d)
    return status, flags, hashes, estimates


def keys_outside_the_level(p, backend=_abi.BACKEND_CPU):
    """A key with an object or a header bit no state has is refused: rules
    look at the cells next to a match, and an object on a guard position
    (past the level's last row) reached past the boards' words (fuzzing)."""
    lib = p.lib
    cuda = backend == _abi.BACKEND_CUDA
    on = " (CUDA)" if cuda else ""
    b = p.create(backend=backend)  # on level 0
    words = p.info.state_key_bytes // 8
    env = (c_int32 * 1)(0)
    valid = (c_uint64 * words)()
    expect(p, "encode_states" + on, lib.psc_encode_states(b, env, 1, valid, None), OK)
    height = p.info.level_heights[0]
    guard = (c_uint64 * words)(*valid)
    guard[1] |= 1 << height  # the first key object's board, column 0's guard position
    header = (c_uint64 * words)(*valid)
    header[0] |= 1 << 20
    actions = (c_int32 * 2)(0, 3)
    estimates = (c_int32 * 1)()
    for name, key in (("an object on a guard position", guard), ("an unknown header bit", header)):
        expect(p, f"decode_state of a key with {name}{on}", lib.psc_decode_state(b, 0, key), BAD_STATE)
        expect(p, f"estimate_distance of a key with {name}{on}", lib.psc_estimate_distance(b, 0, key, 1, estimates),
               BAD_STATE)
        status, flags, hashes, child_estimates = expand(p, b, key, actions, cuda)
        expect(p, f"expand of a key with {name}{on}", status, OK)
        record(list(flags) == [_abi.EXPAND_INVALID] * 2 and list(hashes) == [0, 0] and list(child_estimates) == [0, 0],
               f"expand flags the children of a key with {name} invalid, hash and estimate 0{on}", f" ({list(flags)})")
    expect(p, "decode_state of an encoded key" + on, lib.psc_decode_state(b, 0, valid), OK)
    status, flags, _, _ = expand(p, b, valid, actions, cuda)
    expect(p, "expand of an encoded key" + on, status, OK)
    record(not any(f & _abi.EXPAND_INVALID for f in flags), "expand takes an encoded key" + on, f" ({list(flags)})")
    lib.psc_batch_destroy(b)


def fnv1a(data):
    h = 0xCBF29CE484222325
    for byte in data:
        h = ((h ^ byte) * 0x100000001B3) & (2**64 - 1)
    return h


def state_outside_its_level(p):
    """A saved state whose checksum matches and whose first object has a cell
    on a guard position is refused (a state can be made by hand)."""
    lib = p.lib
    b = p.create(undo_depth=0)
    size = lib.psc_state_size(b)
    state = (c_uint8 * size)()
    expect(p, "save_state without undo", lib.psc_save_state(b, 0, state, size), OK)
    header_bytes = 64  # magic, sha1, undo capacity and count, the body's checksum
    first_word = int.from_bytes(bytes(state[header_bytes:header_bytes + 8]), "little")
    first_word |= 1 << p.info.level_heights[0]
    state[header_bytes:header_bytes + 8] = list(first_word.to_bytes(8, "little"))
    state[56:64] = list(fnv1a(bytes(state[header_bytes:])).to_bytes(8, "little"))
    expect(p, "load_state of a state with an object on a guard position", lib.psc_load_state(b, 0, state, size), BAD_STATE)
    lib.psc_batch_destroy(b)


def two_threads(p, backend=_abi.BACKEND_CPU):
    """Two threads, one batch each, stepping at once: each sees its own
    results and its own error messages (psc_last_error is per thread).
    Returns the states one after the other, for comparing backends."""
    lib = p.lib
    on = " (CUDA)" if backend == _abi.BACKEND_CUDA else ""
    steps = 300
    rng_actions = [[(i * 7 + k * 3) % 5 for i in range(steps)] for k in range(2)]

    def run(k, out):
        b = p.create(num_envs=4, threads=2, backend=backend)
        acts = (c_int32 * 4)()
        trace = []
        for i, a in enumerate(rng_actions[k]):
            for e in range(4):
                acts[e] = (a + e) % 5
            if lib.psc_step(b, acts, None) != OK:
                out[k] = "step failed: " + p.error()
                return
            if i % 50 == 0:
                # An error of this thread's own kind; the message must be this thread's.
                if k == 0:
                    acts[0] = 99
                    s, want = lib.psc_step(b, acts, None), "action 99"
                else:
                    s, want = lib.psc_save_state(b, 1000 + i, None, 0), f"environment {1000 + i}"
                if s == OK or want not in p.error():
                    out[k] = f"thread {k} got the message {p.error()!r}"
                    return
            need = c_size_t()
            lib.psc_dump_state(b, 1, None, 0, byref(need))
            text = ctypes.create_string_buffer(need.value)
            lib.psc_dump_state(b, 1, text, need.value, None)
            trace.append(text.value)
        lib.psc_batch_destroy(b)
        out[k] = trace

    together = [None, None]
    threads = [threading.Thread(target=run, args=(k, together)) for k in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    alone = [None, None]
    for k in range(2):
        run(k, alone)
    record(all(isinstance(t, list) for t in together), "two threads: no errors but their own" + on +
           "".join(f" ({t})" for t in together if not isinstance(t, list)))
    record(together == alone, "two threads: the same states as one after the other" + on)
    return alone


def tuned_batch_steps_as_cpu(p):
    """A CUDA batch large enough to time its stack limits at creation (which
    steps its environments) starts them again: it steps as a CPU batch does."""
    lib = p.lib
    n = 16384
    words = p.info.state_key_bytes // 8
    envs = (c_int32 * n)(*range(n))

    def run(backend):
        b = p.create(num_envs=n, threads=2, backend=backend)
        acts = (c_int32 * n)()
        for step in range(20):
            acts[:] = [(e * 7 + step * 3) % 5 for e in range(n)]
            expect(p, "step a batch of 16,384", lib.psc_step(b, acts, None), OK)
        keys = (c_uint64 * (n * words))()
        expect(p, "encode a batch of 16,384", lib.psc_encode_states(b, envs, n, keys, None), OK)
        lib.psc_batch_destroy(b)
        return bytes(keys)

    on_cpu = run(_abi.BACKEND_CPU)
    record(run(_abi.BACKEND_CUDA) == on_cpu,
           "a CUDA batch of 16,384 environments, its stack limit timed at creation, steps as a CPU batch")
    # Two such batches created at once time their limits under one lock: neither
    # may lower the limit the other's kernels run at.
    together = [None, None]

    def run_into(k):
        together[k] = run(_abi.BACKEND_CUDA)

    threads = [threading.Thread(target=run_into, args=(k,)) for k in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    record(together == [on_cpu, on_cpu],
           "two CUDA batches of 16,384 created and stepped in two threads at once step as a CPU batch")


def build(target, out, *options):
    r = subprocess.run([PSC, GAME, "-o", out, "--target", target, *options], capture_output=True, text=True)
    if r.returncode != 0:
        print(r.stderr)
        raise SystemExit(f"cannot build {GAME} for {target}")
    return out


def main():
    with tempfile.TemporaryDirectory() as tmp:
        cpu = build("cpu", os.path.join(tmp, "cpu.so"))
        p = Plugin(cpu)
        record(p.lib.psc_abi_version() == _abi.ABI_VERSION, "abi_version")
        batch_creation(p, cpu)
        batch_calls(p, cpu)
        on_cpu = two_threads(p)
        if "--cuda" in sys.argv:
            both = Plugin(build("all", os.path.join(tmp, "all.so"), "--search-kernels"))
            record(bool(both.info.backends & (1 << _abi.BACKEND_CUDA)), "the --target all plugin has the CUDA backend")
            b = c_void_p()
            status = both.lib.psc_batch_create(byref(both.options(backend=_abi.BACKEND_CUDA)), byref(b))
            if status == OK:  # a GPU is here: the CUDA batch answers like the CPU one
                batch_calls_cuda = both.lib.psc_step(b, (c_int32 * 2)(0, 9), None)
                expect(both, "CUDA batch: step with action 9", batch_calls_cuda, BAD_ACTION)
                both.lib.psc_batch_destroy(b)
                keys_outside_the_level(both, _abi.BACKEND_CUDA)
                record(two_threads(both, _abi.BACKEND_CUDA) == on_cpu, "two threads: CUDA batches step as CPU ones")
                # The memory layout, whose kernels use a stack (the registers layout's may not).
                tuned_batch_steps_as_cpu(Plugin(build("all", os.path.join(tmp, "memory.so"), "--gpu-state", "memory")))
            else:
                expect(both, "CUDA batch without a GPU", status, (UNAVAILABLE, DEVICE))
            batch_creation(both, os.path.join(tmp, "all.so"))
    print(f"{len(FAILURES)} failure(s), {len(XFAILS)} known failure(s) (KNOWN_BUGS)")
    return 1 if FAILURES else 0


if __name__ == "__main__":
    PSC, GAME = sys.argv[1], sys.argv[2]
    sys.exit(main())
