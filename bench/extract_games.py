#!/usr/bin/python3
"""Writes the 13 benchmark games (the corpus' humandata games) to bench/games/
(git-ignored: they are not psc's games) as <name>.txt."""
import glob
import json
import os
import sys

corpus = sys.argv[1] if len(sys.argv) > 1 else "../shared/corpus"
out = os.path.join(os.path.dirname(os.path.abspath(__file__)), "games")
os.makedirs(out, exist_ok=True)
seen = set()
for path in sorted(glob.glob(os.path.join(corpus, "scraped", "sc-humandata-*.json"))):
    case = json.load(open(path))
    name = case["id"][len("sc-humandata-"):].rsplit("-L", 1)[0]
    if name in seen:
        continue
    seen.add(name)
    with open(os.path.join(out, name + ".txt"), "w") as f:
        f.write(case["game"])
print(f"{len(seen)} games in {out}: {', '.join(sorted(seen))}")
