#!/usr/bin/env bash
# Installs dependencies, builds psc and runs it on a bundled game.
set -euo pipefail
cd "$(dirname "$0")/.."

tools/install-deps.sh
cmake --preset default >/dev/null
cmake --build --preset default -j "$(nproc)"

game=games/sokoban.txt
echo "== psc check $game"
build/cli/psc check "$game" && echo "ok"
echo "== psc $game --emit ir"
build/cli/psc "$game" --emit ir
