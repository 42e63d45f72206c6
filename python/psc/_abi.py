"""ctypes mirror of runtime/psc_plugin.h (ABI version 6).

The structs must match the header field for field; ctypes applies the same
C alignment rules, so the layouts agree on every platform psc builds for.
"""

import ctypes
from ctypes import POINTER, c_char_p, c_double, c_int, c_int8, c_int32, c_size_t, c_uint8, c_uint32, c_uint64, c_void_p

ABI_VERSION = 6

BACKEND_CPU = 0
BACKEND_CUDA = 1

AUTO_RESET_OFF = 0
AUTO_RESET_SAME_STEP = 1
AUTO_RESET_NEXT_STEP = 2

AGAIN_SETTLE = 0
AGAIN_ONE_TURN = 1

ACTION_NAMES = ("up", "left", "down", "right", "action", "undo", "restart", "tick")
ACTION_ACTION = 4
ACTION_COUNT = 8

FLAG_NOACTION = 1 << 0
FLAG_USES_RANDOM = 1 << 6

# psc_expand's per-child flags.
EXPAND_WON = 1 << 0
EXPAND_UNCHANGED = 1 << 1
EXPAND_CUT_OFF = 1 << 2
EXPAND_INVALID = 1 << 3
EXPAND_TIMED_OUT = 1 << 4

STATUS_NAMES = {
    0: "PSC_OK",
    1: "PSC_ERROR_NULL_POINTER",
    2: "PSC_ERROR_ABI_VERSION",
    3: "PSC_ERROR_BAD_ARGUMENT",
    4: "PSC_ERROR_BAD_ENV",
    5: "PSC_ERROR_BAD_LEVEL",
    6: "PSC_ERROR_BAD_ACTION",
    7: "PSC_ERROR_BAD_STATE",
    8: "PSC_ERROR_BUFFER_TOO_SMALL",
    9: "PSC_ERROR_BACKEND_UNAVAILABLE",
    10: "PSC_ERROR_OUT_OF_MEMORY",
    11: "PSC_ERROR_DEVICE",
}
ERROR_BUFFER_TOO_SMALL = 8


class GameInfo(ctypes.Structure):
    _fields_ = [
        ("abi_version", c_uint32),
        ("title", c_char_p),
        ("author", c_char_p),
        ("homepage", c_char_p),
        ("source_name", c_char_p),
        ("source_sha1", c_char_p),
        ("generator", c_char_p),
        ("flags", c_uint32),
        ("backends", c_uint32),
        ("object_count", c_int32),
        ("object_names", POINTER(c_char_p)),
        ("object_layers", POINTER(c_int32)),
        ("layer_count", c_int32),
        ("level_count", c_int32),
        ("level_entries", POINTER(c_int32)),
        ("level_built", POINTER(c_uint8)),
        ("level_widths", POINTER(c_int32)),
        ("level_heights", POINTER(c_int32)),
        ("max_width", c_int32),
        ("max_height", c_int32),
        ("entry_count", c_int32),
        ("entry_is_message", POINTER(c_uint8)),
        ("entry_messages", POINTER(c_char_p)),
        ("action_count", c_int32),
        ("realtime_interval", c_double),
        ("object_sprites", POINTER(c_int8)),
        ("object_colors", POINTER(c_uint32)),
        ("background_color", c_uint32),
        ("text_color", c_uint32),
        ("state_key_bytes", c_uint32),
        ("again_interval", c_double),
        ("rule_message_count", c_int32),
        ("rule_messages", POINTER(c_char_p)),
    ]


class BatchOptions(ctypes.Structure):
    _fields_ = [
        ("struct_size", c_uint32),
        ("backend", c_int32),
        ("num_envs", c_int32),
        ("threads", c_int32),
        ("undo_depth", c_int32),
        ("auto_reset", c_int32),
        ("max_episode_steps", c_int32),
        ("device", c_int32),
        ("again_mode", c_int32),
    ]


class StepResult(ctypes.Structure):
    _fields_ = [
        ("reward", ctypes.c_float),
        ("terminated", c_uint8),
        ("truncated", c_uint8),
        ("won", c_uint8),
        ("cut_off", c_uint8),
        ("episode_steps", c_int32),
        ("message", c_int32),
        ("againing", c_uint8),
        ("reserved", c_uint8 * 3),
    ]


