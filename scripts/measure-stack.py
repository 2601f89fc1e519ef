#!/usr/bin/env python3
"""Loop benchmark of the multi-process stack (docs/results/loop-benchmark.md).

Runs rounds of the same scenario (10 s step in place), each round interleaved so that a shared machine's load
hits every measurement alike:
  * the in-process reference: mft-closedloop, the whole chain in one process (no DDS);
  * one plain lockstep run per variant through services/mft-supervisor and the real services, traced hop by
    hop (MFT_HOP_TRACE): the per-tick split into each DDS hop and each service's compute, p50/p99/max;
  * one lockstep run recording every topic (the recording cost, against the round's first variant);
  * (unless --skip-realtime) a realtime run, traced hop by hop from the sensor sample to the command.
Then the machine's own wake-up floor (mft-wakeup: 1 kHz timer lateness per CPU, thread wake-ups on one core
and across cores), the figure each hop and the realtime latency stand on.
Reported: each variant's real-time factor, its ratio to the in-process speed (per round, in-process wall time
over lockstep wall time, and the median over the rounds), the hop table of its median run, the recording
slowdown, and (unless --skip-realtime) the realtime sensor-to-command latency over a --realtime-s run.
The load average is recorded before and after: run it on an idle machine for figures to quote.

Variants (--variant LABEL=ARGS, repeatable) are extra supervisor options, for A/B comparisons in one command:
  measure-stack.py --variant pinned="--chain-cpu auto" --variant free="--chain-cpu none" --skip-realtime
Without --variant there is one, "default" (the supervisor's defaults).
Multi-process runs should not share a DDS domain with anything else: --private-net runs the whole measurement
in a private network namespace (needs root or user namespaces; `unshare -n`), as the tests do.
"""
import argparse
import importlib.util
import json
import os
import shlex
import shutil
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "python"))
from mftstack.scripts import run_script  # noqa: E402
from mftstack.paths import DEFAULT_BIN, REPO, SCENARIOS, SUPERVISOR  # noqa: E402

SCENARIO = SCENARIOS / "step-in-place.yaml"
LOCKSTEP_TIMEOUT_S = 300  # one 10 s lockstep run takes 1-10 s; a stuck one is ended (with its services)
INPROCESS_TIMEOUT_S = 120
NETNS_ENV = "MFT_MEASURE_STACK_NETNS"


class MeasureError(Exception):
    pass


def progress(msg):
    print(msg, file=sys.stderr, flush=True)


def load_average():
    one, five, fifteen = os.getloadavg()
    return {"1min": round(one, 2), "5min": round(five, 2), "15min": round(fifteen, 2)}


