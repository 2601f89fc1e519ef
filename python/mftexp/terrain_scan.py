"""terrain-scan: how often blind walking gets over the course, over the gait's phase at the board.

A blind walk meets the board's leading edge wherever the gait puts its footfalls: a foot that lands in the last
2-3 cm before the 3 cm board brings its fore shank onto the corner (docs/results/terrain.md). Where the
footfalls fall at the edge is set by the gait's phase there, and so by how far the course starts from the robot.
One run of `terrain` is therefore one draw. This command walks the whole course in process (mft-closedloop, the
same configs, profiles and fall criteria as the stack) with the course shifted by each offset
(config/terrain/<terrain>.yaml start_x_m + offset, one configuration copy per offset in OUT/config-shifts), per
height, speed and controller, and counts the runs that crossed the board (base 0.3 m past its far edge) and
those that traversed the course (no fall, base 0.3 m past the last obstacle, as `terrain` judges it), with each
failed run's first body contact; and per cell, the base's mean height walking on flat ground (one 8 s run, 2-8 s),
which shapes the legs when they reach the board. Outputs: terrain_scan.md, terrain_scan.csv, terrain_scan.json and
terrain_scan.png (one row per cell, one mark per offset)."""
import csv
import re
import shutil
import time
import threading
from pathlib import Path

from .common import (CONTROLLER_NAMES, ExperimentError, Progress, pyplot, run_closedloop, run_workers,
                     write_report, write_yaml_scenario)
from .common import load_yaml
from .terrain import course_profiles, course_segments, walk_scenario

CLEARANCE_M = 0.3  # "past" an obstacle: the base this far beyond its far edge, the whole robot over it


def offsets(span_m, step_m):
    n = int(round(span_m / step_m))
    return [round(i * step_m, 6) for i in range(-n, n + 1)]


def shifted_config(src, dest, terrain, offset):
    """A copy of the configuration folder whose terrain file starts `offset` metres later (only start_x_m
    changes)."""
    if dest.exists():
        shutil.rmtree(dest)
    shutil.copytree(src, dest)
    path = dest / "terrain" / f"{terrain}.yaml"
    text = path.read_text()
    start = float(load_yaml(path).get("start_x_m", 0.0))
    new, n = re.subn(r"(?m)^start_x_m:.*$", f"start_x_m: {start + offset:.6f}", text)
    if n != 1:
        raise ExperimentError(f"{path}: expected one top-level start_x_m line to shift the course")
    path.write_text(new)
    return dest


def run_all(task, items, workers):
    """task(item) for every item on `workers` threads, results in the items' order; Ctrl-C stops the runs in flight
    (run_workers) and the first error ends the scan."""
    results = [None] * len(items)
    errors = []
    lock = threading.Lock()
    next_index = [0]

    def worker(_):
        while not errors:
            with lock:
                i = next_index[0]
                next_index[0] += 1
            if i >= len(items):
                return
            try:
                results[i] = task(items[i])
            except Exception as e:  # reported once by run_workers, as one line
                errors.append(e)
    run_workers(worker, min(workers, len(items)), errors, "interrupted: stopping the runs in flight")
    return results


def judge(run, board_end, course_end, offset):
    """(crossed_board, traversed) from the run's summary on the course shifted by `offset`: the base `CLEARANCE_M`
    past the board's far edge (None without a board), and no fall with the base as far past the last obstacle."""
    x = run["max_base_x_m"]
    crossed = None if board_end is None else x >= board_end + offset + CLEARANCE_M
    return crossed, (not run["fell"]) and x >= course_end + offset + CLEARANCE_M


