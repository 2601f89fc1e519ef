"""terrain: blind walking over the paper's course with each controller (recorded), the paper's Fig. 8 as a PNG,
and whether the left leg stayed inside the MFT preferable space while in stance on the up-slope.

MFT convention (model/mft_polytope.hpp, config/mft_space.yaml): one polygon per leg, A_leg [q_rear, q_fore] <=
b_leg with unit-norm rows (rad); for the left leg q_rear = q8 and q_fore = q10, the same polygon as the right leg
(the augmented A = blkdiag(A_leg, A_leg) over q_a = [q4, q6, q8, q10] that the WBC uses). The violation of a
sample is max(A_leg q - b_leg) in rad: <= 0 inside, computed by `mft-space violation` (mft_space.py)."""
import math
import time
from pathlib import Path

from .common import (CONTROLLER_NAMES, ExperimentError, export_csv, load_yaml, pyplot, read_csv, write_report,
                     write_yaml_scenario)
from .case import COLORS, controller_runs, run_pair
from .mft_space import leg_polygon, mft_violations

INSIDE_TOL_RAD = 0.01  # "stayed inside" allows the soft constraint's small predicted violations
# The minimal departure from the paper's setup that the course needs (docs/results/terrain.md): with the
# paper's k_v = 0.16 the robot stalls at the foot of the 6 degree slope and falls back (course without the board,
# 0.20/0.25/0.30 m/s); kv-0.145 (k_v = 1/sigma1 of the LIP orbit) climbs it. It does not help at the board's edge.
COURSE_PROFILES = ["kv-0.145"]


def course_profiles(args):
    """The runs' profiles: COURSE_PROFILES (unless --paper-setup), then those given with --profile, each once."""
    first = [] if args.paper_setup else COURSE_PROFILES
    return first + [p for p in args.profile if p not in first]


def course_segments(terrain):
    """[(type, x0, x1, z0, z1, seg)] along x; heights where the foot rests (board/slope exact, rough nominal)."""
    x, z = float(terrain.get("start_x_m", 0.0)), float(terrain.get("start_height_m", 0.0))
    out = []
    for seg in terrain.get("terrain") or []:
        L = float(seg["length_m"])
        t = seg["type"]
        if t == "board":
            out.append((t, x, x + L, z + seg["height_m"], z + seg["height_m"], seg))
        elif t == "slope":
            z1 = z + L * math.tan(math.radians(seg["angle_deg"]))
            out.append((t, x, x + L, z, z1, seg))
            z = z1
        else:
            out.append((t, x, x + L, z, z, seg))
        x += L
    return out


def ground_at(segs, x):
    for t, x0, x1, z0, z1, _ in segs:
        if x0 <= x < x1:
            return z0 + (z1 - z0) * (x - x0) / (x1 - x0)
    if segs and x >= segs[-1][2]:
        return segs[-1][4]
    return segs[0][3] if segs and segs[0][0] != "board" else 0.0


def walk_scenario(height, speed, controller, terrain, duration, name, tool="terrain"):
    """Stand 1 s, step in place 1 s, then walk at `speed` and `height` over `terrain` (blind), Kalman estimator."""
    return {"name": name, "description": f"mft-experiment {tool}: blind walking at {speed} m/s, {height} m over {terrain}, "
                                         f"{controller}",
            "duration_s": duration, "controller": controller, "estimator": "kalman", "terrain": terrain,
            "initial_base_height_m": height, "fall": {"base_height_below_m": 0.25, "pitch_beyond_rad": 0.8},
            "commands": [{"at_s": 0.0, "mode": "stand", "z_cmd_m": height, "v_cmd_mps": 0.0},
                         {"at_s": 1.0, "mode": "step_in_place", "z_cmd_m": height, "v_cmd_mps": 0.0},
                         {"at_s": 2.0, "mode": "walk", "z_cmd_m": height, "v_cmd_mps": speed}]}


def scenario(args, controller, duration):
    return walk_scenario(args.height, args.speed, controller, args.terrain, duration,
                         f"terrain-{args.terrain}-{controller}")


