"""Table II (Markdown, CSV) and the sweep plot from the cell lines of results.jsonl."""
import csv
from pathlib import Path

from .common import PAPER_TABLE2, pyplot


def imax_text(cell, start, max_impulse):
    if cell is None:
        return "–"
    if cell["status"] == "below_start":
        return f"< {start:g}"
    if cell["status"] == "at_max":
        return f"≥ {max_impulse:g}"
    return f"{cell['i_max_Ns']:.1f}"


def increase_pct(sa, mft):
    if not sa or not mft or sa["i_max_Ns"] is None or mft["i_max_Ns"] is None:
        return None
    if sa["status"] != "ok" or mft["status"] != "ok":
        return None
    return round(100.0 * (mft["i_max_Ns"] - sa["i_max_Ns"]) / sa["i_max_Ns"], 1)


def ratio(sa, mft):
    """I_max(MFT-WBC) / I_max(SA-WBC), None unless both cells found their boundary."""
    inc = increase_pct(sa, mft)
    return None if inc is None else round(mft["i_max_Ns"] / sa["i_max_Ns"], 3)


def rows(results, heights, direction, variant="default"):
    out = []
    for h in heights:
        sa = results.cells.get((variant, h, "sa", direction))
        mft = results.cells.get((variant, h, "mft", direction))
        out.append((h, sa, mft, increase_pct(sa, mft)))
    return out


def above_text(cell):
    a = (cell or {}).get("recovered_above_Ns") or []
    return ", ".join(f"{x:g}" for x in a)


def write_tables(out_dir, results, heights, controllers, direction, grid, setup, wall_s=None, load=None):
    out_dir = Path(out_dir)
    table = rows(results, heights, direction)
    # CSV: one row per height (the machine-readable form of Table II)
    with open(out_dir / "table.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["height_m", "sa_imax_Ns", "mft_imax_Ns", "mft_sa_ratio", "increase_pct", "sa_status", "mft_status",
                    "sa_bracket_Ns", "mft_bracket_Ns", "sa_recovered_above_Ns", "mft_recovered_above_Ns",
                    "paper_sa_imax_Ns", "paper_mft_imax_Ns", "paper_mft_sa_ratio", "paper_increase_pct"])
        for h, sa, mft, inc in table:
            p = PAPER_TABLE2.get(round(h, 2), {})
            br = lambda c: "" if c is None else f"{c['recovered_Ns'] if c['recovered_Ns'] is not None else ''}/" \
                                                f"{c['failed_Ns'] if c['failed_Ns'] is not None else ''}"
            w.writerow([f"{h:.2f}",
                        "" if sa is None or sa["i_max_Ns"] is None else f"{sa['i_max_Ns']:.2f}",
                        "" if mft is None or mft["i_max_Ns"] is None else f"{mft['i_max_Ns']:.2f}",
                        "" if inc is None else f"{ratio(sa, mft):.3f}", "" if inc is None else f"{inc:.1f}",
                        "" if sa is None else sa["status"], "" if mft is None else mft["status"], br(sa), br(mft),
                        above_text(sa).replace(", ", " "), above_text(mft).replace(", ", " "),
                        p.get("sa", ""), p.get("mft", ""), f"{p['mft'] / p['sa']:.3f}" if p else "",
                        p.get("increase_pct", "")])
    lines = table_lines(table, grid, setup, direction, wall_s, load)
    (out_dir / "table.md").write_text("\n".join(lines) + "\n")
    return table


def table_from_summary(summary):
    """The arguments of table_lines from the summary.json push-sweep writes (a results file of the docs)."""
    table = [(row["height_m"], row["sa"], row["mft"], row["increase_pct"]) for row in summary["table"]]
    return table, summary["grid"], summary["setup"], summary["setup"]["direction"]