def hop_table_module():
    spec = importlib.util.spec_from_file_location("hop_table", REPO / "scripts" / "hop-table.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def run_inprocess(args):
    cmd = [str(Path(args.bin_dir) / "mft-closedloop"), "--scenario", str(args.scenario), "--json"]
    try:
        p = subprocess.run(cmd, capture_output=True, text=True, timeout=INPROCESS_TIMEOUT_S)
    except subprocess.TimeoutExpired:
        raise MeasureError(f"mft-closedloop did not finish within {INPROCESS_TIMEOUT_S} s")
    try:
        summary = json.loads(p.stdout)["summary"]
    except (ValueError, KeyError):
        raise MeasureError(f"mft-closedloop gave no summary (exit {p.returncode}): {p.stderr.strip()[-500:]}")
    if p.returncode != 0:
        raise MeasureError(f"mft-closedloop failed (exit {p.returncode}): {p.stderr.strip()[-500:]}")
    return summary


def run_stack(args, tmp, scenario, mode, tag, extra=(), record=False, hops=False, timeout_s=LOCKSTEP_TIMEOUT_S):
    run_dir = Path(tmp) / f"run-{mode}-{tag}"
    env = dict(os.environ)
    env.pop("MFT_HOP_TRACE", None)
    if hops:  # the services write <service>.hops.csv into the run folder (services/runtime/hop_trace.hpp)
        run_dir.mkdir(parents=True, exist_ok=True)
        env["MFT_HOP_TRACE"] = str(run_dir)
    cmd = [sys.executable, str(SUPERVISOR), "run", str(scenario), "--domain", str(args.domain), "--mode", mode,
           "--json", "--run-dir", str(run_dir), "--bin-dir", str(args.bin_dir)] + list(extra)
    rawlog = Path(tmp) / f"{tag}.rawlog"
    if record:
        cmd += ["--record", str(rawlog)]
    try:
        # The supervisor's children die with it (PR_SET_PDEATHSIG), so ending it on a timeout ends the stack.
        p = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout_s, env=env)
    except subprocess.TimeoutExpired:
        raise MeasureError(f"the {mode} run {tag} did not finish within {timeout_s:.0f} s (logs: {run_dir})")
    try:
        summary = json.loads(p.stdout)
    except ValueError:
        raise MeasureError(f"the {mode} run {tag} gave no summary (exit {p.returncode}): {p.stderr.strip()[-1500:]}")
    if p.returncode != 0 or not summary.get("ok"):
        raise MeasureError(f"the {mode} run {tag} failed: {summary.get('error')} {summary.get('failed')}")
    if record and rawlog.exists():
        rawlog.unlink()
    sim = dict(summary["services"]["mft-sim"])
    for key in ("deadline_misses", "deadline_misses_by_service", "sensor_to_command_latency_us", "wbc_tick_us",
                "chain_cpu", "chain_transport", "rt_priorities", "rt_threads"):
        sim["run_" + key] = summary.get(key)  # the supervisor's figures over every service
    if hops:
        sim["hop_table"] = hop_table_module().hop_table(run_dir, realtime=(mode == "realtime"))
    if "mft-record" in summary["services"]:
        sim["recorder_dropped_samples"] = summary["services"]["mft-record"].get("dropped_samples")
    shutil.rmtree(run_dir, ignore_errors=True)
    return sim


def parse_variants(specs, chain_cpu):
    variants = []
    for spec in specs or []:
        label, sep, rest = spec.partition("=")
        if not sep or not label.strip():
            raise MeasureError(f"--variant {spec!r}: expected LABEL=SUPERVISOR-OPTIONS")
        variants.append((label.strip(), shlex.split(rest)))
    if not variants:
        variants = [("default", [])]
    if chain_cpu is not None:
        variants = [(label, ["--chain-cpu", chain_cpu] + extra) for label, extra in variants]
    if len({label for label, _ in variants}) != len(variants):
        raise MeasureError("--variant: the labels must differ")
    return variants


def median(values):
    return round(statistics.median(values), 4) if values else None