def _course(args):
    """The terrain file's segments: (segments, board start, board end, the last obstacle's far edge), unshifted."""
    tfile = Path(args.config_dir) / "terrain" / f"{args.terrain}.yaml"
    if not tfile.is_file():
        raise ExperimentError(f"terrain file {tfile} does not exist")
    segs = course_segments(load_yaml(tfile))
    obstacles = [s for s in segs if s[0] != "flat"]
    if not obstacles:
        raise ExperimentError(f"{tfile} has no board, slope or rough segment")
    boards = [s for s in segs if s[0] == "board"]
    board_start, board_end = (boards[0][1], boards[0][2]) if boards else (None, None)
    return segs, board_start, board_end, obstacles[-1][2]


def _scan_jobs(args, out, cells, shifts, course_end):
    """One scenario per cell (long enough to pass the course at half the commanded speed), one run per offset."""
    jobs = []
    for h, v, c in cells:
        duration = args.duration or min(300.0, round(2.0 + (course_end + CLEARANCE_M + max(shifts)) / (0.5 * v) + 3.0, 1))
        scen = out / "scenarios" / f"h{h:.3f}-v{v:.3f}-{c}.yaml"
        scen.parent.mkdir(parents=True, exist_ok=True)
        write_yaml_scenario(scen, walk_scenario(h, v, c, args.terrain, duration, f"terrain-scan-{c}", "terrain-scan"))
        jobs += [(h, v, c, o, scen) for o in shifts]
    return jobs


def _scan_run(args, job, configs, course, progress, left):
    """One run on its shifted course, judged on that course: the row of terrain_scan.csv."""
    _, board_start, board_end, course_end = course
    h, v, c, o, scen = job
    sim, wall = run_closedloop(scen, args.bin_dir, configs[o], timeout_s=600.0, profiles=args.profile)
    crossed, traversed = judge(sim, board_end, course_end, o)
    contact = sim.get("first_body_contact") or {}
    row = {"height_m": h, "speed_mps": v, "controller": c, "offset_m": o, "crossed_board": crossed,
           "traversed": traversed, "fell": sim["fell"], "fall_time_s": sim["fall_time_s"],
           "max_base_x_m": round(sim["max_base_x_m"], 4),
           "first_body_contact": contact.get("body"),
           "contact_x_from_board_m": (None if contact.get("x_m") is None or board_start is None
                                      else round(contact["x_m"] - (board_start + o), 4)),
           "contact_time_s": contact.get("time_s")}
    left[0] -= 1
    progress.run_finished(wall, f"{h:.2f} m {v:.2f} m/s {c} offset {o:+.3f} m: "
                                f"{'traversed' if traversed else 'crossed the board' if crossed else 'failed'}",
                          left[0])
    return row


def _flat_height(args, out, cell):
    """The base's mean height walking on flat ground (2-8 s), the cell's setup otherwise: what shapes the legs
    when they reach the board (with the paper's contact-force weight it sits below the command,
    docs/guide/profiles.md)."""
    h, v, c = cell
    scen = out / "scenarios" / f"flat-h{h:.3f}-v{v:.3f}-{c}.yaml"
    write_yaml_scenario(scen, walk_scenario(h, v, c, "flat", 8.0, f"terrain-scan-flat-{c}", "terrain-scan"))
    sim, _ = run_closedloop(scen, args.bin_dir, args.config_dir, timeout_s=120.0, profiles=args.profile)
    z = sim.get("mean_base_z_m")
    return None if sim["fell"] or z is None else round(z, 4)


def _cell_summary(cells, rows, flat):
    """Per cell: how many runs crossed the board and traversed the course, and what failed runs hit first."""
    summary = []
    for h, v, c in cells:
        rs = [r for r in rows if (r["height_m"], r["speed_mps"], r["controller"]) == (h, v, c)]
        bodies = {}
        for r in rs:
            if not r["traversed"] and r["first_body_contact"]:
                bodies[r["first_body_contact"]] = bodies.get(r["first_body_contact"], 0) + 1
        summary.append({"height_m": h, "speed_mps": v, "controller": c, "runs": len(rs),
                        "walking_height_on_flat_m": flat[(h, v, c)],
                        "crossed_board": sum(bool(r["crossed_board"]) for r in rs),
                        "traversed": sum(r["traversed"] for r in rs),
                        "traversed_of_crossed": sum(r["traversed"] for r in rs if r["crossed_board"]),
                        "failed_first_body_contact": bodies})
    return summary


