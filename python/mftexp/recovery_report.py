"""recovery-map's outputs from its runs: the per-cell statistics (mftexp.wilson), table.md beside the paper's
Table II, map.json, heatmaps.png (phase x impulse per cell, coloured by outcome) and probability.png (the
recovery probability over the phases against impulse, both controllers per height and direction)."""
import json
from pathlib import Path

from .common import CONTROLLER_NAMES, pyplot, write_report
from .wilson import bootstrap, crossing, curve, wilson

# The paper's Table II (I_max [N s], push at the right lift-off, forward) and this project's on the stack with
# the paper's grid (docs/results/table-ii.md, Table II with the paper's setup).
PAPER_TABLE2 = {"sa": {0.38: 10.4, 0.40: 9.7, 0.42: 9.1, 0.44: 7.0, 0.46: 4.5},
                "mft": {0.38: 10.7, 0.40: 10.6, 0.42: 10.6, 0.44: 9.5, 0.46: 6.6}}
STACK_TABLE2 = {"sa": {0.38: 12.7, 0.40: 14.5, 0.42: 11.1, 0.44: 9.4, 0.46: 8.0},
                "mft": {0.38: 15.9, 0.40: 14.8, 0.42: 13.3, 0.44: 13.0, 0.46: 13.3}}
OUTCOME_COLOURS = {"recovered": "#2ca02c", "drifting": "#ff7f0e", "fell": "#d62728", "not run": "#dddddd"}


def first_failure_imax(row, impulses):
    """The paper's I_max on a row ({impulse: recovered}): the last impulse before the first failure (None: the
    first failed; the last run impulse when none failed)."""
    last = None
    for i in impulses:
        if i not in row:
            break
        if not row[i]:
            return last
        last = i
    return last


def cell_stats(runs, impulses, labels, bootstrap_samples=2000):
    """Statistics of one (height, controller, direction) from its runs."""
    rows = {lab: {} for lab in labels}
    causes = {}
    for d in runs:
        rows[d["phase"]][d["impulse_Ns"]] = d["recovered"]
        key = d["outcome"] + (f": {d['how']}" if d.get("how") else "")
        causes[key] = causes.get(key, 0) + 1
    top = max((i for d in runs for i in [d["impulse_Ns"]]), default=impulses[0])
    grid = [i for i in impulses if i <= top + 1e-9]
    probs = curve(list(rows.values()), grid)
    n = len(labels)
    per_phase = {lab: {"i_max_Ns": first_failure_imax(rows[lab], grid),
                       "largest_recovered_Ns": max([i for i, ok in rows[lab].items() if ok], default=None),
                       "runs": len(rows[lab])} for lab in labels}
    out = {"impulses_Ns": grid, "probability": [round(p, 4) for p in probs],
           "wilson95": [[round(x, 4) for x in wilson(round(p * n), n)] for p in probs], "phases": n,
           "per_phase": per_phase, "outcomes": dict(sorted(causes.items(), key=lambda kv: -kv[1]))}
    for level, name in ((0.5, "i50"), (0.9, "i90")):
        c = crossing(grid, probs, level)
        lo, hi = bootstrap(list(rows.values()), grid, level, samples=bootstrap_samples)
        out[f"{name}_Ns"] = None if c is None else round(c, 3)
        out[f"{name}_ci95_Ns"] = [lo, hi]
    return out


def build_report(m, runs):
    labels = [p[0] for p in m.points]
    cells = []
    for h in m.args.heights:
        for c in m.args.controllers:
            for d in m.args.directions:
                mine = [r for r in runs if (r["height"], r["controller"], r["direction"]) == (h, c, d)]
                if mine:
                    cells.append(dict({"height": h, "controller": c, "direction": d},
                                      **cell_stats(mine, m.impulses, labels, m.args.bootstrap)))
    return {"phases": [{"label": p[0], "cycle_u": p[1], "stance": p[2], "planner_phase": p[3]} for p in m.points],
            "grid_Ns": [m.args.start, m.args.step, m.args.max_impulse], "stop_after_Ns": m.args.stop_after,
            "runner": "inprocess" if m.inprocess else "stack", "runs": len(runs), "cells": cells, "out": str(m.out)}


