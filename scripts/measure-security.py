#!/usr/bin/env python3
"""measure-security: what DDS Security costs the stack (docs/guide/security.md). Runs step-in-place through the
supervisor plain and secured (material from scripts/make-security.sh in a temporary directory, removed after)
and reports the realtime sensor-to-command latency (p50/p99 of the simulator's SensorData(k) -> JointCommand(k)
round trip through estimator, planner and WBC) and the lockstep wall time of a 10 s run. A measurement, not a
test: the figures depend on the machine's load.

  scripts/measure-security.py [--bin-dir DIR] [--runs 2] [--profiles data,full] [--domain 205] [--json]
"""
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "python"))
from mftstack.scripts import run_script, script_parser  # noqa: E402
from mftstack.paths import REPO, SCENARIOS, SUPERVISOR  # noqa: E402

SCENARIO = SCENARIOS / "step-in-place.yaml"


def run(args, mode, secure, domain, tmp):
    run_dir = tmp / f"run-{domain}-{mode}-{secure and Path(secure).name}"
    cmd = [sys.executable, str(SUPERVISOR), "run", str(SCENARIO), "--domain", str(domain), "--mode", mode, "--json",
           "--bin-dir", args.bin_dir, "--run-dir", str(run_dir)]
    if secure:
        cmd += ["--secure", str(secure)]
    p = subprocess.run(cmd, capture_output=True, text=True, timeout=600,
                       env=dict(os.environ, MFT_RUNS_DIR=str(tmp / "runs")))
    try:
        s = json.loads(p.stdout)
    except ValueError:
        raise SystemExit(f"measure-security: no summary from the supervisor: {p.stderr[-1500:]}")
    if not s.get("ok"):
        log = run_dir / "mft-sim.log"
        tail = "\n".join(log.read_text(errors="replace").splitlines()[-8:]) if log.exists() else ""
        raise SystemExit(f"measure-security: the {mode} run failed: {s.get('error')}\n{tail}")
    sim = s["services"]["mft-sim"]
    out = {"fell": s["fell"], "wall_s": sim["wall_time_s"]}
    if mode == "realtime":
        out.update(p50_us=sim["latency_us"]["p50"], p99_us=sim["latency_us"]["p99"], mean_us=sim["latency_us"]["mean"],
                   damping_ticks=sim["damping_ticks"], deadline_misses=sim["deadline_misses"])
    return out


def main():
    p = script_parser("measure-security", __doc__)
    p.add_argument("--runs", type=int, default=2, help="runs per configuration and mode (median reported)")
    p.add_argument("--profiles", default="data,full", help="governance profiles to measure: data, full (comma list)")
    p.add_argument("--domain", type=int, default=205, help="DDS domain id (default 205)")
    p.add_argument("--json", action="store_true", help="print the figures as JSON")
    args = p.parse_args()
    profiles = [x for x in args.profiles.split(",") if x]
    if any(x not in ("data", "full") for x in profiles) or args.runs < 1 or not 0 <= args.domain <= 232:
        p.error("--profiles takes data and/or full, --runs >= 1, --domain 0..232")
    if not os.access(Path(args.bin_dir) / "mft-sim", os.X_OK):
        p.error(f"no mft-sim in {args.bin_dir} (build first)")
    tmp = Path(tempfile.mkdtemp(prefix="mft-measure-security-"))
    try:
        configs = [("plain", None)]
        for prof in profiles:
            d = tmp / f"sec-{prof}"
            subprocess.run(["bash", str(REPO / "scripts" / "make-security.sh"), str(d), "--profile", prof],
                           check=True, capture_output=True, timeout=120)
            configs.append((f"secured ({prof})", d))
        results = {}
        for name, sec in configs:
            rows = {"lockstep": [], "realtime": []}
            for i in range(args.runs):
                for mode in ("lockstep", "realtime"):
                    print(f"measure-security: {name}, {mode}, run {i + 1}/{args.runs}", file=sys.stderr, flush=True)
                    rows[mode].append(run(args, mode, sec, args.domain, tmp))
            med = lambda mode, k: statistics.median(r[k] for r in rows[mode])
            results[name] = {"lockstep_wall_s": med("lockstep", "wall_s"), "realtime_p50_us": med("realtime", "p50_us"),
                             "realtime_p99_us": med("realtime", "p99_us"),
                             "realtime_damping_ticks": med("realtime", "damping_ticks"),
                             "fell": any(r["fell"] for m in rows.values() for r in m), "runs": rows}
        base = results["plain"]
        if args.json:
            print(json.dumps({"runs_per_config": args.runs, "results": results}, indent=2))
        else:
            print("| configuration | lockstep 10 s, wall [s] | realtime latency p50 [µs] | p99 [µs] | damping ticks / 10 s |")
            print("|---|---|---|---|---|")
            for name, r in results.items():
                rel = "" if name == "plain" else f" (×{r['lockstep_wall_s'] / base['lockstep_wall_s']:.2f})"
                d50 = "" if name == "plain" else f" (+{r['realtime_p50_us'] - base['realtime_p50_us']:.0f})"
                print(f"| {name} | {r['lockstep_wall_s']:.2f}{rel} | {r['realtime_p50_us']:.0f}{d50} | "
                      f"{r['realtime_p99_us']:.0f} | {r['realtime_damping_ticks']:.0f} |")
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    return 0


if __name__ == "__main__":
    run_script(main, "measure-security.py")
