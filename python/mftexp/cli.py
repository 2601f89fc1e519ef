"""Command line of mft-experiment."""
import argparse
import json
import os
import signal
import sys
import time
from pathlib import Path

from . import push as _push, sweep as _sweep, video as _video
from .common import (DEFAULT_BIN, DEFAULT_CONFIG, REPO, REGISTRY, ExperimentError, Interrupted, bounded, check_setup,
                     load_text, log, fmt_duration, snapshot_binaries)

HEIGHT_RANGE = (0.30, 0.46)
DESCRIPTION = """mft-experiment: the paper's experiments (section IV) on the real multi-process stack, in lockstep.

  push-sweep  largest recovered impulse per base height and controller (Table II): table.md/.csv, push_sweep.png
  case        one push with both controllers, the paper's Fig. 6 as a PNG and a side-by-side video (case.mp4)
  terrain     blind walking over the course (board, slope, rough ground) with both controllers, Fig. 8 as a PNG
              and a side-by-side video (terrain.mp4)
  terrain-scan  the course walked in process from many start offsets (the gait's phase at the board's edge):
              how often each height, speed and controller gets over it; terrain_scan.md/.csv/.png
  recovery-map  recovery probability over impulse, gait phase (8 per cycle) and direction, in process by
              default: I_50 / I_90, I_max per phase, outcomes by cause; table.md, heatmaps.png, probability.png
  ablation    Table II with each departure from the paper's setup (a profile, the recovery rule) toggled alone,
              and I_max against the slack weight: ablation.md/.csv/.png
  worker      a Dask worker for push-sweep/ablation --scheduler on several machines (docs/guide/cluster-studies.md)

Every subcommand has --help. Progress goes to stderr; errors are one line (exit status 2); Ctrl-C or SIGTERM
keeps what finished (exit status 130) and stops every stack this tool started."""


class Parser(argparse.ArgumentParser):
    def error(self, message):  # one line, status 2, like every other error of this tool
        self.print_usage(sys.stderr)
        print(f"{self.prog}: error: {message}", file=sys.stderr)
        sys.exit(2)


def _numbers(text, noun, valid, why):
    """A comma-separated list of numbers (3 decimals), each passing `valid`, else `why` (formatted with it)."""
    try:
        xs = [round(float(x), 3) for x in text.split(",") if x.strip()]
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a comma-separated list of {noun}s: {text!r}")
    if not xs:
        raise argparse.ArgumentTypeError(f"no {noun} given")
    for x in xs:
        if not valid(x):
            raise argparse.ArgumentTypeError(why.format(x))
    repeated = sorted({x for x in xs if xs.count(x) > 1})
    if repeated:  # each would run twice and fill the same table cell
        raise argparse.ArgumentTypeError(f"{noun} {', '.join(f'{x:g}' for x in repeated)} given twice")
    return xs


def heights_list(text):
    return _numbers(text, "height", lambda h: HEIGHT_RANGE[0] <= h <= HEIGHT_RANGE[1],
                    "height {} m is outside the planner's window " + f"{HEIGHT_RANGE} m")


def speeds_list(text):
    return _numbers(text, "speed", lambda v: 0 < v <= 0.6, "speed {} m/s is outside (0, 0.6] m/s (planner.yaml max_speed_mps)")


def controllers_list(text):
    cs = [x.strip() for x in text.split(",") if x.strip()]
    for c in cs:
        if c not in ("mft", "sa", "none"):
            raise argparse.ArgumentTypeError(f"unknown controller {c!r} (mft, sa or none)")
    if not cs:
        raise argparse.ArgumentTypeError("no controller given")
    return cs


def positive(text):
    try:
        v = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number: {text!r}")
    if not v > 0 or v != v or v == float("inf"):
        raise argparse.ArgumentTypeError(f"must be a positive number: {text!r}")
    return v


def height(text):
    return heights_list(text)[0]


domain_id = bounded(int, 0, 232, "DDS domain id must be 0..232: {v}")


