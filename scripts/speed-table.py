#!/usr/bin/env python3
"""Markdown table of the libraries' speed figures (docs/results/qp.md) from the JSON files that measured them:
`mft-qp bench DIR --json` (cold and --warm), `mft-bench --benchmark_out=F --benchmark_out_format=json` and
`mft-wakeup --rt --json` (the machine's floor in the same session). Each file is told by its content, so the
order does not matter. Test docs_results_pages regenerates the page's block from the files it cites."""
import argparse
import json
import sys
from pathlib import Path

HEADER = ["| what | measured by | mean [µs] | p50 | p99 | max | target | met |",
          "|---|---|---|---|---|---|---|---|"]


def classify(paths):
    files = {}
    for p in paths:
        d = json.loads(Path(p).read_text())
        kind = ("bench" if "benchmarks" in d else "wakeup" if "timer_late_us" in d
                else ("qp_warm" if d.get("warm") else "qp_cold") if "dir" in d else None)
        if kind is None or kind in files:
            raise ValueError(f"{p}: not one of mft-qp bench (cold, warm), mft-bench or mft-wakeup JSON, or a second one")
        files[kind] = d
    missing = {"qp_cold", "qp_warm", "bench", "wakeup"} - files.keys()
    if missing:
        raise ValueError(f"missing: {', '.join(sorted(missing))}")
    return files


def cells(mean, p50, p99, mx):
    return f"{mean:.2f} | {p50:.2f} | {p99:.2f} | {mx:.1f}"


def qp_row(what, source, d, mean_max=None, max_max=None):
    """A QP row; without targets (the warm start has none of its own) its target and verdict cells stay empty."""
    if mean_max is None:
        return f"| {what} | {source} | {cells(d['mean_us'], d['p50_us'], d['p99_us'], d['max_us'])} | — | — |"
    ok = d["failures"] == 0 and d["mean_us"] <= mean_max and d["max_us"] <= max_max
    return (f"| {what} | {source} | {cells(d['mean_us'], d['p50_us'], d['p99_us'], d['max_us'])} "
            f"| mean ≤ {mean_max}, max ≤ {max_max}, no failure | {'yes' if ok else '**no**'} |")


def bench_row(what, b, target, ok):
    return (f"| {what} | `{b['name'].split('/iterations')[0]}` | "
            f"{cells(b['mean_us'], b['p50_us'], b['p99_us'], b['max_us'])} | {target} | {'yes' if ok else '**no**'} |")


def table(paths):
    f = classify(paths)
    bench = {b["name"]: b for b in f["bench"]["benchmarks"]}
    model, sims = bench["BM_ModelUpdate"], [bench[f"BM_SimControlPeriod/{n}"] for n in (1, 2, 4)]
    rows = [qp_row(f"QP solve, the {f['qp_cold']['count']} instances of tests/data/qp, cold (min over "
                   f"{f['qp_cold']['passes']} passes)", "`mft-qp bench`", f["qp_cold"], 8, 25),
            qp_row("same, warm start", "`mft-qp bench --warm`", f["qp_warm"]),
            bench_row("full model update (M, h, all Jacobians)", model, "mean < 10", model["mean_us"] < 10)]
    for variant in ("Mft", "Sa", "None"):
        b = bench[f"BM_WbcTick{variant}/iterations:20000"]
        ok = b["failures"] == 0 and b["mean_us"] <= 50 and b["max_us"] <= 150
        rows.append(bench_row(f"whole WBC tick, `{variant.lower()}` (model, assembly, solve, eq. 7)", b,
                              "mean ≤ 50, max ≤ 150, no failure", ok))
    for n, b in zip((1, 2, 4), sims):
        rows.append(bench_row(f"one 1 ms simulator period, standing, {n} substep{'s' if n > 1 else ''} "
                              f"(×{b['rtf']:.1f} real time)", b, "≥ 30× real time at 1 substep",
                              n != 1 or b["rtf"] >= 30))
    late, wake = f["wakeup"]["timer_late_us"], f["wakeup"]["wakeup_us"]
    rt = " --rt" if f["wakeup"]["scheduling"] != "SCHED_OTHER" else ""
    floor = (f"- The machine's floor in the same session (`mft-wakeup{rt} --json`, "
             f"{f['wakeup']['scheduling']}): 1 kHz timer lateness p50 / p99 / max "
             + ", ".join(f"{k} {v['p50']:.0f} / {v['p99']:.0f} / {v['max']:.0f}" for k, v in sorted(late.items()))
             + f" µs; a thread wake-up p50 / p99 on one core {wake['same_core']['p50']:.1f} / "
             f"{wake['same_core']['p99']:.1f} µs, across cores {wake['cross_core']['p50']:.1f} / "
             f"{wake['cross_core']['p99']:.1f} µs.")
    ctx = f["bench"]["context"]
    when = f"- mft-bench ran {ctx['date']} on {ctx['num_cpus']} CPUs at {ctx['mhz_per_cpu']} MHz."
    return HEADER + rows + [floor, when]


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("files", nargs=4, help="mft-qp bench (cold), mft-qp bench --warm, mft-bench and mft-wakeup JSON")
    a = ap.parse_args()
    try:
        print("\n".join(table(a.files)))
    except (OSError, ValueError, KeyError) as e:
        print(f"speed-table: {e}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