def cmd_terrain(args):
    tfile = Path(args.config_dir) / "terrain" / f"{args.terrain}.yaml"
    if not tfile.is_file():
        raise ExperimentError(f"terrain file {tfile} does not exist")
    segs = course_segments(load_yaml(tfile))
    args.profile = course_profiles(args)  # passed to the supervisor (and its checks) like any --profile
    rough = [s for s in segs if s[0] != "flat"]
    if not rough:
        raise ExperimentError(f"{tfile} has no board, slope or rough segment")
    course_end = rough[-1][2] + 0.3  # past the last obstacle with the whole robot
    slopes = [s for s in segs if s[0] == "slope" and s[4] > s[3]]
    # walking starts at 2 s; blind walking over the course averages well below the command (0.5 of it allowed)
    duration = args.duration or min(300.0, round(2.0 + course_end / (0.5 * args.speed) + 3.0, 1))
    out, jobs = controller_runs(args, "terrain", lambda scen, c: write_yaml_scenario(scen, scenario(args, c, duration)),
                                duration * 20 + 120)
    t0 = time.monotonic()
    runs = run_pair(args, jobs)
    verts = leg_polygon(args.config_dir)
    report = {"terrain": args.terrain, "speed_mps": args.speed, "height_m": args.height, "duration_s": duration,
              "profiles": list(args.profile),
              "course_end_x_m": round(course_end, 3),
              "segments": [{"type": t, "x0": round(x0, 3), "x1": round(x1, 3), "z0": round(z0, 3), "z1": round(z1, 3)}
                           for t, x0, x1, z0, z1, _ in segs], "controllers": {}, "out": str(out)}
    traces = {}
    for c in args.controllers:
        summary, wall = runs[c]
        sim = summary["services"]["mft-sim"]
        csv_dir = out / f"{c}-csv"
        export_csv(args.bin_dir, out / f"{c}.rawlog", csv_dir,
                   ["gt_q", "gt_qd", "plan_ref", "contact_force", "joint_tau_cmd", "leg_lti"])
        tr = {k: read_csv(csv_dir / f"{k}.csv") for k in ("gt_q", "gt_qd", "plan_ref", "contact_force",
                                                           "joint_tau_cmd", "leg_lti")}
        tr["mft"] = mft_violations(args.bin_dir, args.config_dir, csv_dir / "gt_q.csv")
        traces[c] = tr
        q = tr["gt_q"]
        max_x = max(q["x"]) if q["x"] else 0.0
        traversed = sim["recovery"]["verdict"]["no_fall"] and max_x >= course_end  # the one criterion's no-fall outcome
        # left leg in stance on the up-slope: the planner's stance flag (what the WBC treats as stance)
        stance = dict(zip(tr["plan_ref"]["tick"], tr["plan_ref"]["in_stance_left"]))
        viol = []
        for i, tick in enumerate(q["tick"]):
            if not slopes or stance.get(tick, 0.0) < 0.5:
                continue
            if any(s[1] <= q["x"][i] <= s[2] for s in slopes):
                viol.append(tr["mft"]["mft_violation_left"][i])
        mft_check = None
        if viol:
            mft_check = {"samples": len(viol), "max_violation_rad": round(max(viol), 4),
                         "inside_fraction": round(sum(v <= 0 for v in viol) / len(viol), 4),
                         f"inside_fraction_tol_{INSIDE_TOL_RAD}": round(sum(v <= INSIDE_TOL_RAD for v in viol) / len(viol), 4),
                         "stayed_inside": max(viol) <= INSIDE_TOL_RAD}
        report["controllers"][c] = {
            "traversed": traversed, "fell": sim.get("fell"), "fall_time_s": sim.get("fall_time_s"),
            "fall_reason": sim.get("fall_reason"), "max_base_x_m": round(max_x, 3),
            "fall_x_m": round(q["x"][-1], 3) if sim.get("fell") and q["x"] else None,
            "average_speed_mps": sim.get("average_speed_mps"), "base_height_error_m": sim.get("base_height_error_m"),
            "left_stance_on_up_slope_mft": mft_check, "rawlog": str(out / f"{c}.rawlog"), "wall_s": round(wall, 1)}
    png = plot_terrain(out / "terrain.png", args, report, traces, segs, slopes, verts)
    if args.video:
        from .video import write_video
        report["video"] = write_video(args, [out / f"{c}.rawlog" for c in args.controllers], out / "terrain.mp4")["video"]
    write_report(out / "terrain.json", report, png, t0, args.json)
    if not args.json:
        print(f"terrain {args.terrain}: walk {args.speed} m/s at {args.height} m, course ends at x = {course_end:.2f} m; "
              f"profiles {report['profiles'] or 'none (the paper setup)'}")
        for c, r in report["controllers"].items():
            m = r["left_stance_on_up_slope_mft"]
            print(f"  {CONTROLLER_NAMES.get(c, c):8s} {'TRAVERSED' if r['traversed'] else 'FAILED'}"
                  f"{'' if not r['fell'] else ' (fell at t = %.2f s, x = %.2f m: %s)' % (r['fall_time_s'], r['fall_x_m'], r['fall_reason'])}"
                  f", average speed {r['average_speed_mps']:.3f} m/s"
                  + ("" if not m else f"; left stance leg on the up-slope: {100 * m['inside_fraction']:.1f} % of "
                                      f"{m['samples']} samples inside the MFT space, max violation {m['max_violation_rad']:.3f} rad"))
        print(f"  figure {png}; rawlogs and CSV in {out}")
        if report.get("video"):
            print(f"  video {report['video']}")
    return 0


