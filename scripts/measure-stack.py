#!/usr/bin/env python3
"""Loop benchmark of the multi-process stack (docs/benchmarks.md "Loop benchmark").

Measures, through services/mft-supervisor and the real services:
  * lockstep speed: wall time of the simulator's loop for a 10 s step-in-place run, as a real-time factor;
  * recording cost: the same runs with mft-record recording every topic, alternated with plain ones;
  * realtime latency: sensor-to-command latency (SensorData(k) written -> JointCommand(k) received by the sim)
    p50 / p99 / max over a --realtime-s run, with the deadline misses.
Speed figures depend on the machine and on its load: run it on an idle machine (the load is printed).
"""
import argparse
import importlib.util
import json
import os
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "python"))
from mftstack.scripts import run_script  # noqa: E402
from mftstack.paths import DEFAULT_BIN, SCENARIOS, SUPERVISOR  # noqa: E402

SCENARIO = SCENARIOS / "step-in-place.yaml"


def progress(msg):
    print(msg, file=sys.stderr, flush=True)


def hop_table_module():
    spec = importlib.util.spec_from_file_location("hop_table", REPO / "scripts" / "hop-table.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def run_stack(args, tmp, scenario, mode, record=False, tag="", hops=False):
    run_dir = Path(tmp) / f"run-{mode}-{tag}"
    env = dict(os.environ)
    env.pop("MFT_HOP_TRACE", None)
    if hops:  # the services write <service>.hops.csv into the run folder (services/runtime/hop_trace.hpp)
        run_dir.mkdir(parents=True, exist_ok=True)
        env["MFT_HOP_TRACE"] = str(run_dir)
    cmd = [sys.executable, str(SUPERVISOR), "run", str(scenario), "--domain", str(args.domain), "--mode", mode,
           "--json", "--run-dir", str(run_dir), "--bin-dir", str(args.bin_dir)]
    if record:
        cmd += ["--record", str(Path(tmp) / f"{tag}.rawlog")]
    if args.chain_cpu is not None:
        cmd += ["--chain-cpu", str(args.chain_cpu)]
    p = subprocess.run(cmd, capture_output=True, text=True, timeout=args.realtime_s + 300, env=env)
    try:
        summary = json.loads(p.stdout)
    except ValueError:
        sys.exit(f"measure-stack: the {mode} run gave no summary (exit {p.returncode}):\n{p.stderr[-2000:]}")
    if p.returncode != 0 or not summary.get("ok"):
        sys.exit(f"measure-stack: the {mode} run failed: {summary.get('error')} {summary.get('failed')}")
    if record:
        os.unlink(Path(tmp) / f"{tag}.rawlog")
    if hops:
        summary["hop_table"] = hop_table_module().hop_table(run_dir)
    return summary


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bin-dir", default=str(DEFAULT_BIN), help="service executables")
    ap.add_argument("--domain", type=int, default=71, help="DDS domain id for the runs (default 71)")
    ap.add_argument("--runs", type=int, default=3, help="lockstep runs with and without recording (default 3)")
    ap.add_argument("--realtime-s", type=float, default=60.0, help="length of the realtime run [s] (default 60)")
    ap.add_argument("--chain-cpu", type=int, metavar="N", help="pass --chain-cpu N to the supervisor (chain on CPU N, "
                    "recorder on the others)")
    ap.add_argument("--skip-realtime", action="store_true", help="lockstep figures only")
    ap.add_argument("--hops", action="store_true", help="trace the plain lockstep runs (MFT_HOP_TRACE) and print the "
                    "per-hop table of the median one (scripts/hop-table.py; docs/loop-benchmark.md)")
    ap.add_argument("--json", action="store_true", help="print the figures as JSON")
    args = ap.parse_args()
    if not (Path(args.bin_dir) / "mft-sim").exists():
        sys.exit(f"measure-stack: no mft-sim in {args.bin_dir} (build first: bash scripts/build.sh release)")
    if args.runs < 1 or args.realtime_s < 1:
        sys.exit("measure-stack: --runs and --realtime-s must be at least 1")

    out = {"cpus": os.cpu_count(), "chain_cpu": args.chain_cpu, "load_per_core_before": round(os.getloadavg()[0] / (os.cpu_count() or 1), 2)}
    with tempfile.TemporaryDirectory(prefix="mft-measure-") as tmp:
        plain, recorded = [], []
        for i in range(args.runs):
            progress(f"lockstep run {i + 1}/{args.runs} without and with recording ...")
            s = run_stack(args, tmp, SCENARIO, "lockstep", tag=f"plain{i}", hops=args.hops)
            plain.append(dict(s["services"]["mft-sim"], hop_table=s.get("hop_table")))
            rec = run_stack(args, tmp, SCENARIO, "lockstep", record=True, tag=f"rec{i}")
            recorded.append(rec["services"]["mft-sim"])
            dropped = rec["services"]["mft-record"]["dropped_samples"]
            if dropped:
                progress(f"  warning: the recorder dropped {dropped} samples")
        sim_s = plain[0]["sim_time_s"]
        wall_plain = [s["wall_time_s"] for s in plain]
        wall_rec = [s["wall_time_s"] for s in recorded]
        out["lockstep"] = {
            "sim_s": sim_s,
            "wall_s_plain": wall_plain,
            "wall_s_recording": wall_rec,
            "real_time_factor_median": round(sim_s / statistics.median(wall_plain), 2),
            "real_time_factor_best": round(sim_s / min(wall_plain), 2),
            "recording_real_time_factor_median": round(sim_s / statistics.median(wall_rec), 2),
            "recording_slowdown_median": round(statistics.median(wall_rec) / statistics.median(wall_plain), 3),
            "recording_slowdown_best": round(min(wall_rec) / min(wall_plain), 3),
            # Each recorded run against the plain run just before it: the machine's drift cancels.
            "recording_slowdown_paired": sorted(round(r / p, 3) for r, p in zip(wall_rec, wall_plain)),
            "resends": sum(s.get("lockstep_resends", 0) for s in plain + recorded),
        }
        if args.hops:  # the table of the plain run with the median wall time
            median_run = sorted(plain, key=lambda s: s["wall_time_s"])[len(plain) // 2]
            out["lockstep"]["hop_table"] = median_run["hop_table"]
        if not args.skip_realtime:
            scenario = Path(tmp) / "step-in-place-long.yaml"
            text = SCENARIO.read_text().replace("duration_s: 10.0", f"duration_s: {args.realtime_s}")
            scenario.write_text(text.replace("name: step-in-place", "name: step-in-place-long"))
            progress(f"realtime run of {args.realtime_s:g} s ...")
            s = run_stack(args, tmp, scenario, "realtime", tag="rt")
            out["realtime"] = {"sim_s": s["sim_time_s"], "deadline_misses": s["deadline_misses"],
                               "sensor_to_command_latency_us": s["sensor_to_command_latency_us"],
                               "wbc_tick_us": s["wbc_tick_us"], "fell": s["fell"]}
    out["load_per_core_after"] = round(os.getloadavg()[0] / (os.cpu_count() or 1), 2)

    if args.json:
        print(json.dumps(out, indent=1))
        return
    ls = out["lockstep"]
    print(f"machine: {out['cpus']} cpus, load per core {out['load_per_core_before']} before, "
          f"{out['load_per_core_after']} after")
    print(f"lockstep, {ls['sim_s']:g} s step in place: sim loop wall {statistics.median(ls['wall_s_plain']):.3f} s "
          f"median -> {ls['real_time_factor_median']}x real time (best {ls['real_time_factor_best']}x)")
    print(f"  recording every topic: {statistics.median(ls['wall_s_recording']):.3f} s median -> "
          f"{ls['recording_real_time_factor_median']}x real time, slowdown x{ls['recording_slowdown_median']} "
          f"(best x{ls['recording_slowdown_best']}, paired median x{statistics.median(ls['recording_slowdown_paired']):.3f}); "
          f"tick re-sends {ls['resends']}")
    if "hop_table" in ls:
        print("per-hop table of the median plain lockstep run [us]:")
        hop_table_module().print_table(ls["hop_table"])
    if "realtime" in out:
        rt = out["realtime"]
        lat = rt["sensor_to_command_latency_us"]
        print(f"realtime, {rt['sim_s']:g} s: sensor-to-command latency p50 {lat['p50']:.0f} us, p99 {lat['p99']:.0f} us, "
              f"max {lat['max']:.0f} us over {lat['count']} ticks; deadline misses {rt['deadline_misses']}; "
              f"WBC tick p50 {rt['wbc_tick_us']['p50']:.1f} us, p99 {rt['wbc_tick_us']['p99']:.1f} us")


if __name__ == "__main__":
    run_script(main, "measure-stack.py")
