"""Rendering with the game's sprites and colours, and GIF output."""

import numpy as np
import pytest

import psc

# games/sokoban.txt, level 0 (7x5):      colours from its OBJECTS section:
#   #######                               Background #2e2e2e #333333 (pattern 00010/11111/...)
#   #.....#                               Player #3c8ed9 #f2d0a4 #1f4f7a, rows .111. .111. 00000 .000. .2.2.
#   #.*O..#                               Crate #b5651d #7a3f0f, rows 11111 10001 10001 10001 11111
#   #..P..#                               Target #d9a441, rows ..... .000. .0.0. .000. .....
#   #######
BACKGROUND_0, BACKGROUND_1 = (0x2E, 0x2E, 0x2E), (0x33, 0x33, 0x33)
PLAYER_0, PLAYER_1, PLAYER_2 = (0x3C, 0x8E, 0xD9), (0xF2, 0xD0, 0xA4), (0x1F, 0x4F, 0x7A)
CRATE_0, CRATE_1 = (0xB5, 0x65, 0x1D), (0x7A, 0x3F, 0x0F)
TARGET_0 = (0xD9, 0xA4, 0x41)


def cell(picture, x, y, scale=1):
    size = 5 * scale
    return picture[y * size : (y + 1) * size, x * size : (x + 1) * size]


@pytest.fixture
def env(sokoban_plugin):
    with psc.VectorEnv(sokoban_plugin, num_envs=2, levels=[0, 2]) as env:
        env.reset(seed=0)
        yield env


def test_the_picture_has_the_level_size(env):
    assert env.render(0).shape == (5 * 5, 7 * 5, 3)
    assert env.render(1).shape == (7 * 5, 9 * 5, 3)
    assert env.render(1, scale=3).shape == (7 * 15, 9 * 15, 3)
    assert env.render(0).dtype == np.uint8


def test_sprites_are_painted_over_the_background(env):
    picture = env.render(0)
    player = cell(picture, 3, 3)
    assert tuple(player[0, 0]) == BACKGROUND_0  # '.' in the player sprite: background row 00010, column 0
    assert tuple(player[3, 0]) == BACKGROUND_1  # '.' again: background row 11111
    assert tuple(player[0, 1]) == PLAYER_1
    assert tuple(player[2, 0]) == PLAYER_0
    assert tuple(player[4, 1]) == PLAYER_2
    crate = cell(picture, 2, 2)
    assert tuple(crate[0, 0]) == CRATE_1
    assert tuple(crate[1, 1]) == CRATE_0
    target = cell(picture, 3, 2)
    assert tuple(target[2, 1]) == TARGET_0
    assert tuple(target[2, 2]) == BACKGROUND_0  # the target's hole: background row 01000, column 2
    assert tuple(target[1, 0]) == BACKGROUND_1
    wall = cell(picture, 0, 0)  # Wall #6b4a2f #4f3420, the same pattern as the background
    assert tuple(wall[0, 0]) == (0x6B, 0x4A, 0x2F)
    assert tuple(wall[0, 3]) == (0x4F, 0x34, 0x20)


def test_scaling_repeats_pixels(env):
    small, large = env.render(0), env.render(0, scale=2)
    np.testing.assert_array_equal(large[::2, ::2], small)


def test_save_gif_writes_every_frame(env, tmp_path):
    from PIL import Image

    frames = [env.render(0)]
    for action in [1, 1, 0, 3]:
        env.step([action, 0])
        frames.append(env.render(0))
    path = tmp_path / "rollout.gif"
    psc.save_gif(frames, path, fps=5)
    with Image.open(path) as gif:
        assert gif.n_frames == len(frames)
        assert gif.size == (7 * 5, 5 * 5)
        assert gif.info["duration"] == 200
