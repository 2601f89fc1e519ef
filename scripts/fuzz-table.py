#!/usr/bin/env python3
"""The fuzzing table of docs/results/fuzzing.md, made of `scripts/fuzz.sh TARGET SECONDS --json` outputs.

Each FILE holds one JSON object per line (one fuzz.sh run each, in any order); the table has a row per run,
in the order of the files and lines. Execution rates depend on the machine's load, so each row carries the
1-minute load average at the run's start and end and the commit it fuzzed."""
import argparse
import json
import re
import sys


def runs(paths):
    """Every run object of the files, in order."""
    out = []
    for path in paths:
        with open(path, encoding="utf-8") as f:
            for n, line in enumerate(f, 1):
                if line.strip():
                    try:
                        out.append(json.loads(line))
                    except json.JSONDecodeError as e:
                        raise ValueError(f"{path}:{n}: not a fuzz.sh --json line ({e})") from e
    return out


def grouped(x):
    return f"{x:,.0f}".replace(",", " ")


def row(r):
    rate = r["executions"] / r["seconds"] if r["seconds"] else 0.0
    finding = re.sub(r"(?<![\w.])/\S*/", "", r["finding"])  # the source file's name, not the fuzzing checkout's path
    found = "none" if not r["crashers"] and not r["finding"] else f"{r['crashers']} crasher(s): {finding}"
    return (f"| `{r['target']}` | {r['seconds']} | {grouped(r['executions'])} | {grouped(rate)} | {r['corpus']} | "
            f"{r['cov']} / {r['ft']} | {found} | {r['commit']} | {r['started_utc']} | "
            f"{r['load_1min_start']:.1f} → {r['load_1min_end']:.1f} on {r['cores']} |")


def table(paths):
    """The table's lines."""
    lines = ["| target | run [s] | executions | per second | corpus | cov / ft | findings | commit | started (UTC) "
             "| load (1 min) |", "|---|---|---|---|---|---|---|---|---|---|"]
    return lines + [row(r) for r in runs(paths)]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("files", nargs="+", metavar="FILE", help="fuzz.sh --json output(s)")
    a = ap.parse_args()
    try:
        print("\n".join(table(a.files)))
    except (OSError, ValueError, KeyError) as e:
        print(f"fuzz-table: {e}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
