#!/usr/bin/env python3
"""Makes recorded_state.csv for the example from a recorded run: the CSV folder that `mft-export RUN.rawlog
--csv DIR` writes (est_q, est_qd, est_contact, plan_ref, joint_tau_cmd), a range of consecutive ticks.

    make_recorded_state.py DIR --from-tick N --count K --output recorded_state.csv [--note TEXT]

Columns: tick; the estimate q (x z pitch q4..q11) and qd (xd zd pitchd qd4..qd11); contact_right/left; the
planner's reference (plan_ref, its pitch columns renamed pitch_ref, pitchd_ref, pitchdd_ref); the torques the
stack's WBC commanded for that tick (recorded_tau_q4..q10, recorded_mode), for comparison only."""
import argparse
import csv
import sys
from pathlib import Path

REFERENCE = ["in_stance_right", "in_stance_left", "base_z", "base_zd", "base_zdd", "pitch", "pitchd", "pitchdd",
             "foot_x_right", "foot_z_right", "foot_x_left", "foot_z_left", "foot_vx_right", "foot_vz_right",
             "foot_vx_left", "foot_vz_left", "foot_ax_right", "foot_az_right", "foot_ax_left", "foot_az_left",
             "base_x", "base_xd", "base_xdd", "hold_base_x"]
RENAMED = {"pitch": "pitch_ref", "pitchd": "pitchd_ref", "pitchdd": "pitchdd_ref"}


def by_tick(path):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    if not rows:
        sys.exit(f"make_recorded_state: error: {path} has no rows")
    return {int(float(r["tick"])): r for r in rows}


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("csv_dir")
    p.add_argument("--from-tick", type=int, required=True)
    p.add_argument("--count", type=int, default=10)
    p.add_argument("--output", required=True)
    p.add_argument("--note", default="", help="a comment line saying where the run came from")
    a = p.parse_args()
    d = Path(a.csv_dir)
    try:
        q, qd, contact, ref, cmd = (by_tick(d / f"{n}.csv") for n in
                                    ("est_q", "est_qd", "est_contact", "plan_ref", "joint_tau_cmd"))
    except OSError as e:
        sys.exit(f"make_recorded_state: error: {e}")
    q_names = ["x", "z", "pitch"] + [f"q{i}" for i in range(4, 12)]
    qd_names = ["xd", "zd", "pitchd"] + [f"qd{i}" for i in range(4, 12)]
    header = (["tick"] + q_names + qd_names + ["contact_right", "contact_left"] + [RENAMED.get(n, n) for n in REFERENCE]
              + ["recorded_tau_q4", "recorded_tau_q6", "recorded_tau_q8", "recorded_tau_q10", "recorded_mode"])
    lines = []
    for tick in range(a.from_tick, a.from_tick + a.count):
        if not all(tick in t for t in (q, qd, contact, ref, cmd)):
            sys.exit(f"make_recorded_state: error: tick {tick} is missing from one of the CSV files in {d}")
        row = ([str(tick)] + [q[tick][n] for n in q_names] + [qd[tick][n] for n in qd_names]
               + [contact[tick]["right"], contact[tick]["left"]] + [ref[tick][n] for n in REFERENCE]
               + [cmd[tick][n] for n in ("tau_q4", "tau_q6", "tau_q8", "tau_q10", "mode")])
        lines.append(",".join(row))
    with open(a.output, "w") as f:
        f.write(f"# {a.count} consecutive ticks of a recorded run, made by make_recorded_state.py. {a.note}\n")
        f.write(",".join(header) + "\n" + "\n".join(lines) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
