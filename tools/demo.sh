#!/usr/bin/env bash
# Installs dependencies, builds psc, then compiles the bundled game
# games/sokoban.txt into a plugin and plays it (CLI benchmark, Python rollout,
# its levels solved by psc solve, a scripted solution of its first level), then
# in the terminal with psc play.
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
echo "== psc $game -o out/sokoban.so  (the step-function plugin)"
mkdir -p out
build/cli/psc "$game" -o out/sokoban.so --target cpu
echo "== psc bench $game  (random play, one thread)"
build/cli/psc bench "$game" --level 0 --batch 1,256 --threads 1 --repeats 3
echo "== a random rollout through the Python package"
/usr/bin/python3 examples/random_rollout.py --game "$game" --steps 200
echo "== psc solve $game --all-levels  (shortest solutions, breadth-first)"
build/cli/psc solve "$game" --all-levels
echo "== psc play $game --scripted  (level 1's solution typed as arrow keys)"
printf '\x1b[D\x1b[D\x1b[A\x1b[C' | build/cli/psc play "$game" --level 0 --scripted
if [ -t 0 ] && [ -t 1 ]; then
  echo "== psc play $game  (arrow keys move, Q quits)"
  read -r -p "press Enter to play " _
  exec build/cli/psc play "$game"
fi
