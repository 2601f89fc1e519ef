#!/usr/bin/python3
"""mft-plot: paper-style figures from the CSV that `mft-export FILE --csv DIR` writes.

Usage: mft-plot.py CSV_DIR OUT_DIR   (or `mft-export FILE --plot OUT_DIR`, which does both steps)
Writes OUT_DIR/floating_base.png (base x, z, pitch: ground truth and estimate), OUT_DIR/hip_angles.png
(q4, q6, q8, q10) and OUT_DIR/contact_forces.png (ground reaction forces of both feet).
"""
import csv
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # no display needed
import matplotlib.pyplot as plt  # noqa: E402

STYLE = {"font.family": "serif", "font.size": 8, "axes.labelsize": 8, "legend.fontsize": 7, "xtick.labelsize": 7,
         "ytick.labelsize": 7, "lines.linewidth": 0.9, "axes.grid": True, "grid.linewidth": 0.3, "savefig.dpi": 200}


class PlotError(Exception):
    """One line for the user: a CSV that cannot be read, a figure that cannot be written."""


def load(csv_dir, label):
    path = Path(csv_dir) / f"{label}.csv"
    if not path.is_file():
        return None
    try:
        with open(path, newline="", encoding="utf-8") as f:
            rows = list(csv.reader(f))
    except UnicodeDecodeError as e:
        raise PlotError(f"{path}: not UTF-8 text (byte {e.start}); expected a CSV written by mft-export")
    except OSError as e:
        raise PlotError(f"cannot read {path}: {e.strerror or e}")
    if len(rows) < 2:
        return None
    cols = {name: [] for name in rows[0]}
    for line, r in enumerate(rows[1:], start=2):
        for name, v in zip(rows[0], r):
            try:
                cols[name].append(float(v))
            except ValueError:
                raise PlotError(f"{path}: line {line}, column {name}: not a number: {v[:40]!r}")
    return cols


def save(fig, out, name):
    """Writes the figure to out/name and frees it; returns the path."""
    fig.tight_layout()
    path = Path(out) / name
    try:
        fig.savefig(path)
    except OSError as e:  # a full disk: no half-written figure is left
        path.unlink(missing_ok=True)
        raise PlotError(f"cannot write {path}: {e.strerror or e}{' (disk full?)' if e.errno == 28 else ''}")
    finally:
        plt.close(fig)
    return path


def floating_base(csv_dir, out):
    gt, est = load(csv_dir, "gt_q"), load(csv_dir, "est_q")
    if not gt and not est:
        return None
    fig, axes = plt.subplots(3, 1, figsize=(3.5, 4.2), sharex=True)
    for ax, key, unit in zip(axes, ("x", "z", "pitch"), ("m", "m", "rad")):
        if gt:
            ax.plot(gt["time_s"], gt[key], color="k", label="ground truth")
        if est:
            ax.plot(est["time_s"], est[key], color="tab:red", linestyle="--", label="estimate")
        ax.set_ylabel(f"base {key} [{unit}]")
    axes[0].legend(loc="best", frameon=False)
    axes[-1].set_xlabel("time [s]")
    return save(fig, out, "floating_base.png")


def hip_angles(csv_dir, out):
    gt = load(csv_dir, "gt_q")
    if not gt:
        return None
    fig, ax = plt.subplots(figsize=(3.5, 2.2))
    names = {"q4": "right rear hip", "q6": "right fore hip", "q8": "left rear hip", "q10": "left fore hip"}
    for (key, name), style in zip(names.items(), ("-", "--", "-", "--")):
        ax.plot(gt["time_s"], gt[key], linestyle=style, label=f"{key} {name}")
    ax.set_xlabel("time [s]")
    ax.set_ylabel("hip angle [rad]")
    ax.legend(loc="best", frameon=False, ncol=2)
    return save(fig, out, "hip_angles.png")


def contact_forces(csv_dir, out):
    f = load(csv_dir, "contact_force")
    if not f:
        return None
    fig, axes = plt.subplots(2, 1, figsize=(3.5, 3.2), sharex=True)
    for ax, comp in zip(axes, ("fz", "fx")):
        ax.plot(f["time_s"], f[f"{comp}_right"], color="tab:blue", label="right foot")
        ax.plot(f["time_s"], f[f"{comp}_left"], color="tab:orange", linestyle="--", label="left foot")
        ax.set_ylabel(f"{comp} [N]")
    axes[0].legend(loc="best", frameon=False)
    axes[-1].set_xlabel("time [s]")
    return save(fig, out, "contact_forces.png")


def main():
    if len(sys.argv) != 3 or sys.argv[1] in ("-h", "--help"):
        print(__doc__.strip())
        return 0 if len(sys.argv) == 2 else 2
    csv_dir, out = sys.argv[1], sys.argv[2]
    plt.rcParams.update(STYLE)
    try:
        Path(out).mkdir(parents=True, exist_ok=True)
        made = [p for p in (floating_base(csv_dir, out), hip_angles(csv_dir, out), contact_forces(csv_dir, out)) if p]
    except PlotError as e:
        print(f"mft-plot: {e}", file=sys.stderr)
        return 2
    except OSError as e:
        print(f"mft-plot: {e.filename or out}: {e.strerror or e}", file=sys.stderr)
        return 2
    if not made:
        print(f"mft-plot: no gt_q, est_q or contact_force CSV in {csv_dir}", file=sys.stderr)
        return 1
    for p in made:
        print(f"mft-plot: wrote {p}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
