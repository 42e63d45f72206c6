"""python3 -m psc build GAME.txt -o OUT.so [--target cpu|cuda|all] [--levels 0,1]
python3 -m psc --version

build: builds a plugin and writes it with its IR (OUT.ir.json, for shaped
rewards) and its source (OUT.source.txt, for text agents), ready to copy to a
machine that has no psc compiler.  --version: this package's version and the
psc compiler it uses.
"""

import argparse
import os
import shutil
import sys

from . import __version__
from .build import TARGETS, CompileError, compile, compiler_version, find_psc_binary, ir_path_for, source_path_for

PSC_HELP = "the psc compiler (default: $PSC_BINARY, <repo>/build/cli/psc in a source checkout, then PATH)"


def print_version(psc_binary) -> None:
    print(f"psc Python package {__version__} ({os.path.dirname(os.path.abspath(__file__))})")
    binary = find_psc_binary(psc_binary)
    print(f"psc compiler: {os.path.abspath(binary)}")
    print(compiler_version(binary))


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python3 -m psc", description="Builds psc plugins for the Python package.")
    parser.add_argument("--version", action="store_true", help="print this package's version and its psc compiler")
    parser.add_argument("--psc", dest="psc_binary", help=PSC_HELP)
    commands = parser.add_subparsers(dest="command")
    build = commands.add_parser("build", help="build a plugin and its IR file")
    build.add_argument("game", help="the PuzzleScript game (.txt)")
    build.add_argument("-o", "--output", required=True, help="the plugin to write (.so); OUT.ir.json goes beside it")
    build.add_argument("--target", default="cpu", choices=TARGETS)
    build.add_argument("--levels", help="playable levels to build, comma separated (default: all)")
    # SUPPRESS: without the option here, the one before the command stays.
    build.add_argument("--psc", dest="psc_binary", help=PSC_HELP, default=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.version:
        try:
            print_version(args.psc_binary)
        except (FileNotFoundError, CompileError) as error:
            print(f"error: {error}", file=sys.stderr)
            return 1
        return 0
    if args.command is None:
        parser.error("a command is needed: build (or --version)")
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