def add_common(p, workers=True):
    p.add_argument("--bin-dir", default=str(DEFAULT_BIN), help="service executables (default %(default)s)")
    p.add_argument("--config-dir", default=str(DEFAULT_CONFIG), help="configuration folder (default %(default)s)")
    p.add_argument("--profile", action="append", default=[], metavar="NAME",
                   help="configuration profile config/profiles/NAME.yaml (repeatable, applied in order; default: "
                        "none, the paper's setup; docs/guide/profiles.md); passed to the supervisor")
    p.add_argument("--domain-base", type=domain_id, default=90,
                   help="DDS domain of the first stack; stack i uses domain-base + i (default %(default)s: "
                        "no test uses 90-99; the integration tests take 100-219)")
    if workers:
        p.add_argument("--workers", type=int, default=2, choices=range(1, 9), metavar="N",
                       help="stacks run in parallel, one per core (default %(default)s)")
    p.add_argument("--no-snapshot", dest="snapshot", action="store_false",
                   help="use --bin-dir directly instead of a copy of its services in OUT/bin (the copy keeps a "
                        "rebuild of the shared build folder from breaking or changing a running experiment)")
    p.add_argument("--json", action="store_true", help="print the result as JSON on stdout")
    p.add_argument("--quiet", action="store_true", help="no progress lines")


def add_distributed(p):
    g = p.add_argument_group("several machines (Dask distributed; docs/guide/cluster-studies.md)")
    g.add_argument("--scheduler", metavar="ADDRESS",
                   help="run every stack run as a task on the workers of this Dask scheduler (tcp://HOST:8786) "
                        "instead of --workers stacks here; results.jsonl, the table and resuming are the same")
    g.add_argument("--in-flight", type=int, metavar="N",
                   help="with --scheduler: searches (one run each) in flight at once (default: the workers' threads "
                        "when the study starts)")
    g.add_argument("--domain-slots", type=int, default=10, metavar="N",
                   help="with --scheduler: a worker machine runs its stacks on domains domain-base .. domain-base+N-1, "
                        "each held by one run at a time (default %(default)s)")
    g.add_argument("--worker-wait", type=positive, default=120.0, metavar="S",
                   help="with --scheduler: give up when no worker is connected for this long [s] (default 120)")


def add_push_setup(p):
    g = p.add_argument_group("push and recovery criteria")
    g.add_argument("--direction", choices=("forward", "backward"), default="forward", help="push direction (default forward)")
    g.add_argument("--liftoff", choices=("right", "left"), default="right",
                   help="the push comes right after this foot lifts off (default right)")
    g.add_argument("--push-after", type=positive, default=3.0,
                   help="the push is armed at this time [s] (stepping starts at 1 s) and applied at the next lift-off")
    g.add_argument("--observe", type=positive, default=5.0,
                   help="run length after --push-after [s]; the last 1 s is the recovery window (default 5)")
    g.add_argument("--recovery-rule", choices=("stepping", "no_fall"), default="stepping",
                   help="what counts as recovered: back to stepping in place (default) or no fall within the run; "
                        "both outcomes are recorded either way")
    g.add_argument("--max-speed", type=positive, default=0.05,
                   help="recovered: |mean base speed| over the last 1 s at most this [m/s] (default 0.05)")
    g.add_argument("--height-band", type=positive, default=0.02,
                   help="recovered: mean base height over the last 1 s within this of the second before the push [m]")
    g.add_argument("--max-pitch", type=positive, default=0.1, help="recovered: |pitch| over the last 1 s [rad]")
    g.add_argument("--min-touchdowns", type=int, default=2, help="recovered: touchdowns in the last 1 s (still stepping)")


def add_study_options(p, kind):
    """What every resumable study (push-sweep, ablation) takes: its folder, the push set-up, the stacks and the
    executor."""
    p.add_argument("--out", help=f"output folder; an existing one is resumed (default runs/{kind}-<time>)")
    add_push_setup(p)
    add_common(p)
    add_distributed(p)