def measure(args, tmp):
    variants = parse_variants(args.variant, args.chain_cpu)
    out = {"cpus": os.cpu_count(), "allowed_cpus": sorted(os.sched_getaffinity(0)), "scenario": str(args.scenario),
           "rounds": args.runs, "load_average_before": load_average(), "load_averages_per_round": []}
    if os.getloadavg()[0] > 0.5 * (os.cpu_count() or 1):
        progress(f"measure-stack: warning: load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cpus: other jobs "
                 "slow the in-process reference and the stack unevenly, so the ratio is not a figure to quote")
    inprocess = []
    plain = {label: [] for label, _ in variants}
    recorded = []
    for i in range(args.runs):
        progress(f"round {i + 1}/{args.runs} (load {os.getloadavg()[0]:.2f}): in-process, "
                 + ", ".join(f"lockstep {label}" for label, _ in variants)
                 + ("" if args.skip_recording else ", lockstep recording") + " ...")
        out["load_averages_per_round"].append(round(os.getloadavg()[0], 2))
        inprocess.append(run_inprocess(args))
        for label, extra in variants:
            plain[label].append(run_stack(args, tmp, args.scenario, "lockstep", f"{label}-{i}", extra, hops=not args.no_hops))
        if not args.skip_recording:
            s = run_stack(args, tmp, args.scenario, "lockstep", f"rec-{i}", variants[0][1], record=True)
            recorded.append(s)
            if s.get("recorder_dropped_samples"):
                progress(f"  warning: the recorder dropped {s['recorder_dropped_samples']} samples")
    sim_s = inprocess[0]["sim_time_s"]
    wall_in = [s["wall_time_s"] for s in inprocess]
    out["inprocess"] = {"sim_s": sim_s, "wall_s": wall_in, "real_time_factor_median": round(sim_s / statistics.median(wall_in), 2),
                        "us_per_tick_median": round(statistics.median(wall_in) / inprocess[0]["ticks"] * 1e6, 1)}
    out["lockstep"] = {}
    for label, extra in variants:
        runs = plain[label]
        wall = [s["wall_time_s"] for s in runs]
        ratios = [round(w_in / w, 4) for w_in, w in zip(wall_in, wall)]  # speed ratio = in-process wall / lockstep wall
        v = {"supervisor_options": extra, "sim_s": runs[0]["sim_time_s"], "wall_s": wall,
             "real_time_factor_median": round(runs[0]["sim_time_s"] / statistics.median(wall), 2),
             "us_per_tick_median": round(statistics.median(wall) / max(1, runs[0]["ticks"]) * 1e6, 1),
             "ratio_to_inprocess_per_round": ratios, "ratio_to_inprocess_median": median(ratios),
             "resends": sum(s.get("lockstep_resends", 0) for s in runs), "chain_cpu": [s["run_chain_cpu"] for s in runs]}
        if not args.no_hops:  # the table of the run with the median wall time
            v["hop_table"] = sorted(runs, key=lambda s: s["wall_time_s"])[len(runs) // 2]["hop_table"]
        out["lockstep"][label] = v
    if recorded:
        base = plain[variants[0][0]]
        wall_rec = [s["wall_time_s"] for s in recorded]
        out["recording"] = {
            "variant": variants[0][0], "wall_s": wall_rec,
            # Each recorded run against the plain run of the same round: the machine's drift cancels.
            "slowdown_per_round": [round(r / p["wall_time_s"], 3) for r, p in zip(wall_rec, base)],
            "resends": sum(s.get("lockstep_resends", 0) for s in recorded),
            "dropped_samples": sum(s.get("recorder_dropped_samples") or 0 for s in recorded)}
        out["recording"]["slowdown_median"] = median(out["recording"]["slowdown_per_round"])
    if not args.skip_realtime:
        scenario = Path(tmp) / "step-in-place-long.yaml"
        text = Path(args.scenario).read_text().replace("duration_s: 10.0", f"duration_s: {args.realtime_s}")
        scenario.write_text(text.replace("name: step-in-place", "name: step-in-place-long"))
        progress(f"realtime run of {args.realtime_s:g} s (load {os.getloadavg()[0]:.2f}) ...")
        extra = variants[0][1] + (["--stall-probe"] if args.stall_probe else [])
        s = run_stack(args, tmp, scenario, "realtime", "rt", extra, hops=not args.no_hops, timeout_s=args.realtime_s + 300)
        out["realtime"] = {"sim_s": s["sim_time_s"], "deadline_misses": s["run_deadline_misses"],
                           "sensor_to_command_latency_us": s["run_sensor_to_command_latency_us"],
                           "wbc_tick_us": s["run_wbc_tick_us"], "fell": s["fell"], "chain_cpu": s["run_chain_cpu"],
                           "rt_priorities": s["run_rt_priorities"], "rt_threads": s["run_rt_threads"],
                           "sim_wakeup_late_us": s.get("sim_wakeup_late_us"),
                           # the simulator's watchdog misses (a tick > 3 ms without its command), and with
                           # --stall-probe which of them fell in a stall of the machine
                           "sim_deadline_misses": s.get("deadline_misses"),
                           "sim_misses_during_cpu_stalls": s.get("deadline_misses_during_cpu_stalls"),
                           "sim_misses_unexplained": s.get("deadline_misses_unexplained"),
                           # every service's: the readers' while their topic flowed, and outside it (start, stop)
                           "deadline_misses_by_service": s["run_deadline_misses_by_service"]}
        if "hop_table" in s:
            out["realtime"]["hop_table"] = s["hop_table"]
    if not args.skip_wakeup:
        out["machine_wakeup"] = run_wakeup_probe(args)
        if "hop_table" in out.get("realtime", {}):
            out["realtime"]["hops_against_the_floor"] = hops_against_the_floor(out["realtime"]["hop_table"],
                                                                               out["machine_wakeup"])
    out["load_average_after"] = load_average()
    return out


def hops_against_the_floor(table, wakeup):
    """Each realtime hop that carries a sample from one process to the next, against the machine's own thread
    wake-up (mft-wakeup, same run): a hop cannot beat a wake-up, so what its p99 has over the floor is the
    transport's own share. A stack may run unpinned (--chain-cpu none, --stack), where a hop wakes its reader on the
    same core or on the other one: both floors are given, and the excess is taken over the larger (cross-core on a
    multi-core VM); a pinned chain's hops are same-core wake-ups."""
    floors = {where: w["p99"] for where, w in wakeup["wakeup_us"].items()}
    floor = max(floors.values())
    hop_table = hop_table_module()
    rows = []
    for r in table["intervals"]:
        if r["interval"] in hop_table.TRANSPORT_HOPS and r.get("count"):
            rows.append({"hop": r["interval"], "p50": r["p50"], "p99": r["p99"], "max": r["max"],
                         "p99_over_wakeup_floor": round(r["p99"] - floor, 1)})
    computes = [r for r in table["intervals"] if r["interval"] not in hop_table.TRANSPORT_HOPS and r.get("count")]
    return {"wakeup_p99_us": floors, "hops": rows,
            # the chain's p99 if every hop cost only the floor and every compute its own p99 (an upper bound of
            # the floor's share: p99s do not add, so this overstates what four wake-ups cost together)
            "floor_plus_compute_p99_sum_us": round(4 * floor + sum(r["p99"] for r in computes), 1),
            "chain_p99_us": table["tick_us"].get("p99")}


def run_wakeup_probe(args):
    """The machine's own floor (mft-wakeup --rt, SCHED_FIFO as the realtime stack when permitted): 1 kHz timer
    lateness per CPU, thread wake-ups on one core and across cores."""
    exe = Path(args.bin_dir) / "mft-wakeup"
    if not exe.exists():
        raise MeasureError(f"no mft-wakeup in {args.bin_dir} (build it, or pass --skip-wakeup)")
    progress(f"machine wake-up probe (load {os.getloadavg()[0]:.2f}) ...")
    try:
        p = subprocess.run([str(exe), "--json", "--rt"], capture_output=True, text=True, timeout=120)
        return json.loads(p.stdout)
    except subprocess.TimeoutExpired:
        raise MeasureError("mft-wakeup did not finish within 120 s")
    except ValueError:
        raise MeasureError(f"mft-wakeup gave no figures (exit {p.returncode}): {p.stderr.strip()[-300:]}")


def print_report(out):
    hop_table = hop_table_module()
    lb, la = out["load_average_before"], out["load_average_after"]
    print(f"machine: {out['cpus']} cpus (allowed {out['allowed_cpus']}); load average before {lb['1min']} "
          f"{lb['5min']} {lb['15min']}, after {la['1min']} {la['5min']} {la['15min']}; per round "
          f"{out['load_averages_per_round']}")
    ip = out["inprocess"]
    print(f"in-process (mft-closedloop), {ip['sim_s']:g} s: wall {statistics.median(ip['wall_s']):.3f} s median "
          f"-> {ip['real_time_factor_median']}x real time, {ip['us_per_tick_median']} us per tick")
    for label, v in out["lockstep"].items():
        print(f"lockstep [{label}] {' '.join(v['supervisor_options']) or '(defaults)'}: wall "
              f"{statistics.median(v['wall_s']):.3f} s median -> {v['real_time_factor_median']}x real time, "
              f"{v['us_per_tick_median']} us per tick; ratio to in-process {v['ratio_to_inprocess_median']} median "
              f"(per round {v['ratio_to_inprocess_per_round']}); tick re-sends {v['resends']}")
        if "hop_table" in v:
            print("  per-hop table of its median run [us]:")
            hop_table.print_table(v["hop_table"])
    if "recording" in out:
        r = out["recording"]
        print(f"recording every topic [{r['variant']}]: slowdown x{r['slowdown_median']} median (per round "
              f"{r['slowdown_per_round']}); re-sends {r['resends']}, dropped samples {r['dropped_samples']}")
    if "realtime" in out:
        rt = out["realtime"]
        lat = rt["sensor_to_command_latency_us"]
        print(f"realtime, {rt['sim_s']:g} s: sensor-to-command latency p50 {lat['p50']:.0f} us, p99 {lat['p99']:.0f} us, "
              f"max {lat['max']:.0f} us over {lat['count']} ticks; deadline misses {rt['deadline_misses']} (readers and "
              f"simulator), of the simulator {rt['sim_deadline_misses']}"
              + (f": {rt['sim_misses_during_cpu_stalls']} during CPU stalls, {rt['sim_misses_unexplained']} unexplained"
                 if rt.get("sim_misses_unexplained") is not None else ""))
        readers = ", ".join(f"{name} {m.get('reader')} ({m.get('gaps_over_deadline')} measured gaps, "
                            f"{m.get('gaps_during_cpu_stalls')} of them in CPU stalls; +{m.get('outside_stream')} at start/stop)"
                            for name, m in (rt.get("deadline_misses_by_service") or {}).items())
        if "hop_table" in rt:
            print("  per-hop table of the realtime run [us] (the sum is the sensor-to-command latency):")
            hop_table.print_table(rt["hop_table"])
        if "hops_against_the_floor" in rt:
            f = rt["hops_against_the_floor"]
            print(f"  against the machine's thread wake-up p99 {f['wakeup_p99_us']} us: "
                  + "; ".join(f"{h['hop'].split(' ->')[0]}: p99 {h['p99']:.0f} (+{h['p99_over_wakeup_floor']:.0f})"
                              for h in f["hops"])
                  + f"; chain p99 {f['chain_p99_us']} us against 4 wake-ups + computes (p99 sum) "
                  f"{f['floor_plus_compute_p99_sum_us']} us")
        print(f"  readers' DDS deadline misses while their topic flowed (of them, gaps over the deadline measured by "
              f"the reader; outside the stream: the stack starting, stopping): {readers}")
    if "machine_wakeup" in out:
        w = out["machine_wakeup"]
        timers = ", ".join(f"{cpu} p50 {t['p50']:.1f} p99 {t['p99']:.1f} max {t['max']:.0f}" for cpu, t in w["timer_late_us"].items())
        wake = ", ".join(f"{where.replace('_', ' ')} p50 {t['p50']:.1f} p99 {t['p99']:.1f} max {t['max']:.0f}"
                         for where, t in w["wakeup_us"].items())
        print(f"machine wake-up floor (mft-wakeup, {w['scheduling']}) [us]: 1 kHz timer late: {timers}; "
              f"thread wake-up: {wake}")


def reexec_in_private_net():
    """Runs this script again inside `unshare -n` with the loopback up; returns its exit status."""
    if not shutil.which("unshare") or not shutil.which("ip"):
        raise MeasureError("--private-net needs unshare and ip (util-linux, iproute2)")
    argv = [a for a in sys.argv[1:] if a != "--private-net"]
    env = dict(os.environ, **{NETNS_ENV: "1"})
    cmd = ["unshare", "-n", "sh", "-c", 'ip link set lo up && exec "$@"', "sh", sys.executable, str(Path(__file__).resolve())] + argv
    p = subprocess.run(cmd, env=env)
    if p.returncode != 0 and p.returncode not in (1, 2, 130):
        progress(f"measure-stack: the run in a private network namespace ended with status {p.returncode} "
                 "(unshare -n needs root or user namespaces)")
    return p.returncode


def main():
    ap = argparse.ArgumentParser(prog="measure-stack.py", description=__doc__.split("\n\n")[0],
                                 epilog=__doc__.split("\n\n", 1)[1], formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bin-dir", default=str(DEFAULT_BIN), help="service executables")
    ap.add_argument("--scenario", default=str(SCENARIO), help="scenario (default config/scenarios/step-in-place.yaml)")
    ap.add_argument("--domain", type=int, default=71, help="DDS domain id for the runs (default 71)")
    ap.add_argument("--runs", type=int, default=3, help="rounds (in-process, lockstep per variant, recorded; default 3)")
    ap.add_argument("--realtime-s", type=float, default=60.0, help="length of the realtime run [s] (default 60)")
    ap.add_argument("--chain-cpu", metavar="N|auto|none", help="pass --chain-cpu to the supervisor in every variant")
    ap.add_argument("--variant", action="append", metavar="LABEL=OPTIONS", help="a lockstep variant: extra supervisor "
                    "options (repeatable; each round runs every variant once, interleaved)")
    ap.add_argument("--skip-realtime", action="store_true", help="lockstep figures only")
    ap.add_argument("--skip-recording", action="store_true", help="no recorded runs")
    ap.add_argument("--stall-probe", action="store_true", help="realtime run with the simulator's CPU stall probe: "
                    "each deadline miss attributed to a stall of the machine or to the chain (costs ~30 us of p50)")
    ap.add_argument("--skip-wakeup", action="store_true", help="no machine wake-up probe (mft-wakeup)")
    ap.add_argument("--no-hops", action="store_true", help="do not trace the plain lockstep runs and the realtime run "
                    "hop by hop")
    ap.add_argument("--hops", action="store_true", help=argparse.SUPPRESS)  # the default now; kept for old commands
    ap.add_argument("--private-net", action="store_true", help="run inside a private network namespace (unshare -n)")
    ap.add_argument("--json", action="store_true", help="print the figures as JSON")
    args = ap.parse_args()
    for exe in ("mft-sim", "mft-closedloop"):
        if not (Path(args.bin_dir) / exe).exists():
            print(f"measure-stack.py: error: no {exe} in {args.bin_dir} (build first: bash scripts/build.sh release)",
                  file=sys.stderr)
            return 2
    if not Path(args.scenario).is_file():
        print(f"measure-stack.py: error: no scenario file {args.scenario}", file=sys.stderr)
        return 2
    if args.runs < 1 or args.realtime_s < 1 or not 0 <= args.domain <= 232:
        print("measure-stack.py: error: --runs and --realtime-s must be at least 1, --domain 0..232", file=sys.stderr)
        return 2
    try:
        if args.private_net and not os.environ.get(NETNS_ENV):
            return reexec_in_private_net()
        with tempfile.TemporaryDirectory(prefix="mft-measure-") as tmp:
            out = measure(args, tmp)
    except MeasureError as e:
        print(f"measure-stack.py: error: {e}", file=sys.stderr)
        return 1
    if args.json:
        print(json.dumps(out, indent=1))
    else:
        print_report(out)
    return 0


if __name__ == "__main__":
    run_script(main, "measure-stack.py")