def fmt(x, unit=""):
    return "-" if x is None else f"{x:.2f}{unit}"


def fmt_ci(ci):
    return "-" if ci[0] is None else f"[{ci[0]:.2f}, {ci[1]:.2f}]"


def table_lines(report):
    lines = [f"# recovery-map: {report['runs']} runs ({report['runner']}), impulses from {report['grid_Ns'][0]:g} N s "
             f"by {report['grid_Ns'][1]:g} N s, {len(report['phases'])} phases per gait cycle", "",
             "I_50 / I_90: where the recovery probability over the phases falls below 50 % / 90 % (linear between "
             "grid points; bootstrap 95 % interval over the phases). I_max at lift-off: the paper's statistic at its "
             "push (the right foot's lift-off, forward), beside the paper's Table II and this project's on the stack "
             "(0.1 N s grid).", "",
             "| height [m] | controller | direction | I_50 [N s] (95 %) | I_90 [N s] (95 %) | I_max at lift-off | "
             "min / median / max I_max over phases | largest recovered | Table II paper / stack |",
             "|---|---|---|---|---|---|---|---|---|"]
    for s in report["cells"]:
        imaxes = sorted(v["i_max_Ns"] if v["i_max_Ns"] is not None else 0.0 for v in s["per_phase"].values())
        lift = s["per_phase"].get("liftoff", {}).get("i_max_Ns")
        largest = max((v["largest_recovered_Ns"] or 0.0) for v in s["per_phase"].values())
        t2 = "-"
        if s["direction"] == "forward" and s["controller"] in PAPER_TABLE2:
            t2 = f"{fmt(PAPER_TABLE2[s['controller']].get(s['height']))} / {fmt(STACK_TABLE2[s['controller']].get(s['height']))}"
        lines.append(f"| {s['height']:.2f} | {CONTROLLER_NAMES.get(s['controller'], s['controller'])} | {s['direction']} "
                     f"| {fmt(s['i50_Ns'])} {fmt_ci(s['i50_ci95_Ns'])} | {fmt(s['i90_Ns'])} {fmt_ci(s['i90_ci95_Ns'])} "
                     f"| {fmt(lift)} | {imaxes[0]:.2f} / {imaxes[len(imaxes) // 2]:.2f} / {imaxes[-1]:.2f} "
                     f"| {largest:.2f} | {t2} |")
    lines += ["", "Outcomes by cause (all runs of the cell):", ""]
    for s in report["cells"]:
        causes = ", ".join(f"{k} {v}" for k, v in s["outcomes"].items())
        lines.append(f"- {s['height']:.2f} m {CONTROLLER_NAMES.get(s['controller'], s['controller'])} "
                     f"{s['direction']}: {causes}")
    lines += ["", "I_max per phase (last impulse before the first failure; '<' = the first impulse failed):", "",
              "| height | controller | direction | " + " | ".join(p["label"] for p in report["phases"]) + " |",
              "|---|---|---|" + "---|" * len(report["phases"])]
    for s in report["cells"]:
        vals = [fmt(s["per_phase"][p["label"]]["i_max_Ns"]) if s["per_phase"][p["label"]]["i_max_Ns"] is not None
                else f"< {report['grid_Ns'][0]:g}" for p in report["phases"]]
        lines.append(f"| {s['height']:.2f} | {s['controller']} | {s['direction']} | " + " | ".join(vals) + " |")
    return lines