def add_search(p, default):
    p.add_argument("--search", choices=("linear", "coarse", "bisect"), default=default,
                   help=f"linear: the paper's scan, exact; coarse: --coarse steps, then the step grid at the first "
                        f"coarse failure; bisect: quick, not equivalent where recovery is not monotone (default "
                        f"{default})")
    p.add_argument("--coarse", type=positive, default=0.5, help="coarse step of --search coarse [N s] (default 0.5)")
    p.add_argument("--above", type=float, default=1.0,
                   help="also run this far above the first failure [N s] to report recoveries there (default 1)")
    p.add_argument("--no-speculation", dest="speculate", action="store_false",
                   help="a slot with no cell left to start stays idle; by default it runs the impulses a cell's "
                        "search will ask for next if the runs in flight recover, and the search takes their "
                        "outcomes when it gets there (the same runs, results and table; only the wall time differs)")
    p.add_argument("--inprocess", action="store_true",
                   help="run mft-closedloop (the same libraries, configs and recovery verdict in one process, about "
                        "8x faster here) instead of the multi-process stack")


def make_setup(args):
    from .push import PushSetup, Criteria
    if args.observe < 2.0:
        raise ExperimentError("--observe must be at least 2 s (the recovery window is the last 1 s)")
    return PushSetup(push_after_s=args.push_after, observe_s=args.observe, liftoff=args.liftoff,
                     direction=args.direction, profiles=list(args.profile),
                     criteria=Criteria(rule=args.recovery_rule, max_speed_mps=args.max_speed, height_band_m=args.height_band,
                                       max_pitch_rad=args.max_pitch, min_touchdowns=args.min_touchdowns))


def add_push_sweep_command(sub):
    """push-sweep: Table II."""
    s = sub.add_parser("push-sweep", help="Table II: the largest recovered impulse per height and controller",
                       description=_sweep.__doc__ + "\n" + _push.__doc__,
                       formatter_class=argparse.RawDescriptionHelpFormatter)
    s.add_argument("--heights", type=heights_list, default=[0.38, 0.40, 0.42, 0.44, 0.46],
                   help="reference base heights [m], comma-separated (default 0.38,0.40,0.42,0.44,0.46)")
    s.add_argument("--controllers", type=controllers_list, default=["sa", "mft"], help="default sa,mft")
    s.add_argument("--start", type=positive, default=3.0, help="first impulse [N s] (default 3, the paper's)")
    s.add_argument("--step", type=positive, default=0.1, help="impulse grid step [N s] (default 0.1, the paper's)")
    s.add_argument("--max-impulse", type=positive, default=30.0, help="largest impulse tried [N s] (default 30)")
    add_search(s, "linear")
    s.add_argument("--no-rawlogs", dest="keep_rawlogs", action="store_false",
                   help="do not keep the rawlogs of each cell's boundary runs")
    add_study_options(s, "experiment")


def add_case_command(sub):
    """case: one push, the paper's Fig. 6."""
    c = sub.add_parser("case", help="one push, both controllers, the paper's Fig. 6",
                       description="One push at one height with both controllers (recorded), and the paper's "
                                   "Fig. 6 as a PNG: hip joint angles of both legs; base height, pitch and speed; "
                                   "and both runs side by side as a video (case.mp4, docs/guide/videos.md).")
    c.add_argument("--height", type=height, default=0.44, help="reference base height [m] (default 0.44)")
    c.add_argument("--impulse", type=positive, default=7.1, help="impulse [N s] (default 7.1, the paper's case)")
    c.add_argument("--controllers", type=controllers_list, default=["mft", "sa"], help="default mft,sa")
    c.add_argument("--out", help="output folder (default runs/case-<time>)")
    add_push_setup(c)
    add_common(c)
    _video.add_video_options(c)


