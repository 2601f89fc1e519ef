"""case: one push at one height with each controller (recorded), and the paper's Fig. 6 as a PNG."""
import threading
import time
from pathlib import Path

from .common import (CONTROLLER_NAMES, REPO, REGISTRY, ExperimentError, Interrupted, check_scenario, export_csv,
                     load_yaml, log, pyplot, read_csv, run_scenario, run_workers, write_report)
from . import push as pushmod
from .mft_space import mft_violations

COLORS = {"mft": "tab:blue", "sa": "tab:orange", "none": "tab:gray"}


def controller_runs(args, kind, write, timeout_s):
    """The output folder (args.out or runs/<kind>-<time>) and one checked scenario per controller in it, written by
    write(path, controller): the jobs [(controller, scenario, run_dir, rawlog, timeout)] of run_pair."""
    out = Path(args.out or REPO / "runs" / f"{kind}-{time.strftime('%Y%m%d-%H%M%S')}")
    out.mkdir(parents=True, exist_ok=True)
    jobs = []
    for c in args.controllers:
        rd = out / f"{c}-run"
        rd.mkdir(exist_ok=True)
        scen = rd / "scenario.yaml"
        write(scen, c)
        check_scenario(args.bin_dir, args.config_dir, scen, profiles=args.profile)
        jobs.append((c, scen, rd, out / f"{c}.rawlog", timeout_s))
    return out, jobs


def run_pair(args, jobs):
    """Runs [(name, scenario, run_dir, rawlog)] on args.workers stacks; returns {name: (summary, wall)}."""
    results, errors = {}, []
    queue = list(jobs)
    lock = threading.Lock()

    def worker(i):
        while not REGISTRY.stopping.is_set():
            with lock:
                if not queue:
                    return
                name, scen, rd, rawlog, timeout = queue.pop(0)
            try:
                t0 = time.monotonic()
                if not args.quiet:
                    log(f"{name}: running on domain {args.domain_base + i} (recording to {rawlog.name})")
                for attempt in (1, 2, 3):
                    try:
                        results[name] = run_scenario(scen, rd, args.domain_base + i, args.bin_dir, args.config_dir,
                                                     record=rawlog, timeout_s=timeout, profiles=args.profile)
                        break
                    except ExperimentError as e:
                        if attempt == 3 or REGISTRY.stopping.is_set():
                            raise
                        log(f"{name}: {e}; retrying ({attempt} of 2)")
                        time.sleep(3.0 * attempt)
                if not args.quiet:
                    log(f"{name}: done in {time.monotonic() - t0:.1f} s")
            except Interrupted:
                return
            except BaseException as e:  # noqa: reported by the caller
                errors.append(e)
                REGISTRY.stop_all()
                return

    run_workers(worker, args.workers, errors)
    if REGISTRY.stopping.is_set():
        raise Interrupted()
    return results


def cmd_case(args, setup):
    out, jobs = controller_runs(args, "case", lambda scen, c: pushmod.write_scenario(scen, setup, args.height, c,
                                                                                      args.impulse),
                                setup.duration_s * 40 + 120)
    t0 = time.monotonic()
    runs = run_pair(args, jobs)
    report = {"height_m": args.height, "impulse_Ns": args.impulse, "direction": setup.direction,
              "liftoff": setup.liftoff, "controllers": {}, "out": str(out)}
    traces = {}
    for c in args.controllers:
        summary, wall = runs[c]
        sim = summary["services"]["mft-sim"]
        recovered, reason = pushmod.judge(sim, setup.criteria)
        csv_dir = out / f"{c}-csv"
        export_csv(args.bin_dir, out / f"{c}.rawlog", csv_dir,
                   ["gt_q", "gt_qd", "leg_lti", "plan_ref", "joint_tau_cmd", "joint_tau_meas"])
        traces[c] = {"q": read_csv(csv_dir / "gt_q.csv"), "qd": read_csv(csv_dir / "gt_qd.csv"),
                     "lti": read_csv(csv_dir / "leg_lti.csv"), "plan": read_csv(csv_dir / "plan_ref.csv"),
                     "tau_cmd": read_csv(csv_dir / "joint_tau_cmd.csv"),
                     "tau_meas": read_csv(csv_dir / "joint_tau_meas.csv"),
                     "mft": mft_violations(args.bin_dir, args.config_dir, csv_dir / "gt_q.csv")}
        rec = sim["recovery"]
        report["controllers"][c] = {
            "recovered": recovered, "reason": reason, "fell": sim.get("fell"), "fall_time_s": sim.get("fall_time_s"),
            "fall_reason": sim.get("fall_reason"), "push_time_s": rec.get("push_time_s"),
            "pre_mean_base_height_m": rec["pre"]["mean_base_height_m"] if rec.get("pre") else None,
            "after": rec.get("after"), "tail": rec.get("tail"), "rawlog": str(out / f"{c}.rawlog"),
            "wall_s": round(wall, 2)}
    png = plot_case(out / "case.png", args, setup, report, traces)
    report["fig67"] = str(plot_fig67(out / "case_fig67.png", args, setup, report, traces))
    if args.video:
        from .video import write_video
        report["video"] = write_video(args, [out / f"{c}.rawlog" for c in args.controllers], out / "case.mp4")["video"]
    write_report(out / "case.json", report, png, t0, args.json)
    if not args.json:
        print(f"case: {args.impulse:g} N s {setup.direction} at {args.height:.2f} m ({setup.liftoff}-foot lift-off)")
        for c, r in report["controllers"].items():
            print(f"  {CONTROLLER_NAMES.get(c, c):8s} push at {r['push_time_s']:.3f} s: "
                  f"{'RECOVERED' if r['recovered'] else 'NOT RECOVERED'} ({r['reason']})")
        print(f"  figures {png}, {report['fig67']}; rawlogs and CSV in {out}")
        if report.get("video"):
            print(f"  video {report['video']}")
    return 0


