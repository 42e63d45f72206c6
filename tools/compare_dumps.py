#!/usr/bin/python3
"""Compares two corpus_replay.py reports made with --dumps (e.g. CPU and GPU):
every case's verdict and the sha1 of its dumped states.

    tools/compare_dumps.py CPU_REPORT.json GPU_REPORT.json

Prints each case that differs and a summary; exits 1 if any differs."""
import json
import sys


def main():
    a, b = (json.load(open(p)) for p in sys.argv[1:3])
    left = {c["id"]: c for c in a["cases"]}
    right = {c["id"]: c for c in b["cases"]}
    same = differ = 0
    for cid in sorted(set(left) | set(right)):
        x, y = left.get(cid), right.get(cid)
        if x and y and x["status"] == y["status"] and x["dump_sha1"] and x["dump_sha1"] == y["dump_sha1"]:
            same += 1
            continue
        differ += 1
        print(f"DIFFER {cid}: {a.get('backend')} {x and x['status']} {x and x['dump_sha1']} / "
              f"{b.get('backend')} {y and y['status']} {y and y['dump_sha1']}")
    print(f"{a.get('suite')}: {same} cases with identical states on {a.get('backend')} and {b.get('backend')}, {differ} differ")
    sys.exit(1 if differ else 0)


if __name__ == "__main__":
    main()
