#!/usr/bin/python3
"""Every game of the corpus that psc compiles must give CUDA source that NVRTC
accepts (`psc check --cuda`: NVRTC's front end, no GPU needed).

    cuda_sources.py PSC CORPUS [--jobs N]

Games are taken once each (by text) from every trace and every errors case.
A game with errors fails `psc check` before any CUDA is made; those are
counted apart (the front-end tests judge them), not as passes.  A game whose
check runs past SECONDS_A_GAME fails."""
import argparse
import concurrent.futures
import hashlib
import json
import os
import subprocess
import sys
import tempfile

SECONDS_A_GAME = 60


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("psc")
    ap.add_argument("corpus")
    ap.add_argument("--jobs", type=int, default=os.cpu_count() or 2)
    a = ap.parse_args()
    games = {}
    for entry in json.load(open(os.path.join(a.corpus, "INDEX.json"))):
        text = json.load(open(os.path.join(a.corpus, entry["path"])))["game"]
        games.setdefault(hashlib.sha1(text.encode()).hexdigest(), text)
    with tempfile.TemporaryDirectory() as tmp:
        def check(item):
            key, text = item
            path = os.path.join(tmp, key + ".txt")
            with open(path, "w") as f:
                f.write(text)
            # A bound far past any game's time, to catch a hang or a blow-up, not to time the games: the
            # slowest (trains-love-snowmen, rules as a table) takes 3.7 s on a 2-core machine, and W3RDS
            # took 110 s while code generation was quadratic in its 3,258 rule groups (e242e44 to 79219d4).
            try:
                r = subprocess.run([a.psc, "check", path, "--cuda"], capture_output=True, text=True,
                                   timeout=SECONDS_A_GAME, env=dict(os.environ, PSC_COMPILE_TIMEOUT=str(SECONDS_A_GAME - 5)))
            except subprocess.TimeoutExpired:
                return key, None, f"psc check --cuda ran past {SECONDS_A_GAME} s"
            return key, r.returncode, r.stderr

        compiled = has_errors = 0
        failures = []
        with concurrent.futures.ThreadPoolExecutor(a.jobs) as pool:
            for key, code, err in pool.map(check, sorted(games.items())):
                if code == 0:
                    compiled += 1
                elif "generated CUDA source does not compile" in err or code != 1:
                    failures.append(key)
                    print(f"FAIL {key}: {err[-1500:]}")
                else:
                    has_errors += 1
    print(f"{len(games)} games: CUDA source compiles for {compiled}, fails for {len(failures)}; "
          f"{has_errors} have errors (no CUDA made)")
    sys.exit(1 if failures or compiled == 0 else 0)


if __name__ == "__main__":
    main()
