"""Loading a psc plugin (a shared library with the C ABI of psc_plugin.h)."""

import ctypes
import os
from dataclasses import dataclass
from typing import List, Tuple

import numpy as np

from . import _abi


class PscError(RuntimeError):
    """A plugin call failed; the message is the plugin's psc_last_error() text."""

    def __init__(self, status: int, message: str):
        self.status = status
        self.status_name = _abi.STATUS_NAMES.get(status, f"status {status}")
        super().__init__(f"{message} ({self.status_name})")


@dataclass(frozen=True)
class GameInfo:
    """The plugin's psc_game_info, copied into Python values."""

    title: str
    author: str
    homepage: str
    source_name: str
    source_sha1: str
    generator: str
    flags: int
    backends: int
    object_names: Tuple[str, ...]
    object_layers: Tuple[int, ...]
    layer_count: int
    level_entries: Tuple[int, ...]
    level_built: Tuple[bool, ...]
    level_sizes: Tuple[Tuple[int, int], ...]  # (width, height) of each playable level
    max_width: int
    max_height: int
    entry_is_message: Tuple[bool, ...]
    entry_messages: Tuple[str, ...]
    action_count: int
    realtime_interval: float
    object_sprites: np.ndarray  # int8 (object_count, 5, 5), -1 transparent
    object_colors: np.ndarray  # uint32 (object_count, 10), 0xRRGGBB
    background_color: int
    text_color: int
    state_key_bytes: int
    again_interval: float  # seconds between `again` turns in the reference's player
    rule_messages: Tuple[str, ...]  # texts of rules' `message` commands (step results' message indexes them)

    @property
    def level_count(self) -> int:
        return len(self.level_entries)

    @property
    def uses_random(self) -> bool:
        return bool(self.flags & _abi.FLAG_USES_RANDOM)

    @property
    def noaction(self) -> bool:
        return bool(self.flags & _abi.FLAG_NOACTION)

    def has_backend(self, backend: int) -> bool:
        return bool(self.backends & (1 << backend))


def _text(value) -> str:
    return value.decode("utf-8") if value else ""


def _read_info(raw: _abi.GameInfo) -> GameInfo:
    objects = raw.object_count
    levels = raw.level_count
    entries = raw.entry_count
    sprites = np.ctypeslib.as_array(raw.object_sprites, shape=(objects * 25,)).reshape(objects, 5, 5).copy()
    colors = np.ctypeslib.as_array(raw.object_colors, shape=(objects * 10,)).reshape(objects, 10).copy()
    return GameInfo(
        title=_text(raw.title),
        author=_text(raw.author),
        homepage=_text(raw.homepage),
        source_name=_text(raw.source_name),
        source_sha1=_text(raw.source_sha1),
        generator=_text(raw.generator),
        flags=raw.flags,
        backends=raw.backends,
        object_names=tuple(_text(raw.object_names[i]) for i in range(objects)),
        object_layers=tuple(raw.object_layers[i] for i in range(objects)),
        layer_count=raw.layer_count,
        level_entries=tuple(raw.level_entries[i] for i in range(levels)),
        level_built=tuple(bool(raw.level_built[i]) for i in range(levels)),
        level_sizes=tuple((raw.level_widths[i], raw.level_heights[i]) for i in range(levels)),
        max_width=raw.max_width,
        max_height=raw.max_height,
        entry_is_message=tuple(bool(raw.entry_is_message[i]) for i in range(entries)),
        entry_messages=tuple(_text(raw.entry_messages[i]) for i in range(entries)),
        action_count=raw.action_count,
        realtime_interval=raw.realtime_interval,
        object_sprites=sprites,
        object_colors=colors,
        background_color=raw.background_color,
        text_color=raw.text_color,
        state_key_bytes=raw.state_key_bytes,
        again_interval=raw.again_interval,
        rule_messages=tuple(_text(raw.rule_messages[i]) for i in range(raw.rule_message_count)),
    )


class Plugin:
    """One loaded plugin: its functions (with signatures) and its game info.

    The library stays loaded for the life of the process (ctypes never
    unloads), so batches may outlive this object safely.
    """

    def __init__(self, path: str):
        self.path = os.path.abspath(path)
        self.lib = ctypes.CDLL(self.path)
        _abi.bind(self.lib)
        version = self.lib.psc_abi_version()
        if version != _abi.ABI_VERSION:
            raise PscError(2, f"{self.path}: plugin ABI version {version}, this package speaks {_abi.ABI_VERSION}")
        self.info = _read_info(self.lib.psc_get_game_info().contents)

    def check(self, status: int, doing: str) -> None:
        """Raises PscError with the plugin's own message when a call failed."""
        if status != 0:
            raise PscError(status, f"{doing}: {_text(self.lib.psc_last_error())}")

    def playable_levels(self) -> List[int]:
        """Levels this plugin was built for (psc --levels may leave some out)."""
        return [i for i, built in enumerate(self.info.level_built) if built]