class Buffers(ctypes.Structure):
    # Pointers kept as integers (c_void_p): for CUDA batches they are device
    # addresses that must never be dereferenced on the host.
    _fields_ = [
        ("device", c_int32),
        ("num_envs", c_int32),
        ("actions", c_void_p),
        ("observations", c_void_p),
        ("rewards", c_void_p),
        ("terminated", c_void_p),
        ("truncated", c_void_p),
        ("won", c_void_p),
        ("episode_steps", c_void_p),
    ]


class RolloutStats(ctypes.Structure):
    _fields_ = [("steps", ctypes.c_int64), ("wins", ctypes.c_int64), ("episodes", ctypes.c_int64)]


# name: (restype, argtypes).  Array arguments are c_void_p so that numpy
# arrays (arr.ctypes.data) and device pointers (plain ints) both pass.
_PROTOTYPES = {
    "psc_abi_version": (c_uint32, []),
    "psc_get_game_info": (POINTER(GameInfo), []),
    "psc_last_error": (c_char_p, []),
    "psc_batch_create": (c_int, [POINTER(BatchOptions), POINTER(c_void_p)]),
    "psc_batch_destroy": (None, [c_void_p]),
    "psc_batch_size": (c_int, [c_void_p, POINTER(c_int32)]),
    "psc_reset": (c_int, [c_void_p, c_void_p, c_int32, c_void_p, c_void_p]),
    "psc_reset_entry": (c_int, [c_void_p, c_int32, c_int32, c_char_p]),
    "psc_start_cut_off": (c_int, [c_void_p, c_int32, POINTER(c_uint8)]),
    "psc_start_won": (c_int, [c_void_p, c_int32, POINTER(c_uint8)]),
    "psc_set_deadline": (c_int, [c_void_p, c_double]),
    "psc_step": (c_int, [c_void_p, c_void_p, c_void_p]),
    "psc_observe": (c_int, [c_void_p, c_void_p, c_size_t]),
    "psc_get_buffers": (c_int, [c_void_p, POINTER(Buffers)]),
    "psc_step_buffers": (c_int, [c_void_p]),
    "psc_step_many": (c_int, [c_void_p, c_int32, c_void_p, c_void_p, c_void_p, c_void_p, c_void_p]),
    "psc_set_stream": (c_int, [c_void_p, c_void_p]),
    "psc_synchronize": (c_int, [c_void_p]),
    "psc_rollout": (c_int, [c_void_p, c_int32, c_uint64, POINTER(RolloutStats)]),
    "psc_state_size": (c_size_t, [c_void_p]),
    "psc_save_state": (c_int, [c_void_p, c_int32, c_void_p, c_size_t]),
    "psc_load_state": (c_int, [c_void_p, c_int32, c_void_p, c_size_t]),
    "psc_dump_state": (c_int, [c_void_p, c_int32, c_void_p, c_size_t, POINTER(c_size_t)]),
    "psc_encode_states": (c_int, [c_void_p, c_void_p, c_int32, c_void_p, c_void_p]),
    "psc_decode_state": (c_int, [c_void_p, c_int32, c_void_p]),
    "psc_canonical_keys": (c_int, [c_void_p, c_void_p, c_int32, c_void_p]),
    "psc_expand": (c_int, [c_void_p, c_int32, c_void_p, c_int32, c_void_p, c_int32, c_void_p, c_void_p, c_void_p, c_void_p]),
    "psc_estimate_distance": (c_int, [c_void_p, c_int32, c_void_p, c_int32, c_void_p]),
    "psc_device_alloc": (c_int, [c_void_p, c_size_t, POINTER(c_void_p)]),
    "psc_device_free": (c_int, [c_void_p, c_void_p]),
    "psc_copy": (c_int, [c_void_p, c_void_p, c_void_p, c_size_t]),
}


def bind(library: ctypes.CDLL) -> None:
    """Declares every ABI function's signature on a loaded plugin."""
    for name, (restype, argtypes) in _PROTOTYPES.items():
        function = getattr(library, name)
        function.restype = restype
        function.argtypes = argtypes