def _legend(ax, **kw):
    if ax.get_legend_handles_labels()[0]:  # no warning for an empty panel (a run that never reached the slope)
        ax.legend(**kw)


def plot_terrain(path, args, report, traces, segs, slopes, verts):
    """The paper's Fig. 8: (a) the floating base over the course, (b) the left leg on the up-slope."""
    plt = pyplot()
    fig = plt.figure(figsize=(13, 8), dpi=110)
    gs = fig.add_gridspec(3, 3)
    ax = {"z": fig.add_subplot(gs[0, 0:2]), "p": fig.add_subplot(gs[1, 0]), "v": fig.add_subplot(gs[1, 1]),
          "j": fig.add_subplot(gs[0:2, 2]), "qt": fig.add_subplot(gs[2, 0]), "vt": fig.add_subplot(gs[2, 1]),
          "tau": fig.add_subplot(gs[2, 2])}
    _plot_base(ax, args, report, traces, segs)
    _plot_left_leg(ax, traces, slopes, verts)
    for a in ax.values():
        a.grid(alpha=0.3)
    fig.suptitle(f"Blind walking over '{args.terrain}' at {args.speed} m/s, $z_B^{{ref}}$ = {args.height} m", fontsize=11)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
    return path


def _plot_base(ax, args, report, traces, segs):
    """(a): height over the course with its segments, pitch and forward speed of each run."""
    ax_z, ax_p, ax_v = ax["z"], ax["p"], ax["v"]
    xs = [segs[0][1] - 1.0] + [s[1] for s in segs] + [segs[-1][2], segs[-1][2] + 1.0]
    ax_z.plot(xs, [ground_at(segs, x) for x in xs], color="k", lw=1, label="ground (rough: nominal)")
    for t, x0, x1, *_ in segs:
        if t != "flat":
            ax_z.axvspan(x0, x1, color="0.9")
            ax_z.text(0.5 * (x0 + x1), 0.02, t, ha="center", fontsize=8)
    for c, tr in traces.items():
        q, qd = tr["gt_q"], tr["gt_qd"]
        r = report["controllers"][c]
        lab = f"{CONTROLLER_NAMES.get(c, c)}: {'traversed' if r['traversed'] else 'failed'}"
        ax_z.plot(q["x"], q["z"], color=COLORS.get(c), lw=1, label=lab)
        ax_p.plot(q["time_s"], q["pitch"], color=COLORS.get(c), lw=1, label=c)
        ax_v.plot(qd["time_s"], qd["xd"], color=COLORS.get(c), lw=0.8, label=c)
        if r["fell"]:
            ax_z.plot([q["x"][-1]], [q["z"][-1]], "x", color="tab:red", ms=9, mew=2)
    ax_v.axhline(args.speed, color="k", lw=0.6, ls=":", label="command")
    ax_z.set_title("(a) floating base: height over the course (world z vs x)", fontsize=10)
    ax_z.set_xlabel("base x [m]")
    ax_z.set_ylabel("z [m]")
    _legend(ax_z, fontsize=7, loc="center left")
    ax_p.set_title("(a) pitch", fontsize=10)
    ax_p.set_xlabel("time [s]")
    ax_p.set_ylabel("pitch [rad]")
    ax_v.set_title("(a) forward speed", fontsize=10)
    ax_v.set_xlabel("time [s]")
    ax_v.set_ylabel("xd [m/s]")
    _legend(ax_v, fontsize=7)


