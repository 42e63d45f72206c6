"""python3 -m psc build GAME.txt -o OUT.so [--target cpu|cuda|all] [--levels 0,1]

Builds a plugin and writes it with its IR (OUT.ir.json, for shaped rewards)
and its source (OUT.source.txt, for text agents), ready to copy to a machine that has no psc compiler.
"""

import argparse
import os
import shutil
import sys

from .build import TARGETS, compile, ir_path_for, source_path_for


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python3 -m psc", description="Builds psc plugins for the Python package.")
    commands = parser.add_subparsers(dest="command", required=True)
    build = commands.add_parser("build", help="build a plugin and its IR file")
    build.add_argument("game", help="the PuzzleScript game (.txt)")
    build.add_argument("-o", "--output", required=True, help="the plugin to write (.so); OUT.ir.json goes beside it")
    build.add_argument("--target", default="cpu", choices=TARGETS)
    build.add_argument("--levels", help="playable levels to build, comma separated (default: all)")
    build.add_argument(
        "--psc", dest="psc_binary", help="the psc compiler (default: $PSC_BINARY, <repo>/build/cli/psc, PATH)"
    )
    args = parser.parse_args(argv)
    levels = None if args.levels is None else [int(level) for level in args.levels.split(",")]
    plugin = compile(args.game, levels=levels, target=args.target, psc_binary=args.psc_binary)
    os.makedirs(os.path.dirname(os.path.abspath(args.output)), exist_ok=True)
    shutil.copyfile(plugin, args.output)
    shutil.copyfile(ir_path_for(plugin), ir_path_for(args.output))
    shutil.copyfile(source_path_for(plugin), source_path_for(args.output))
    print(f"{args.output}\n{ir_path_for(args.output)}\n{source_path_for(args.output)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