def add_terrain_command(sub):
    """terrain: blind walking over the course, the paper's Fig. 8."""
    t = sub.add_parser("terrain", help="blind walking over the course with both controllers, the paper's Fig. 8",
                       description="Blind walking over config/terrain/<terrain>.yaml (3 cm board, 6 degree slope, "
                                   "about 2 cm rough ground) with both controllers, recorded. Success = the base "
                                   "passed the end of the course without a fall. Reports whether the left leg stayed "
                                   "inside the MFT preferable space (config/mft_space.yaml leg polygon) while in "
                                   "stance on the up-slope, and draws the paper's Fig. 8 and a side-by-side video (terrain.mp4). "
                                   "The runs carry the profile kv-0.145, the one departure the slope needs "
                                   "(--paper-setup: none).")
    t.add_argument("--speed", type=positive, default=0.25, help="commanded walking speed [m/s] (default 0.25)")
    t.add_argument("--height", type=height, default=0.42, help="reference base height [m] (default 0.42)")
    t.add_argument("--terrain", default="course", help="terrain file under config/terrain (default course)")
    t.add_argument("--duration", type=positive, help="run length [s] (default: enough to pass the course)")
    t.add_argument("--controllers", type=controllers_list, default=["mft", "sa"], help="default mft,sa")
    t.add_argument("--out", help="output folder (default runs/terrain-<time>)")
    t.add_argument("--paper-setup", action="store_true",
                   help="without the profile kv-0.145 that the scenario otherwise carries (with the paper's k_v = 0.16 "
                        "the robot stalls on the slope; docs/results/terrain.md)")
    add_common(t)
    _video.add_video_options(t)


