"""Writes the distinct game texts of the reference corpus (every suite, the
error cases included) into a folder, one file per game, as fuzzing seeds.

Usage: seed_corpus.py CORPUS_DIR OUT_DIR [--sample N]
--sample N keeps N games, the same ones every time (by their sha1), for short runs."""
import argparse
import hashlib
import json
import os


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("corpus")
    ap.add_argument("out")
    ap.add_argument("--sample", type=int, default=0)
    args = ap.parse_args()
    games = {}
    for suite in ("testsuite", "scraped", "errors"):
        folder = os.path.join(args.corpus, suite)
        if not os.path.isdir(folder):
            continue
        for name in sorted(os.listdir(folder)):
            if not name.endswith(".json"):
                continue
            with open(os.path.join(folder, name), encoding="utf-8") as f:
                text = json.load(f).get("game")
            if isinstance(text, str):
                data = text.encode("utf-8")
                games[hashlib.sha1(data).hexdigest()] = data
    keys = sorted(games)
    if args.sample > 0:
        keys = keys[: args.sample]
    os.makedirs(args.out, exist_ok=True)
    for key in keys:
        with open(os.path.join(args.out, key + ".txt"), "wb") as f:
            f.write(games[key])
    print(f"{len(keys)} seed games of {len(games)} in {args.out}")


if __name__ == "__main__":
    main()