def plot_case(path, args, setup, report, traces):
    plt = pyplot()
    fig, axes = plt.subplots(2, 3, figsize=(13, 6.5), dpi=120)
    hips = [("q4", "right rear hip $q_4$", "-"), ("q6", "right fore hip $q_6$", "--"),
            ("q8", "left rear hip $q_8$", "-."), ("q10", "left fore hip $q_{10}$", ":")]
    tmin = max(0.0, min(r["push_time_s"] for r in report["controllers"].values()) - 1.5)
    for col, c in enumerate(args.controllers[:2]):
        ax = axes[0][col]
        q = traces[c]["q"]
        for key, label, ls in hips:
            ax.plot(q["time_s"], q[key], ls, lw=1.1, label=label)
        r = report["controllers"][c]
        ax.set_title(f"(a) hip joint angles, {CONTROLLER_NAMES.get(c, c)}: "
                     f"{'recovered' if r['recovered'] else ('FELL' if r['fell'] else 'not recovered')}",
                     color="black" if r["recovered"] else "tab:red", fontsize=10)
        ax.set_ylabel("angle [rad]")
        ax.set_xlabel("time [s]")
        ax.legend(fontsize=7, loc="upper left", ncol=2)
    # (a') LTI of both legs, both controllers
    ax = axes[0][2]
    for c in args.controllers:
        l = traces[c]["lti"]
        ax.plot(l["time_s"], l["lti_right"], "-", color=COLORS.get(c), lw=1, label=f"{c} right")
        ax.plot(l["time_s"], l["lti_left"], "--", color=COLORS.get(c), lw=1, label=f"{c} left")
    ax.axhline(0.7, color="k", lw=0.6, ls=":")
    ax.axhline(0.02, color="tab:red", lw=0.6, ls=":")
    ax.set_title("leg LTI (MFT space: LTI ≥ 0.7; singular < 0.02)", fontsize=10)
    ax.set_xlabel("time [s]")
    ax.legend(fontsize=7)
    panels = [("z", "base height [m]", traces, "q"), ("pitch", "pitch [rad]", traces, "q"),
              ("xd", "forward speed [m/s]", traces, "qd")]
    for col, (key, label, _, src) in enumerate(panels):
        ax = axes[1][col]
        for c in args.controllers:
            d = traces[c][src]
            ax.plot(d["time_s"], d[key], color=COLORS.get(c), lw=1.2, label=CONTROLLER_NAMES.get(c, c))
            r = report["controllers"][c]
            if r["fell"]:
                ax.plot([d["time_s"][-1]], [d[key][-1]], "x", color="tab:red", ms=9, mew=2)
        if key == "z":
            ax.axhline(args.height, color="k", lw=0.6, ls=":", label="reference")
            ax.axhline(setup.fall_base_height_m, color="tab:red", lw=0.6, ls=":", label="fall")
        ax.set_title(f"(b) floating base: {label}", fontsize=10)
        ax.set_xlabel("time [s]")
        ax.set_ylabel(label)
        ax.legend(fontsize=7)
    for row in axes:
        for ax in row:
            for c, r in report["controllers"].items():
                ax.axvline(r["push_time_s"], color=COLORS.get(c), lw=0.8, ls="--", alpha=0.7)
            ax.set_xlim(tmin, setup.duration_s)
            ax.grid(alpha=0.3)
    fig.suptitle(f"Push recovery, $z_B^{{ref}}$ = {args.height:.2f} m, I = {args.impulse:g} N s {setup.direction} "
                 f"at a {setup.liftoff}-foot lift-off (dashed: push; x: fall)", fontsize=11)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
    return path


def hip_torque_limit(config_dir):
    """The hips' output peak torque [N m] from robot.yaml: gear ratio x motor peak torque (x efficiency)."""
    a = (load_yaml(Path(config_dir) / "robot.yaml") or {}).get("actuator") or {}
    try:
        return float(a["gear_ratio"]) * float(a["motor_peak_torque_Nm"]) * float(a.get("gearbox_efficiency", 1.0))
    except (KeyError, TypeError, ValueError):
        raise ExperimentError(f"{config_dir}/robot.yaml has no actuator gear_ratio / motor_peak_torque_Nm")