def add_terrain_scan_command(sub):
    """terrain-scan: the course from many start offsets."""
    from . import terrain_scan as _scan
    ts = sub.add_parser("terrain-scan", help="the course from many start offsets: how often blind walking gets over it",
                        description=_scan.__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ts.add_argument("--heights", type=heights_list, default=[0.42, 0.44],
                    help="reference base heights [m] (default 0.42,0.44: terrain's default and 0.44)")
    ts.add_argument("--speeds", type=speeds_list, default=[0.25], help="commanded speeds [m/s] (default 0.25)")
    ts.add_argument("--controllers", type=controllers_list, default=["mft", "sa"], help="default mft,sa")
    ts.add_argument("--shift-span", type=positive, default=0.10,
                    help="the course is shifted from -SPAN to +SPAN [m] (default 0.10: more than a step)")
    ts.add_argument("--shift-step", type=positive, default=0.01, help="offset step [m] (default 0.01)")
    ts.add_argument("--terrain", default="course", help="terrain file under config/terrain (default course)")
    ts.add_argument("--duration", type=positive, help="run length [s] (default: enough to pass the course)")
    ts.add_argument("--out", help="output folder (default runs/terrain-scan-<time>)")
    ts.add_argument("--paper-setup", action="store_true",
                    help="without the profile kv-0.145 that terrain's runs carry (see terrain --help)")
    add_common(ts)


def add_ablation_command(sub):
    """ablation: each departure alone, and a parameter's sensitivity."""
    from . import ablation as _abl
    a = sub.add_parser("ablation", help="each departure from the paper's setup alone; I_max against the slack weight",
                       description=_abl.__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    a.add_argument("--heights", type=heights_list, default=[0.38, 0.44, 0.46], help="default 0.38,0.44,0.46")
    a.add_argument("--controllers", type=controllers_list, default=["sa", "mft"], help="default sa,mft")
    a.add_argument("--toggles", type=lambda t: [x.strip() for x in t.split(",") if x.strip()],
                   help="only these variants (profile names, rule-no-fall); default: every profile and the rule")
    a.add_argument("--start", type=positive, default=3.0, help="first impulse [N s] (default 3)")
    a.add_argument("--step", type=positive, default=0.1, help="fine grid step [N s] (default 0.1)")
    a.add_argument("--max-impulse", type=positive, default=30.0, help="largest impulse tried [N s] (default 30)")
    add_search(a, "coarse")
    a.add_argument("--param", default="wbc.weights.slack",
                   help="sensitivity: a dotted configuration key FILE.a.b (default wbc.weights.slack)")
    a.add_argument("--values", type=lambda t: [float(x) for x in t.split(",") if x.strip()],
                   default=[1e1, 1e2, 1e3, 1e4, 1e5], help="sensitivity values (default 1e1,1e2,1e3,1e4,1e5)")
    a.add_argument("--sensitivity-height", type=height, default=0.44, help="sensitivity height [m] (default 0.44)")
    a.add_argument("--no-sensitivity", dest="sensitivity", action="store_false", help="skip the sensitivity")
    add_study_options(a, "ablation")


def add_worker_command(sub):
    """worker: a Dask worker with this clone's build."""
    w = sub.add_parser("worker", help="a Dask worker for --scheduler (this clone's build; docs/guide/cluster-studies.md)",
                       description="Starts dask-worker for SCHEDULER with this clone's mft-experiment importable and "
                                   "its services (--bin-dir) as the binaries of every run; runs until stopped "
                                   "(Ctrl-C). Equivalent by hand: PYTHONPATH=REPO/python "
                                   "MFT_BIN_DIR=BIN dask-worker SCHEDULER --nthreads N. Each run takes a DDS domain "
                                   "that no other run on this machine holds (lock files in MFT_EXPERIMENT_SCRATCH, "
                                   "default TMPDIR/mft-experiment-worker).",
                       epilog="Everything after -- goes to dask-worker as it is, e.g. "
                              "mft-experiment worker tcp://head:8786 -- --host 10.0.0.2 --local-directory /scratch")
    w.add_argument("scheduler", metavar="SCHEDULER", help="the scheduler's address, tcp://HOST:8786")
    w.set_defaults(dask_args=[])
    w.add_argument("--nthreads", type=int, default=max(1, os.cpu_count() or 1), metavar="N",
                   help="stacks at once on this machine (default: one per core, %(default)s)")
    w.add_argument("--bin-dir", default=str(DEFAULT_BIN), help="service executables (default %(default)s)")
    w.add_argument("--name", help="worker name shown in the client's per-worker counts (default: its address)")
    w.add_argument("--no-nanny", action="store_true", help="no nanny process (a killed worker is not restarted)")


def add_recovery_map_command(sub):
    """recovery-map: the recovery probability over impulse, gait phase and direction (mftexp.recovery_args)."""
    from . import recovery_args
    recovery_args.add_parser(sub, heights_list, controllers_list, positive, add_common, add_distributed)


def build_parser():
    p = Parser(prog="mft-experiment", description=DESCRIPTION,
               formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = p.add_subparsers(dest="command", metavar="{push-sweep,case,terrain,terrain-scan,recovery-map,ablation,worker}", parser_class=Parser)
    sub.required = True

    for add in (add_push_sweep_command, add_case_command, add_terrain_command, add_terrain_scan_command,
                add_recovery_map_command, add_ablation_command, add_worker_command):
        add(sub)
    return p


def check_scheduler_address(text, what="--scheduler"):
    import re
    if not re.fullmatch(r"(tcp|tls|ucx)://\S+", text):
        raise ExperimentError(f"{what} {text!r}: expected an address like tcp://HOST:8786")


def check_distributed_args(args):
    check_scheduler_address(args.scheduler)
    if args.in_flight is not None and not 1 <= args.in_flight <= 4096:
        raise ExperimentError("--in-flight must be 1..4096")
    if not 1 <= args.domain_slots or args.domain_base + args.domain_slots - 1 > 232:
        raise ExperimentError(f"--domain-base {args.domain_base} with --domain-slots {args.domain_slots} leaves the "
                              f"DDS domains 0..232")


def cmd_worker(args):
    """execs dask-worker with this clone's mftexp importable and its build as the binaries."""
    import importlib.util
    if importlib.util.find_spec("distributed") is None:
        raise ExperimentError(f"Dask distributed is missing for {sys.executable} (Debian: apt-get install "
                              f"python3-distributed)")
    check_scheduler_address(args.scheduler, "SCHEDULER")
    check_setup(args.bin_dir, DEFAULT_CONFIG)
    if args.nthreads < 1:
        raise ExperimentError("--nthreads must be at least 1")
    # No statistical profiler (it samples every thread each 10 ms, on cores the stacks need).
    env = dict(os.environ, MFT_BIN_DIR=str(Path(args.bin_dir).resolve()), DASK_DISTRIBUTED__WORKER__PROFILE__ENABLED="False",
               PYTHONPATH=os.pathsep.join([str(REPO / "python")] +
                                          [p for p in [os.environ.get("PYTHONPATH")] if p]))
    extra = list(args.dask_args)
    argv = [sys.executable, "-m", "distributed.cli.dask_worker", args.scheduler, "--nthreads", str(args.nthreads),
            "--no-dashboard"] + (["--name", args.name] if args.name else []) + (["--no-nanny"] if args.no_nanny else []) \
        + extra
    log(f"dask-worker for {args.scheduler}: {args.nthreads} threads, binaries {env['MFT_BIN_DIR']}")
    os.execve(sys.executable, argv, env)


def use_snapshot(args):
    if getattr(args, "scheduler", None):
        return  # the workers use their own builds (checked against this clone's commit)
    if args.snapshot:
        Path(args.out).mkdir(parents=True, exist_ok=True)
        args.bin_dir = str(snapshot_binaries(args.bin_dir, Path(args.out) / "bin"))


def cmd_push_sweep(args):
    from .sweep import Sweep
    from . import report
    from dataclasses import asdict
    if args.step > 5 or args.start > args.max_impulse:
        raise ExperimentError("need --start <= --max-impulse and --step <= 5 N s")
    if args.max_impulse > 100:
        raise ExperimentError("--max-impulse is at most 100 N s (the scenario format's limit)")
    setup = make_setup(args)
    args.out = args.out or str(REPO / "runs" / f"experiment-{time.strftime('%Y%m%d-%H%M%S')}")
    use_snapshot(args)
    if args.inprocess:
        args.keep_rawlogs = False
    sweep = Sweep(args, setup)
    load0 = sweep.announce(f"push-sweep into {args.out}: heights {args.heights}, controllers {args.controllers}, "
                           f"{args.direction} push, grid {args.start:g}+k*{args.step:g} N s ({args.search}), ")
    wall = None
    try:
        wall = sweep.run()
    finally:
        sweep.executor.close()
        table = report.write_tables(args.out, sweep.results, args.heights, args.controllers, args.direction,
                                    sweep.grid, dict(asdict(setup), profiles=sweep.variants["default"].profiles),
                                    wall, (load0, load_text()))
    png = report.plot_sweep(args.out, table, args.direction)
    summary = report.summary_json(table, sweep.results, sweep.grid,
                                  dict(asdict(setup), profiles=sweep.variants["default"].profiles), wall, sweep.new_runs)
    summary.update({"progress": sweep.progress.snapshot(), "executor": sweep.executor.info(),
                    "load_average": [load0, load_text()], "out": args.out, "table_md": str(Path(args.out) / "table.md"),
                    "table_csv": str(Path(args.out) / "table.csv"), "plot": str(png)})
    (Path(args.out) / "summary.json").write_text(json.dumps(summary, indent=1) + "\n")
    log(f"done in {fmt_duration(wall)} ({sweep.new_runs} new runs"
        + (f"; runs per worker, recorded re-runs included: {sweep.progress.workers_text()}"
           if sweep.progress.per_worker else "")
        + f"): {args.out}/table.md, table.csv, push_sweep.png")
    if args.json:
        print(json.dumps(summary, indent=1))
    else:
        print((Path(args.out) / "table.md").read_text())
    return 0


def main(argv=None):
    parser = build_parser()
    argv = list(sys.argv[1:] if argv is None else argv)
    dask_args = []
    if argv[:1] == ["worker"] and "--" in argv:  # dask-worker's own options, passed on untouched
        cut = argv.index("--")
        argv, dask_args = argv[:cut], argv[cut + 1:]
    args = parser.parse_args(argv)
    if args.command == "worker":
        args.dask_args = dask_args

    def on_term(*_):
        raise KeyboardInterrupt()
    signal.signal(signal.SIGTERM, on_term)
    try:
        if args.command == "worker":
            return cmd_worker(args)
        if getattr(args, "scheduler", None):
            check_distributed_args(args)
        elif args.domain_base + getattr(args, "workers", 2) - 1 > 232:
            raise ExperimentError(f"--domain-base {args.domain_base} leaves no DDS domain (0..232) for every stack")
        if getattr(args, "scheduler", None):  # the stacks run on the workers, with their own builds
            if not (Path(args.config_dir) / "robot.yaml").is_file():
                raise ExperimentError(f"configuration folder {args.config_dir} has no robot.yaml")
        else:
            check_setup(args.bin_dir, args.config_dir,
                        need=("mft-sim", "mft-estimator", "mft-planner", "mft-wbc") +
                             (("mft-record", "mft-export") if args.command in ("case", "terrain") or
                              getattr(args, "keep_rawlogs", False) else ()) +
                             (("mft-closedloop",) if getattr(args, "inprocess", False) or
                              args.command in ("terrain-scan", "recovery-map") else ()))
        if args.command == "push-sweep":
            return cmd_push_sweep(args)
        if args.command in ("case", "terrain"):
            args.out = args.out or str(REPO / "runs" / f"{args.command}-{time.strftime('%Y%m%d-%H%M%S')}")
            use_snapshot(args)
        if args.command == "case":
            from .case import cmd_case
            return cmd_case(args, make_setup(args))
        if args.command == "terrain":
            from .terrain import cmd_terrain
            return cmd_terrain(args)
        if args.command == "recovery-map":
            from .recovery_map import cmd_recovery_map
            args.out = args.out or str(REPO / "runs" / f"recovery-map-{time.strftime('%Y%m%d-%H%M%S')}")
            use_snapshot(args)
            return cmd_recovery_map(args)
        if args.command == "terrain-scan":
            from .terrain_scan import cmd_terrain_scan
            args.out = args.out or str(REPO / "runs" / f"terrain-scan-{time.strftime('%Y%m%d-%H%M%S')}")
            use_snapshot(args)
            return cmd_terrain_scan(args)
        if args.command == "ablation":
            from .ablation import cmd_ablation
            args.out = args.out or str(REPO / "runs" / f"ablation-{time.strftime('%Y%m%d-%H%M%S')}")
            use_snapshot(args)
            return cmd_ablation(args, make_setup(args))
    except ExperimentError as e:
        REGISTRY.stop_all()
        print(f"mft-experiment: error: {e}", file=sys.stderr)
        return 2
    except (KeyboardInterrupt, Interrupted):
        REGISTRY.stop_all()
        print("mft-experiment: interrupted; " + ("no table written (a scan takes minutes: run it again)"
                                                if args.command == "terrain-scan" else
                                                "finished runs are kept (run the same command to resume)"), file=sys.stderr)
        return 130
    except UnicodeDecodeError as e:
        REGISTRY.stop_all()
        print(f"mft-experiment: error: a file is not UTF-8 text (byte {e.start}: {e.reason})", file=sys.stderr)
        return 2
    except OSError as e:  # an --out that cannot be written (/proc, a file, read-only, a full disk)
        REGISTRY.stop_all()
        where = f": {e.filename}" if e.filename else ""
        print(f"mft-experiment: error: {e.strerror or e}{where}", file=sys.stderr)
        return 2
    return 0