def table_lines(table, grid, setup, direction, wall_s=None, load=None):
    """table.md's lines: Table II in the paper's layout, the paper's rows, each cell's boundary, the setup."""
    start, mx = grid["start_Ns"], grid["max_Ns"]
    # heights across, SA, MFT, increase down; then the paper's rows
    hs = " | ".join(f"{h:.2f}" for h, *_ in table)
    lines = [f"Results of push-recovery tests ({direction} push at a {setup['liftoff']}-foot lift-off, "
             f"grid {start:g} + k·{grid['step_Ns']:g} N s, search {grid['search']})", "",
             f"| z_B^ref [m] | {hs} |", "|---" * (len(table) + 1) + "|",
             "| I_max of SA-WBC [N s] | " + " | ".join(imax_text(sa, start, mx) for _, sa, _, _ in table) + " |",
             "| I_max of MFT-WBC [N s] | " + " | ".join(imax_text(m, start, mx) for _, _, m, _ in table) + " |",
             "| MFT/SA ratio | " + " | ".join("–" if i is None else f"{ratio(sa, m):.2f}" for _, sa, m, i in table) + " |",
             "| Percentage of increase [%] | " + " | ".join("–" if i is None else f"{i:+.1f}" for *_, i in table) + " |",
             "| paper: I_max of SA-WBC [N s] | " + " | ".join(str(PAPER_TABLE2.get(round(h, 2), {}).get("sa", "–"))
                                                          for h, *_ in table) + " |",
             "| paper: I_max of MFT-WBC [N s] | " + " | ".join(str(PAPER_TABLE2.get(round(h, 2), {}).get("mft", "–"))
                                                           for h, *_ in table) + " |",
             "| paper: MFT/SA ratio | " + " | ".join(
                 (lambda p: f"{p['mft'] / p['sa']:.2f}" if p else "–")(PAPER_TABLE2.get(round(h, 2)))
                 for h, *_ in table) + " |",
             "| paper: percentage of increase [%] | " + " | ".join(
                 str(PAPER_TABLE2.get(round(h, 2), {}).get("increase_pct", "–")) for h, *_ in table) + " |", ""]
    lines.append("Boundary of each cell (I_max / first failure [N s], recoveries above the first failure, runs, "
                 "the first failure's reason):")
    lines.append("")
    for h, sa, mft, _ in table:
        for name, c in (("SA-WBC", sa), ("MFT-WBC", mft)):
            if c is None:
                continue
            ff = c.get("first_failure") or {}
            lines.append(f"- {h:.2f} m {name}: {c['recovered_Ns']} / {c['failed_Ns']}, "
                         f"recovered above: {above_text(c) or 'none seen'}, {c['runs']} runs"
                         + (f"; first failure ({ff.get('outcome')}): {ff.get('reason')}" if ff else ""))
    lines += ["", f"Setup: profiles {', '.join(setup.get('profiles') or []) or 'none (the defaults)'}, recovery rule "
                  f"{setup['criteria']['rule']}, runner {grid.get('runner', 'stack')}."]
    if wall_s is not None:
        lines += ["", f"Wall time of this invocation: {wall_s / 60:.1f} min" +
                  (f" (load average before / after: {load[0]} / {load[1]})." if load else ".")]
    return lines


def plot_sweep(out_dir, table, direction):
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(7.5, 4.2), dpi=130)
    hs = [h for h, *_ in table]
    xs = range(len(hs))
    bw = 0.2
    def val(c):
        return c["i_max_Ns"] if c and c["i_max_Ns"] is not None else float("nan")
    ax.bar([x - 1.5 * bw for x in xs], [val(sa) for _, sa, _, _ in table], bw, color="tab:orange", label="SA-WBC (this stack)")
    ax.bar([x - 0.5 * bw for x in xs], [val(m) for _, _, m, _ in table], bw, color="tab:blue", label="MFT-WBC (this stack)")
    ax.bar([x + 0.5 * bw for x in xs], [PAPER_TABLE2.get(round(h, 2), {}).get("sa", float("nan")) for h in hs], bw,
           color="none", edgecolor="tab:orange", hatch="//", label="SA-WBC (paper)")
    ax.bar([x + 1.5 * bw for x in xs], [PAPER_TABLE2.get(round(h, 2), {}).get("mft", float("nan")) for h in hs], bw,
           color="none", edgecolor="tab:blue", hatch="//", label="MFT-WBC (paper)")
    for x, (_, sa, m, inc) in zip(xs, table):
        if inc is not None:
            ax.text(x - bw, max(val(sa), val(m)) + 0.3, f"{inc:+.0f} %", ha="center", fontsize=8)
    ax.set_xticks(list(xs))
    ax.set_xticklabels([f"{h:.2f}" for h in hs])
    ax.set_xlabel("reference base height $z_B^{ref}$ [m]")
    ax.set_ylabel("$I_{max}$ [N s]")
    ax.set_title(f"Push recovery: largest {direction} impulse recovered from (Table II)")
    ax.legend(fontsize=8, ncol=2, loc="lower left")
    ax.grid(axis="y", alpha=0.3)
    fig.tight_layout()
    path = Path(out_dir) / "push_sweep.png"
    fig.savefig(path)
    plt.close(fig)
    return path


def summary_json(table, results, grid, setup, wall_s, new_runs):
    return {"grid": grid, "setup": setup, "wall_s": None if wall_s is None else round(wall_s, 1),
            "new_runs": new_runs, "runs_on_file": len(results.runs),
            "table": [{"height_m": h,
                       "sa": None if sa is None else {k: sa.get(k) for k in CELL_KEYS},
                       "mft": None if m is None else {k: m.get(k) for k in CELL_KEYS},
                       "mft_sa_ratio": ratio(sa, m), "increase_pct": inc, "paper": PAPER_TABLE2.get(round(h, 2))}
                      for h, sa, m, inc in table]}


CELL_KEYS = ("i_max_Ns", "status", "recovered_Ns", "failed_Ns", "first_failure", "recovered_above_Ns",
             "largest_recovered_Ns", "monotone", "runs", "deterministic", "rawlogs")
