#!/usr/bin/env python3
"""Where a tick's time goes: the per-hop table of one traced run (docs/results/loop-benchmark.md).

Reads the <service>.hops.csv files that the services write when MFT_HOP_TRACE names a folder
(`MFT_HOP_TRACE=DIR services/mft-supervisor run ...`, or scripts/measure-stack.py) and splits each tick
of the critical path sim -> estimator -> planner -> WBC -> sim into consecutive intervals (their sum is the
tick): mean, p50, p99 and max in microseconds over the ticks traced (the first --skip ticks left out: start-up).
With --realtime the table ends where the command reaches the simulator: in realtime the simulator's loop waits
for its 1 kHz timer, not for the command, so the sum is the sensor-to-command latency, not the tick.
"""
import argparse
import csv
import json
import statistics
import sys
from pathlib import Path

SERVICES = ("mft-sim", "mft-estimator", "mft-planner", "mft-wbc")
# (name, from (service, mark), to (service, mark), to on the next tick): consecutive, so they add up to the tick.
INTERVALS = [
    ("sim writes SensorData and GroundTruth -> estimator has it", ("mft-sim", "publish"), ("mft-estimator", "sensor_in"), False),
    ("estimator compute", ("mft-estimator", "sensor_in"), ("mft-estimator", "write"), False),
    ("estimator writes RobotState -> planner has it", ("mft-estimator", "write"), ("mft-planner", "state_in"), False),
    ("planner compute", ("mft-planner", "state_in"), ("mft-planner", "write"), False),
    ("planner writes Reference -> WBC starts (holds both inputs)", ("mft-planner", "write"), ("mft-wbc", "compute"), False),
    ("WBC compute", ("mft-wbc", "compute"), ("mft-wbc", "write"), False),
    ("WBC writes JointCommand -> sim has it", ("mft-wbc", "write"), ("mft-sim", "command_in"), False),
    # the realtime table ends here (CHAIN_INTERVALS)
    ("sim reader -> sim loop thread (hand-off; none on the chain channel)", ("mft-sim", "command_in"), ("mft-sim", "wake"), False),
    ("sim physics step", ("mft-sim", "wake"), ("mft-sim", "stepped"), False),
    ("sim bookkeeping, message conversion", ("mft-sim", "stepped"), ("mft-sim", "publish"), True),
]
CHAIN_INTERVALS = INTERVALS[:7]  # from SensorData(k) leaving to JointCommand(k) arriving
# The intervals that carry a sample from one process to the next (the others are a service's own compute).
TRANSPORT_HOPS = [INTERVALS[i][0] for i in (0, 2, 4, 6)]
# Informational: the writer's own cost of a write (serialization, the send calls, waking the reader).
WRITE_COSTS = [
    ("sim: write SensorData+GroundTruth (sender's cost)", ("mft-sim", "publish"), ("mft-sim", "published")),
    ("estimator: write RobotState", ("mft-estimator", "write"), ("mft-estimator", "written")),
    ("planner: write Reference", ("mft-planner", "write"), ("mft-planner", "written")),
    ("WBC: write JointCommand", ("mft-wbc", "write"), ("mft-wbc", "written")),
]


def load(run_dir):
    tables = {}
    for s in SERVICES:
        path = Path(run_dir) / f"{s}.hops.csv"
        if not path.exists():
            raise FileNotFoundError(2, "no hop trace (was the run started with MFT_HOP_TRACE?)", str(path))
        with open(path, newline="") as f:
            tables[s] = {int(row["tick"]): {k: int(v) for k, v in row.items() if k != "tick"} for row in csv.DictReader(f)}
    return tables


def stats(values_us):
    v = sorted(values_us)
    if not v:
        return {"count": 0}
    p = lambda q: v[min(len(v) - 1, int(q * len(v)))]
    return {"count": len(v), "mean": round(statistics.fmean(v), 2), "min": round(v[0], 2), "p50": round(p(0.5), 2),
            "p99": round(p(0.99), 2), "p99_9": round(p(0.999), 2), "max": round(v[-1], 2)}


