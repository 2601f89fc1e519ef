#!/usr/bin/env python3
"""Markdown rows of the figures of measure-stack.py JSON files, one row per file: the realtime run's (default) or,
with --lockstep, the lockstep rounds' (speed ratio to the in-process run, recording cost); with --stages, the
realtime run's chain stage by stage, one column per file. docs/results pages quote
these rows; test docs_results_pages regenerates them from the files the page cites."""
import argparse
import json
import sys
from pathlib import Path

HEADER = ["| run | sensor → command p50 / p99 / p99.9 / max [µs] | timer lateness p99 on the chain's CPU "
          "(other CPU) [µs] | p99 over the timer's | WBC tick p99 realtime / lockstep [µs] | simulator misses "
          "(not in a CPU stall) | load before → after |",
          "|---|---|---|---|---|---|---|"]


def row(path):
    d = json.loads(Path(path).read_text())
    rt = d["realtime"]
    s, w = rt["sensor_to_command_latency_us"], rt["wbc_tick_us"]
    lock = next(iter(d["lockstep"].values()))
    wbc_lock = next(i for i in lock["hop_table"]["intervals"] if i["interval"] == "WBC compute")
    late = d["machine_wakeup"]["timer_late_us"]
    cpu = rt.get("chain_cpu")
    mine = late[f"cpu{cpu}"]["p99"] if cpu is not None else max(v["p99"] for v in late.values())
    others = ", ".join(f"{v['p99']:.0f}" for k, v in sorted(late.items()) if cpu is None or k != f"cpu{cpu}")
    return (f"| {Path(path).stem} | {s['p50']:.0f} / {s['p99']:.0f} / {s.get('p99_9', float('nan')):.0f} / "
            f"{s['max']:.0f} | {mine:.0f} ({others}) | {s['p99'] - mine:+.0f} | {w['p99']:.0f} / {wbc_lock['p99']:.0f} "
            f"| {rt['sim_deadline_misses']} ({rt['sim_misses_unexplained']}) | "
            f"{d['load_average_before']['1min']:.2f} → {d['load_average_after']['1min']:.2f} |")


def table(paths):
    return HEADER + [row(p) for p in paths]


LOCKSTEP_HEADER = ["| run | rounds | µs per tick lockstep / in process | speed ratio to in process, median (min–max) "
                   "| recording every topic: slowdown median (min–max) | samples dropped | timer lateness p99 per CPU "
                   "[µs] | load before → after |",
                   "|---|---|---|---|---|---|---|---|"]


def lockstep_row(path):
    d = json.loads(Path(path).read_text())
    lock, rec = next(iter(d["lockstep"].values())), d["recording"]
    ratios, slow = lock["ratio_to_inprocess_per_round"], rec["slowdown_per_round"]
    late = d.get("machine_wakeup", {}).get("timer_late_us", {})
    floor = ", ".join(f"{k} {v['p99']:.0f}" for k, v in sorted(late.items())) or "not measured"
    return (f"| {Path(path).stem} | {d['rounds']} | {lock['us_per_tick_median']:.1f} / "
            f"{d['inprocess']['us_per_tick_median']:.1f} | {lock['ratio_to_inprocess_median']:.3f} "
            f"({min(ratios):.3f}–{max(ratios):.3f}) | ×{rec['slowdown_median']:.3f} ({min(slow):.3f}–{max(slow):.3f}) "
            f"| {rec['dropped_samples']} | {floor} | "
            f"{d['load_average_before']['1min']:.2f} → {d['load_average_after']['1min']:.2f} |")


def lockstep_table(paths):
    return LOCKSTEP_HEADER + [lockstep_row(p) for p in paths]


def stages_table(paths):
    """The realtime run's chain stage by stage, one column per file: p50 / p99 of each interval of the hop table
    (from the sensor sample leaving the simulator to the command reaching it), then the writers' own costs."""
    runs = [json.loads(Path(p).read_text())["realtime"]["hop_table"] for p in paths]
    head = ["| interval, p50 / p99 [µs] | " + " | ".join(Path(p).stem for p in paths) + " |",
            "|---|" + "---|" * len(paths)]
    rows = []
    for key in ("intervals", "write_costs"):
        for i, item in enumerate(runs[0][key]):
            cells = [f"{r[key][i]['p50']:.0f} / {r[key][i]['p99']:.0f}" for r in runs]
            rows.append(f"| {item['interval']} | " + " | ".join(cells) + " |")
    rows.append("| sum: sensor → command | " + " | ".join(f"{r['tick_us']['p50']:.0f} / {r['tick_us']['p99']:.0f}"
                                                           for r in runs) + " |")
    return head + rows


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("files", nargs="+", help="JSON files written by scripts/measure-stack.py --json")
    ap.add_argument("--lockstep", action="store_true", help="the lockstep rounds' row instead of the realtime run's")
    ap.add_argument("--stages", action="store_true", help="the realtime run's chain stage by stage (p50 / p99 of "
                    "each hop-table interval), one column per file")
    a = ap.parse_args()
    try:
        print("\n".join((lockstep_table if a.lockstep else stages_table if a.stages else table)(a.files)))
    except (OSError, ValueError, KeyError, StopIteration) as e:
        print(f"realtime-table: {e}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