def plot_heatmaps(path, report, runs):
    plt = pyplot()
    from matplotlib.colors import ListedColormap
    cells = report["cells"]
    labels = [p["label"] for p in report["phases"]]
    cols = 2 if len(cells) > 1 else 1
    nrows = (len(cells) + cols - 1) // cols
    fig, axes = plt.subplots(nrows, cols, figsize=(7 * cols, 2.2 + 0.28 * len(labels) * nrows), squeeze=False)
    order = list(OUTCOME_COLOURS)
    cmap = ListedColormap([OUTCOME_COLOURS[k] for k in order])
    grid = max((s["impulses_Ns"] for s in cells), key=len)  # one impulse axis for every cell
    for ax, s in zip(axes.flat, cells):
        z = [[order.index("not run")] * len(grid) for _ in labels]
        for d in runs:
            if (d["height"], d["controller"], d["direction"]) == (s["height"], s["controller"], s["direction"]) \
                    and d["impulse_Ns"] in grid:
                z[labels.index(d["phase"])][grid.index(d["impulse_Ns"])] = order.index(
                    d["outcome"] if d["outcome"] in OUTCOME_COLOURS else "fell")
        step = grid[1] - grid[0] if len(grid) > 1 else 1.0
        ax.imshow(z, aspect="auto", cmap=cmap, vmin=0, vmax=len(order) - 1, interpolation="nearest",
                  extent=(grid[0] - step / 2, grid[-1] + step / 2, len(labels) - 0.5, -0.5))
        ax.set_yticks(range(len(labels)))
        ax.set_yticklabels(labels, fontsize=7)
        ax.set_title(f"{s['height']:.2f} m, {CONTROLLER_NAMES.get(s['controller'], s['controller'])}, {s['direction']}",
                     fontsize=9)
        ax.set_xlabel("impulse [N s]", fontsize=8)
    for ax in list(axes.flat)[len(cells):]:
        ax.axis("off")
    for k in order:
        axes.flat[0].plot([], [], "s", color=OUTCOME_COLOURS[k], label=k)
    fig.legend(loc="lower center", ncol=len(order), fontsize=8, frameon=False)
    fig.tight_layout(rect=(0, 0.04, 1, 1))
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path


def plot_probability(path, report):
    plt = pyplot()
    heights = sorted({s["height"] for s in report["cells"]})
    dirs = sorted({s["direction"] for s in report["cells"]}, reverse=True)
    fig, axes = plt.subplots(len(dirs), len(heights), figsize=(4.2 * len(heights), 3.2 * len(dirs)), squeeze=False)
    colours = {"mft": "tab:blue", "sa": "tab:red", "none": "tab:gray"}
    for s in report["cells"]:
        ax = axes[dirs.index(s["direction"])][heights.index(s["height"])]
        x = s["impulses_Ns"]
        col = colours.get(s["controller"], "k")
        ax.plot(x, s["probability"], "-", color=col, label=CONTROLLER_NAMES.get(s["controller"], s["controller"]))
        ax.fill_between(x, [w[0] for w in s["wilson95"]], [w[1] for w in s["wilson95"]], color=col, alpha=0.2, lw=0)
        ax.set_title(f"{s['height']:.2f} m, pushed {s['direction']}", fontsize=9)
        ax.set_ylim(-0.03, 1.03)
        ax.set_xlabel("impulse [N s]", fontsize=8)
        ax.set_ylabel("recovered (over phases)", fontsize=8)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path


def write_outputs(m, runs, t0):
    report = build_report(m, runs)
    out = m.out
    (out / "table.md").write_text("\n".join(table_lines(report)) + "\n")
    plot_heatmaps(out / "heatmaps.png", report, runs)
    png = plot_probability(out / "probability.png", report)
    report["heatmaps"] = str(out / "heatmaps.png")
    write_report(out / "map.json", report, png, t0, m.args.json)
    if not m.args.json:
        print((out / "table.md").read_text(), end="")
    return 0


def load_report(path):
    return json.loads(Path(path).read_text())
