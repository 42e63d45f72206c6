"""psc.compile: the plugin cache, the IR beside each plugin, `python3 -m psc build`."""

import json
import os
import subprocess
import sys
from pathlib import Path

from helpers import GAMES, REPO

import psc
from psc.build import ir_path_for


def test_compile_reuses_the_cached_plugin(sokoban_plugin):
    stamp = os.stat(sokoban_plugin).st_mtime_ns
    assert psc.compile(GAMES / "sokoban.txt") == sokoban_plugin
    assert os.stat(sokoban_plugin).st_mtime_ns == stamp


def test_options_make_different_plugins(sokoban_plugin):
    only_level_1 = psc.compile(GAMES / "sokoban.txt", levels=[1])
    assert only_level_1 != sokoban_plugin
    assert psc.Plugin(only_level_1).info.level_built == (False, True, False)


def test_the_ir_lies_beside_the_plugin(sokoban_plugin):
    ir = json.loads(Path(ir_path_for(sokoban_plugin)).read_text())
    assert ir["win_conditions"][0]["quantifier"] == "all"
    assert [o["name"] for o in ir["objects"]] == ["background", "target", "player", "wall", "crate"]


def test_the_module_command_writes_plugin_and_ir(tmp_path):
    output = tmp_path / "sokoban.so"
    subprocess.run(
        [sys.executable, "-m", "psc", "build", str(GAMES / "sokoban.txt"), "-o", str(output), "--levels", "0"],
        check=True,
        cwd=REPO / "python",
        stdout=subprocess.DEVNULL,
    )
    assert (tmp_path / "sokoban.ir.json").exists()
    with psc.VectorEnv(output, num_envs=1, reward="shaped") as env:
        assert env.info.level_built == (True, False, False)
        # Observations keep the size of the game's largest level (9x7), whatever was built.
        assert env.single_observation_space.shape[1:] == (7, 9)