def stance_leg_traces(tr):
    """Per tick: the planner's stance leg's LTI and its distance outside the polytope's leg hexagon
    max(A_leg [q_rear, q_fore] - b_leg) [rad] (double support: the worse leg)."""
    q, lti, plan, mft = tr["q"], tr["lti"], tr["plan"], tr["mft"]
    by_tick = {int(t): s for t, s in zip(plan["tick"], plan["stance_leg"])}
    t_out, l_out, v_out = [], [], []
    for i, tick in enumerate(q["tick"]):
        s = by_tick.get(int(tick), -1)
        vr, vl = mft["mft_violation_right"][i], mft["mft_violation_left"][i]
        lr, ll = lti["lti_right"][i], lti["lti_left"][i]
        t_out.append(q["time_s"][i])
        l_out.append(lr if s == 0 else ll if s == 1 else min(lr, ll))
        v_out.append(vr if s == 0 else vl if s == 1 else max(vr, vl))
    return t_out, l_out, v_out


def plot_fig67(path, args, setup, report, traces):
    """The paper's Fig. 6/7 quantities for each controller (columns): base height and pitch, the stance leg's
    LTI with the preferable space's bound (LTI >= 0.7, which the polytope approximates) and its distance outside
    the polytope, the hip torque commands against the actuators' peak torque."""
    plt = pyplot()
    limit = hip_torque_limit(args.config_dir)
    cs = args.controllers[:2]
    fig, axes = plt.subplots(4, len(cs), figsize=(6.2 * len(cs), 10), dpi=110, squeeze=False, sharex=True)
    tmin = max(0.0, min(r["push_time_s"] for r in report["controllers"].values()) - 1.0)
    for col, c in enumerate(cs):
        tr, r = traces[c], report["controllers"][c]
        name = CONTROLLER_NAMES.get(c, c)
        state = "recovered" if r["recovered"] else ("FELL" if r["fell"] else "not recovered")
        ax = axes[0][col]
        ax.plot(tr["q"]["time_s"], tr["q"]["z"], color=COLORS.get(c), lw=1.2, label="base height")
        ax.axhline(args.height, color="k", lw=0.6, ls=":", label="reference")
        ax.set_ylabel("base height [m]")
        ax.set_title(f"{name}: {args.impulse:g} N s at {args.height:.2f} m, {state}",
                     color="black" if r["recovered"] else "tab:red", fontsize=10)
        ax.legend(fontsize=7, loc="lower left")
        ax = axes[1][col]
        ax.plot(tr["q"]["time_s"], tr["q"]["pitch"], color=COLORS.get(c), lw=1.2)
        ax.set_ylabel("pitch [rad]")
        ax = axes[2][col]
        t, l, v = stance_leg_traces(tr)
        ax.plot(t, l, color=COLORS.get(c), lw=1.2, label="stance-leg LTI")
        ax.axhline(0.7, color="k", lw=0.8, ls="--", label="MFT space bound LTI 0.7")
        ax.set_ylabel("stance-leg LTI")
        ax.set_ylim(0, 1.02)
        ax2 = ax.twinx()
        ax2.plot(t, v, color="tab:green", lw=0.9, alpha=0.8, label="max(A q - b), stance leg")
        ax2.axhline(0.0, color="tab:green", lw=0.6, ls=":")
        ax2.set_ylabel("outside the polytope [rad]", color="tab:green")
        ax.legend(fontsize=7, loc="lower left")
        ax2.legend(fontsize=7, loc="lower right")
        ax = axes[3][col]
        tau = tr["tau_cmd"]
        for key, label, ls in (("tau_q4", "$\\tau_4$ right rear", "-"), ("tau_q6", "$\\tau_6$ right fore", "--"),
                               ("tau_q8", "$\\tau_8$ left rear", "-."), ("tau_q10", "$\\tau_{10}$ left fore", ":")):
            ax.plot(tau["time_s"], tau[key], ls, lw=1.0, label=label)
        for sgn in (1, -1):
            ax.axhline(sgn * limit, color="tab:red", lw=0.8, ls="--")
        ax.text(tmin + 0.05, limit * 0.9, f"peak {limit:.1f} N m", color="tab:red", fontsize=7, va="top")
        ax.set_ylabel("hip torque command [N m]")
        ax.set_xlabel("time [s]")
        ax.legend(fontsize=7, ncol=2, loc="lower left")
        for ax in axes[:, col]:
            ax.axvline(r["push_time_s"], color="tab:gray", lw=0.8, ls="--")
            if r["fell"]:
                ax.axvline(r["fall_time_s"], color="tab:red", lw=0.8)
            ax.set_xlim(tmin, setup.duration_s)
            ax.grid(alpha=0.3)
    fig.suptitle("Fig. 6/7 equivalents: base, stance-leg MFT, hip torques (dashed grey: push; red: fall)", fontsize=11)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
    return path