def cmd_terrain_scan(args):
    course = _course(args)
    if not 0 < args.shift_step <= args.shift_span:
        raise ExperimentError("need 0 < --shift-step <= --shift-span")
    if args.shift_span / args.shift_step > 200:
        raise ExperimentError("at most 401 offsets (--shift-span / --shift-step <= 200)")
    args.profile = course_profiles(args)
    out = Path(args.out)
    shifts = offsets(args.shift_span, args.shift_step)
    cells = [(h, v, c) for h in args.heights for v in args.speeds for c in args.controllers]
    t0 = time.monotonic()
    configs = {o: shifted_config(Path(args.config_dir), out / "config-shifts" / f"shift{o:+.3f}", args.terrain, o)
               for o in shifts}
    jobs = _scan_jobs(args, out, cells, shifts, course[3])
    progress = Progress(args.workers, quiet=args.quiet)
    progress.note(f"{len(jobs)} runs: {len(cells)} cells x {len(shifts)} course offsets, {args.workers} at a time, "
                  f"profiles {args.profile or 'none (the paper setup)'}")
    left = [len(jobs)]
    flat = dict(zip(cells, run_all(lambda cell: _flat_height(args, out, cell), cells, args.workers)))
    rows = run_all(lambda job: _scan_run(args, job, configs, course, progress, left), jobs, args.workers)
    report = {"terrain": args.terrain, "profiles": list(args.profile), "offsets_m": shifts,
              "clearance_m": CLEARANCE_M, "cells": _cell_summary(cells, rows, flat), "runs": rows, "out": str(out)}
    write_tables(out, report)
    png = plot_scan(out / "terrain_scan.png", report)
    write_report(out / "terrain_scan.json", report, png, t0, args.json)
    if not args.json:
        print((out / "terrain_scan.md").read_text(), end="")
    return 0


