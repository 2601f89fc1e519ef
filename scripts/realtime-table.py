#!/usr/bin/env python3
"""Markdown rows of the figures of measure-stack.py JSON files, one row per file: the realtime run's (default) or,
with --lockstep, the lockstep rounds' (speed ratio to the in-process run, recording cost); with --stages, the
realtime run's chain stage by stage, one column per file; with --targets, the realtime targets and how many of the
runs met each. docs/results pages quote
these rows; test docs_results_pages regenerates them from the files the page cites."""
import argparse
import json
import sys
from pathlib import Path

HEADER = ["| run | sensor → command p50 / p99 / p99.9 / max [µs] | timer lateness p99 on the chain's CPU "
          "(other CPU) [µs] | p99 over the timer's | WBC tick p99 realtime / lockstep [µs] | simulator misses "
          "(not in a CPU stall) | load before → after |",
          "|---|---|---|---|---|---|---|"]


def chain_timer_p99(d):
    """The timer lateness p99 of the chain's CPU in run D (of the worst CPU when the chain was not pinned)."""
    late, cpu = d["machine_wakeup"]["timer_late_us"], d["realtime"].get("chain_cpu")
    return late[f"cpu{cpu}"]["p99"] if cpu is not None else max(v["p99"] for v in late.values())


def wbc_lockstep_p99(d):
    """The WBC's compute p99 in run D's first lockstep round set (the realtime tick's reference)."""
    lock = next(iter(d["lockstep"].values()))
    return next(i for i in lock["hop_table"]["intervals"] if i["interval"] == "WBC compute")["p99"]


def row(path):
    d = json.loads(Path(path).read_text())
    rt = d["realtime"]
    s, w = rt["sensor_to_command_latency_us"], rt["wbc_tick_us"]
    late, cpu = d["machine_wakeup"]["timer_late_us"], rt.get("chain_cpu")
    mine = chain_timer_p99(d)
    others = ", ".join(f"{v['p99']:.0f}" for k, v in sorted(late.items()) if cpu is None or k != f"cpu{cpu}")
    return (f"| {Path(path).stem} | {s['p50']:.0f} / {s['p99']:.0f} / {s.get('p99_9', float('nan')):.0f} / "
            f"{s['max']:.0f} | {mine:.0f} ({others}) | {s['p99'] - mine:+.0f} | "
            f"{w['p99']:.0f} / {wbc_lockstep_p99(d):.0f} "
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


# The realtime loop's targets: the chain's sensor-to-command p99 close to the machine's own floor (the timer lateness
# of the chain's CPU in the same run) or small outright, and the WBC's tick not inflated by running in realtime.
TARGET_P99_US = 250.0
TARGET_P99_OVER_TIMER_US = 150.0
TARGET_WBC_TICK_RATIO = 2.0


def target_figures(path):
    """(p99, p99 over the chain CPU's timer p99, WBC tick p99 realtime / lockstep, misses, misses outside a stall)."""
    d = json.loads(Path(path).read_text())
    rt = d["realtime"]
    p99 = rt["sensor_to_command_latency_us"]["p99"]
    return (p99, p99 - chain_timer_p99(d), rt["wbc_tick_us"]["p99"] / wbc_lockstep_p99(d), rt["sim_deadline_misses"],
            rt["sim_misses_unexplained"])


def targets_table(paths):
    """The targets, and per target how many of the runs in PATHS met it, with the range of the figure."""
    runs = {Path(p).stem: target_figures(p) for p in paths}
    latency_met = [n for n, f in runs.items() if f[0] <= TARGET_P99_US or f[1] <= TARGET_P99_OVER_TIMER_US]
    wbc_met = [n for n, f in runs.items() if f[2] <= TARGET_WBC_TICK_RATIO]
    missed = [n for n in runs if n not in wbc_met]

    def span(i, fmt):
        values = [f[i] for f in runs.values()]
        return f"{fmt.format(min(values))}–{fmt.format(max(values))}"

    return ["| target | runs that met it |", "|---|---|",
            f"| sensor → command p99 at most {TARGET_P99_US:.0f} µs, or at most {TARGET_P99_OVER_TIMER_US:.0f} µs "
            f"above the timer lateness p99 of the chain's CPU in the same run | {len(latency_met)} of {len(runs)} (p99 "
            f"{span(0, '{:.0f}')} µs; over the timer's {span(1, '{:+.0f}')} µs) |",
            f"| the WBC's tick p99 in realtime at most {TARGET_WBC_TICK_RATIO:g} times its lockstep p99 | "
            f"{len(wbc_met)} of {len(runs)} (ratio {span(2, '{:.2f}')}" + (f"; not met: {', '.join(missed)}" if missed
                                                                            else "") + ") |",
            f"| (no target) simulator deadline misses, told apart by the stall probe | "
            f"{sum(f[3] for f in runs.values())} in all, {sum(f[4] for f in runs.values())} of them not in a CPU "
            f"stall |"]


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("files", nargs="+", help="JSON files written by scripts/measure-stack.py --json")
    ap.add_argument("--lockstep", action="store_true", help="the lockstep rounds' row instead of the realtime run's")
    ap.add_argument("--stages", action="store_true", help="the realtime run's chain stage by stage (p50 / p99 of "
                    "each hop-table interval), one column per file")
    ap.add_argument("--targets", action="store_true", help="the realtime targets and how many of the runs met each")
    a = ap.parse_args()
    kind = lockstep_table if a.lockstep else stages_table if a.stages else targets_table if a.targets else table
    try:
        print("\n".join(kind(a.files)))
    except (OSError, ValueError, KeyError, StopIteration) as e:
        print(f"realtime-table: {e}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
