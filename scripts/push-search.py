#!/usr/bin/env python3
"""push-search: the largest forward push each controller recovers from while stepping in place
(docs/notebook/2026-11-24-closed-loop-push-recovery.md, "Push recovery"). For every actuator model, controller and height it runs

  mft-closedloop --config-dir <copy with actuators.model = M> --height H --controller C --duration 10
                 --push I --push-at 5 --recovery-rule R --json

and takes the loop's own recovery verdict (chain/push_recovery.hpp, the criterion every tool uses;
--rule stepping = back to stepping in place, the default, or no_fall) at every coarse step from --start to --max, and in fine steps between every two
neighbouring coarse points that disagree, so a non-monotonic boundary shows. I_max is the largest recovered push
below the first failure; the largest recovered push and the recovered ranges are reported too. At most --jobs runs
at a time, under nice. A measurement, not a test.

  scripts/push-search.py [--bin build/release/bin/mft-closedloop] [--models sea,sea_motor] [--controllers mft,sa]
                         [--heights 0.40,0.42,0.44,0.46] [--start 4] [--max 16] [--coarse 0.5] [--fine 0.1]
                         [--substeps N] [--json out.json]
"""
import argparse
import concurrent.futures
import json
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "python"))
from mftstack.scripts import run_script  # noqa: E402
from mftstack.paths import DEFAULT_BIN, DEFAULT_CONFIG  # noqa: E402


def config_for(model, substeps, tmp):
    d = Path(tmp) / model
    shutil.copytree(DEFAULT_CONFIG, d)
    sim = d / "sim.yaml"
    text, n = re.subn(r"(?m)^  model: \w+", f"  model: {model}", sim.read_text())
    if substeps:
        text, m = re.subn(r"(?m)^substeps: \d+", f"substeps: {substeps}", text)
        n += m - 1
    if n != 1:
        sys.exit("push-search: cannot find actuators.model or substeps in config/sim.yaml")
    sim.write_text(text)
    return d


def recovered(args, cfg, controller, height, push):
    cmd = ["nice", "-n", "5", args.bin, "--config-dir", str(cfg), "--height", f"{height}", "--controller", controller,
           "--duration", "10", "--push", f"{push:.2f}", "--push-at", "5", "--recovery-rule", args.rule, "--json"]
    p = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
    if p.returncode not in (0, 1):
        raise RuntimeError(f"{' '.join(cmd)}: exit {p.returncode}\n{p.stderr}")
    verdict = json.loads(p.stdout)["recovery"]["verdict"]
    if verdict["outcome"] == "not_pushed":
        raise RuntimeError(f"{' '.join(cmd)}: the push was never applied")
    return verdict["recovered"]


def search(args, cfg, model, controller, height):
    runs = {}

    def run(i):
        i = round(i, 2)
        if i not in runs:
            runs[i] = recovered(args, cfg, controller, height, i)
        return runs[i]

    n = int(round((args.max - args.start) / args.coarse))
    coarse = [round(args.start + k * args.coarse, 2) for k in range(n + 1)]
    for i in coarse:
        run(i)
    # Refine every change between neighbouring coarse points (the boundary need not be a single step).
    for a, b in zip(coarse, coarse[1:]):
        if runs[a] != runs[b]:
            i = a + args.fine
            while i < b - 1e-9:
                run(i)
                i += args.fine
    pushes = sorted(runs)
    first_fall = next((p for p in pushes if not runs[p]), None)
    ok = [p for p in pushes if runs[p]]
    below = [p for p in ok if first_fall is None or p < first_fall]
    above = [p for p in ok if first_fall is not None and p > first_fall]
    return {"model": model, "controller": controller, "height": height,
            "i_max": below[-1] if below else None, "first_fall": first_fall,
            "largest_recovered": ok[-1] if ok else None, "recovered_above_first_fall": above,
            "runs": {f"{p:.2f}": r for p, r in sorted(runs.items())}}


def spans(result):
    """The recovered pushes as ranges, e.g. '4-10, 11.9-14.5'."""
    out, cur = [], None
    for key, ok in result["runs"].items():
        p = float(key)
        if ok:
            cur = [p, p] if cur is None else [cur[0], p]
        elif cur is not None:
            out.append(cur)
            cur = None
    if cur is not None:
        out.append(cur)
    return ", ".join(f"{a:g}-{b:g}" if a != b else f"{a:g}" for a, b in out)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bin", default=str(DEFAULT_BIN / "mft-closedloop"))
    ap.add_argument("--models", default="sea,sea_motor")
    ap.add_argument("--controllers", default="mft,sa")
    ap.add_argument("--heights", default="0.40,0.42,0.44,0.46")
    ap.add_argument("--start", type=float, default=4.0)
    ap.add_argument("--coarse", type=float, default=0.5)
    ap.add_argument("--fine", type=float, default=0.1)
    ap.add_argument("--max", type=float, default=16.0)
    ap.add_argument("--substeps", type=int, help="physics steps per control period (default: config/sim.yaml's)")
    ap.add_argument("--rule", choices=("stepping", "no_fall"), default="stepping",
                    help="recovered = back to stepping in place (default) or no fall within the run")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--json", help="write every run to this file")
    args = ap.parse_args()
    with tempfile.TemporaryDirectory(prefix="push-search-") as tmp:
        cfgs = {m: config_for(m, args.substeps, tmp) for m in args.models.split(",")}
        tasks = [(m, c, float(h)) for m in cfgs for h in args.heights.split(",") for c in args.controllers.split(",")]
        with concurrent.futures.ThreadPoolExecutor(max_workers=args.jobs) as pool:
            results = list(pool.map(lambda t: search(args, cfgs[t[0]], *t), tasks))
    print("| model | height | controller | I_max [N s] | first failure | largest recovered | recovered ranges |")
    print("|---|---|---|---|---|---|---|")
    for r in results:
        print(f"| {r['model']} | {r['height']:.2f} | {r['controller']} | {r['i_max']} | {r['first_fall']} | "
              f"{r['largest_recovered']} | {spans(r)} |")
    if args.json:
        Path(args.json).write_text(json.dumps(results, indent=1))


if __name__ == "__main__":
    run_script(main, "push-search.py")