def write_tables(out, report):
    with open(out / "terrain_scan.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(report["runs"][0]))
        w.writeheader()
        w.writerows(report["runs"])
    o = report["offsets_m"]
    lines = [f"# terrain-scan: {report['terrain']}, course shifted by {o[0]:+.3f} ... {o[-1]:+.3f} m "
             f"({len(o)} offsets); profiles {', '.join(report['profiles']) or 'none (the paper setup)'}", "",
             "| height [m] | speed [m/s] | controller | walking height on flat ground [m] | crossed the board | "
             "traversed the course | failed runs' first body contact |", "|---|---|---|---|---|---|---|"]
    for s in report["cells"]:
        bodies = ", ".join(f"{b} {n}" for b, n in sorted(s["failed_first_body_contact"].items())) or "-"
        z = "fell" if s["walking_height_on_flat_m"] is None else f"{s['walking_height_on_flat_m']:.3f}"
        lines.append(f"| {s['height_m']:.2f} | {s['speed_mps']:.2f} | {CONTROLLER_NAMES.get(s['controller'], s['controller'])} "
                     f"| {z} | {s['crossed_board']}/{s['runs']} | {s['traversed']}/{s['runs']} | {bodies} |")
    (out / "terrain_scan.md").write_text("\n".join(lines) + "\n")


def grid_lines(report):
    """The heights x speeds table of a scan with both controllers: per cell the runs that crossed the board and
    (in brackets) traversed the course, MFT-WBC / SA-WBC; per height the walking height on flat ground. What the
    docs' `terrain-scan` blocks hold (scripts/results-blocks.py)."""
    cells = {(s["height_m"], s["speed_mps"], s["controller"]): s for s in report["cells"]}
    heights = sorted({h for h, _, _ in cells})
    speeds = sorted({v for _, v, _ in cells})
    ctrls = [c for c in ("mft", "sa") if any(k[2] == c for k in cells)]
    runs = sorted({s["runs"] for s in report["cells"]})

    def pair(h, v, key):
        return " / ".join("-" if (h, v, c) not in cells else str(cells[(h, v, c)][key]) for c in ctrls)

    def flat(h):  # the range over the height's speeds and controllers
        zs = [cells[k]["walking_height_on_flat_m"] for k in cells if k[0] == h]
        shown = sorted({f"{z:.3f}" for z in zs if z is not None})
        text = shown[0] if len(shown) == 1 else f"{shown[0]}–{shown[-1]}" if shown else ""
        return ", ".join(filter(None, [text, "fell" if None in zs else ""]))
    names = " / ".join(CONTROLLER_NAMES.get(c, c) for c in ctrls)
    lines = [f"- {report['terrain']}, course shifted by {len(report['offsets_m'])} offsets "
             f"({report['offsets_m'][0] * 100:+.0f} ... {report['offsets_m'][-1] * 100:+.0f} cm), "
             f"{'/'.join(map(str, runs))} runs per cell; profiles: {', '.join(report['profiles']) or 'none'}",
             f"- per cell: runs that crossed the board (traversed the course), {names}", "",
             "| commanded height [m] (walking height on flat [m]) | " + " | ".join(f"{v:.2f} m/s" for v in speeds) + " |",
             "|---|" + "---|" * len(speeds)]
    for h in heights:
        lines.append(f"| {h:.2f} ({flat(h)}) | "
                     + " | ".join(f"{pair(h, v, 'crossed_board')} ({pair(h, v, 'traversed')})" for v in speeds) + " |")
    return lines + ["", _failures_line(report["cells"])]


def _failures_line(cells):
    """What the runs that did not traverse touched first, summed over the cells."""
    failed = sum(s["runs"] - s["traversed"] for s in cells)
    bodies = {}
    for s in cells:
        for b, n in s.get("failed_first_body_contact", {}).items():
            bodies[b] = bodies.get(b, 0) + n
    touched = ", ".join(f"{b} {n}" for b, n in sorted(bodies.items())) or "none"
    return (f"- of the {failed} runs that did not traverse, the first body other than a foot to touch the ground: "
            f"{touched}; no such contact in {failed - sum(bodies.values())}")


def plot_scan(path, report):
    plt = pyplot()
    cells = report["cells"]
    fig, ax = plt.subplots(figsize=(9, 1.0 + 0.45 * len(cells)))
    colors = {"traversed": "tab:green", "crossed": "tab:orange", "failed": "tab:red"}
    for i, s in enumerate(cells):
        for r in report["runs"]:
            if (r["height_m"], r["speed_mps"], r["controller"]) != (s["height_m"], s["speed_mps"], s["controller"]):
                continue
            k = "traversed" if r["traversed"] else "crossed" if r["crossed_board"] else "failed"
            ax.plot(r["offset_m"] * 100, i, "s", color=colors[k], ms=7)
    for k, col in colors.items():
        ax.plot([], [], "s", color=col, label={"crossed": "crossed the board, fell later"}.get(k, k))
    ax.set_yticks(range(len(cells)))
    ax.set_yticklabels([f"{s['height_m']:.2f} m, {s['speed_mps']:.2f} m/s, "
                        f"{CONTROLLER_NAMES.get(s['controller'], s['controller'])}" for s in cells])
    ax.set_xlabel("course shifted by [cm] (the gait's phase at the board's edge)")
    ax.set_ylim(-0.7, len(cells) - 0.3)
    height_in = fig.get_size_inches()[1]
    fig.legend(loc="lower center", ncol=3, fontsize=8, frameon=False)
    ax.set_title(f"blind walking over '{report['terrain']}': outcome per course offset", fontsize=10)
    fig.tight_layout(rect=(0, 0.35 / height_in, 1, 1))  # room for the legend's one line under the axis label
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path