def _plot_left_leg(ax, traces, slopes, verts):
    """(b): the left leg on the up-slope in the joint space with the hexagon, and for the MFT run (or the first)
    its hip angles, its MFT violation and its hip torques over time."""
    ax_j, ax_qt, ax_vt, ax_tau = ax["j"], ax["qt"], ax["vt"], ax["tau"]
    vx = [v[0] for v in verts] + [verts[0][0]]
    vy = [v[1] for v in verts] + [verts[0][1]]
    ax_j.fill(vx, vy, color="tab:green", alpha=0.15, label="MFT preferable space (hexagon)")
    ax_j.plot(vx, vy, color="tab:green", lw=1)
    main = "mft" if "mft" in traces else next(iter(traces))
    for c, tr in traces.items():
        q = tr["gt_q"]
        stance = dict(zip(tr["plan_ref"]["tick"], tr["plan_ref"]["in_stance_left"]))
        on = [i for i, x in enumerate(q["x"]) if any(s[1] <= x <= s[2] for s in slopes)]
        st = [i for i in on if stance.get(q["tick"][i], 0) >= 0.5]
        sw = [i for i in on if stance.get(q["tick"][i], 0) < 0.5]
        ax_j.plot([q["q8"][i] for i in sw], [q["q10"][i] for i in sw], ".", ms=1, color=COLORS.get(c), alpha=0.25)
        ax_j.plot([q["q8"][i] for i in st], [q["q10"][i] for i in st], ".", ms=2, color=COLORS.get(c),
                  label=f"{c}: left stance on the up-slope")
        if c == main and on:
            t = [q["time_s"][i] for i in on]
            ax_qt.plot(t, [q["q8"][i] for i in on], color="tab:purple", lw=1, label="$q_8$ (rear hip)")
            ax_qt.plot(t, [q["q10"][i] for i in on], color="tab:brown", lw=1, label="$q_{10}$ (fore hip)")
            viol = [tr["mft"]["mft_violation_left"][i] for i in on]
            ax_vt.plot(t, viol, color="0.6", lw=0.8, label="swing")
            ax_vt.plot([q["time_s"][i] for i in st], [tr["mft"]["mft_violation_left"][i] for i in st], ".",
                       ms=2, color=COLORS.get(c), label="stance")
            tau = tr["joint_tau_cmd"]
            ti = [k for k, tt in enumerate(tau["time_s"]) if t[0] <= tt <= t[-1]]
            ax_tau.plot([tau["time_s"][k] for k in ti], [tau["tau_q8"][k] for k in ti], lw=0.8, label="$\\tau_8$")
            ax_tau.plot([tau["time_s"][k] for k in ti], [tau["tau_q10"][k] for k in ti], lw=0.8, label="$\\tau_{10}$")
    ax_j.set_xlabel("$q_8$ rear hip [rad]")
    ax_j.set_ylabel("$q_{10}$ fore hip [rad]")
    ax_j.set_title("(b) left leg in the actuated joint space, up-slope", fontsize=10)
    _legend(ax_j, fontsize=7, loc="lower right")
    ax_qt.set_title(f"(b) left hip angles on the up-slope ({main})", fontsize=10)
    ax_qt.set_xlabel("time [s]")
    _legend(ax_qt, fontsize=7)
    ax_vt.axhline(0, color="tab:green", lw=0.8)
    ax_vt.set_title(f"(b) MFT constraint max(A q - b), left leg ({main})", fontsize=10)
    ax_vt.set_xlabel("time [s]")
    ax_vt.set_ylabel("[rad] (≤ 0 inside)")
    _legend(ax_vt, fontsize=7)
    ax_tau.set_title(f"(b) left hip torque commands ({main})", fontsize=10)
    ax_tau.set_xlabel("time [s]")
    ax_tau.set_ylabel("[N m]")
    _legend(ax_tau, fontsize=7)