def hop_table(run_dir, skip=100, realtime=False):
    """The per-tick split; realtime=True: the chain from the sensor sample to the command only (CHAIN_INTERVALS),
    whose sum per tick ("tick_us") is then the sensor-to-command latency."""
    t = load(run_dir)
    ticks = sorted(k for k in t["mft-sim"] if k >= skip and k + 1 in t["mft-sim"])
    if not ticks:
        raise ValueError(f"{run_dir}: no traced tick after the first {skip}")

    def stamp(service, mark, k):
        v = t[service].get(k, {}).get(mark, 0)
        return v or None

    rows = []
    per_tick_total = []
    for name, (sa, ma), (sb, mb), next_tick in (CHAIN_INTERVALS if realtime else INTERVALS):
        vals = []
        for k in ticks:
            a, b = stamp(sa, ma, k), stamp(sb, mb, k + 1 if next_tick else k)
            if a is not None and b is not None:
                vals.append((b - a) * 1e-3)
        rows.append({"interval": name, **stats(vals)})
    for k in ticks:
        a, b = stamp("mft-sim", "publish", k), stamp("mft-sim", "command_in", k) if realtime else stamp("mft-sim", "publish", k + 1)
        if a is not None and b is not None:
            per_tick_total.append((b - a) * 1e-3)
    writes = []
    for name, (sa, ma), (sb, mb) in WRITE_COSTS:
        vals = [(stamp(sb, mb, k) - stamp(sa, ma, k)) * 1e-3 for k in ticks
                if stamp(sa, ma, k) is not None and stamp(sb, mb, k) is not None]
        writes.append({"interval": name, **stats(vals)})
    return {"ticks": len(ticks), "realtime": realtime, "tick_us": stats(per_tick_total), "intervals": rows,
            "write_costs": writes}


def print_table(table, out=sys.stdout):
    what = "sensor to command (realtime)" if table.get("realtime") else "per tick"
    print(f"{table['ticks']} ticks; {what}: mean {table['tick_us']['mean']} us, p50 {table['tick_us']['p50']}, "
          f"p99 {table['tick_us']['p99']}, max {table['tick_us']['max']}", file=out)
    print(f"| {'interval':62} | mean | p50 | p99 | max |", file=out)
    print(f"|{'-' * 64}|---|---|---|---|", file=out)
    for r in table["intervals"] + [{"interval": "(write costs, inside the intervals above)"}] + table["write_costs"]:
        if "mean" not in r:
            print(f"| {r['interval']:62} | | | | |", file=out)
            continue
        print(f"| {r['interval']:62} | {r['mean']:.1f} | {r['p50']:.1f} | {r['p99']:.1f} | {r['max']:.0f} |", file=out)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("run_dir", help="the folder MFT_HOP_TRACE named for the run")
    ap.add_argument("--skip", type=int, default=100, help="leave out the first N ticks (start-up; default 100)")
    ap.add_argument("--realtime", action="store_true", help="a realtime run: the chain from the sensor sample to the "
                    "command only (the simulator's loop waits for its timer, not for the command)")
    ap.add_argument("--json", action="store_true", help="print the table as JSON")
    args = ap.parse_args()
    if args.skip < 0:
        print("hop-table.py: error: --skip must be >= 0", file=sys.stderr)
        sys.exit(2)
    try:
        table = hop_table(args.run_dir, args.skip, args.realtime)
    except (OSError, ValueError, KeyError) as e:
        print(f"hop-table.py: error: {getattr(e, 'strerror', None) or e}"
              f"{': ' + str(e.filename) if getattr(e, 'filename', None) else ''}", file=sys.stderr)
        sys.exit(2)
    if args.json:
        print(json.dumps(table, indent=1))
    else:
        print_table(table)


if __name__ == "__main__":
    main()
