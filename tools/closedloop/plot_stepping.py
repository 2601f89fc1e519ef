#!/usr/bin/python3
"""Stepping plot for the README: base height, pitch and hip angles from mft-closedloop CSV traces.

  mft-closedloop --height 0.44 --duration 8 --csv mft.csv
  mft-closedloop --height 0.44 --duration 8 --controller sa --csv sa.csv
  plot_stepping.py mft.csv sa.csv docs/img/stepping.png
"""
import csv
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt


def load(path):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    return {k: [float(r[k]) for r in rows] for k in rows[0]}


def main():
    mft, sa, out = load(sys.argv[1]), load(sys.argv[2]), sys.argv[3]
    fig, ax = plt.subplots(3, 1, figsize=(9, 8), sharex=True)
    ax[0].plot(sa["t"], sa["z"], color="tab:orange", label="SA-WBC")
    ax[0].plot(mft["t"], mft["z"], color="tab:blue", label="MFT-WBC")
    ax[0].plot(mft["t"], mft["z_cmd"], "k--", lw=1, label="command")
    ax[0].axhline(0.435, color="tab:green", ls=":", label="MFT space edge (vertical stance)")
    ax[0].set_ylabel("base height [m]")
    ax[0].set_ylim(0.42, 0.445)
    ax[0].legend(loc="lower right", fontsize=8, ncol=2)
    ax[1].plot(sa["t"], sa["pitch"], color="tab:orange", label="SA-WBC")
    ax[1].plot(mft["t"], mft["pitch"], color="tab:blue", label="MFT-WBC")
    ax[1].set_ylabel("pitch [rad]")
    ax[1].legend(loc="lower right", fontsize=8)
    for key, label, color in [("q4", "right rear q4", "tab:blue"), ("q6", "right fore q6", "tab:cyan"),
                              ("q8", "left rear q8", "tab:red"), ("q10", "left fore q10", "tab:pink")]:
        ax[2].plot(mft["t"], mft[key], color=color, label=label)
    ax[2].set_ylabel("hip angles, MFT-WBC [rad]")
    ax[2].set_xlabel("time [s] (stand, then step in place from 1 s)")
    ax[2].legend(loc="lower right", fontsize=8, ncol=4)
    fig.suptitle("Stepping in place at a 0.44 m command (mft-closedloop, Kalman estimator)")
    fig.tight_layout()
    fig.savefig(out, dpi=110)


if __name__ == "__main__":
    main()
