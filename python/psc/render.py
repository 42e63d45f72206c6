"""Pictures of observations, drawn with the game's own 5x5 sprites."""

from typing import Sequence

import numpy as np

from .plugin import GameInfo

SPRITE_SIZE = 5


def _rgb(colors) -> np.ndarray:
    colors = np.asarray(colors, dtype=np.uint32)
    return np.stack([(colors >> 16) & 0xFF, (colors >> 8) & 0xFF, colors & 0xFF], axis=-1).astype(np.uint8)


def render_planes(info: GameInfo, planes: np.ndarray, width: int, height: int, scale: int = 1) -> np.ndarray:
    """One environment's multi-hot planes (C, max_height, max_width) as RGB.

    Only the level's own width x height cells are drawn (the level sits at the
    top left of the planes).  Each cell is background_color with its objects'
    sprites painted over it in channel order, -1 pixels left transparent, as
    psc_plugin.h specifies.  Returns uint8 (height*5*scale, width*5*scale, 3).
    """
    cells = planes[:, :height, :width].astype(bool)
    image = np.empty((height, width, SPRITE_SIZE, SPRITE_SIZE, 3), dtype=np.uint8)
    image[:] = _rgb(info.background_color)
    palette = _rgb(info.object_colors)  # (C, 10, 3)
    for c in range(cells.shape[0]):
        sprite = info.object_sprites[c]
        opaque = sprite >= 0
        if not cells[c].any() or not opaque.any():
            continue
        pixels = palette[c][np.where(opaque, sprite, 0)]  # (5, 5, 3)
        paint = cells[c][:, :, None, None] & opaque[None, None]
        image[paint] = np.broadcast_to(pixels, image.shape)[paint]
    picture = image.transpose(0, 2, 1, 3, 4).reshape(height * SPRITE_SIZE, width * SPRITE_SIZE, 3)
    if scale > 1:
        picture = picture.repeat(scale, axis=0).repeat(scale, axis=1)
    return picture


def save_gif(frames: Sequence[np.ndarray], path: str, fps: float = 10.0) -> None:
    """Writes RGB frames (H, W, 3) as a looping GIF (needs Pillow)."""
    from PIL import Image  # only GIF writing needs Pillow

    if not frames:
        raise ValueError("no frames to save")
    images = [Image.fromarray(np.asarray(frame, dtype=np.uint8)) for frame in frames]
    images[0].save(path, save_all=True, append_images=images[1:], duration=int(round(1000 / fps)), loop=0)
