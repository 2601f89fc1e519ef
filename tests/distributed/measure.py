#!/usr/bin/env python3
"""Measures the three-host stack's network behaviour for docs/guide/distributed.md (root; namespaces made and
deleted here, testnet.py). Each row is a fresh realtime stack (sim | wbc | estimator+planner[+recorder]),
through mft-supervisor --stack, on its own namespaces:

  bandwidth  bytes per second on each host's link (realtime step in place, with and without the recorder),
             and the sensor-to-command latency against the default single-host stack on loopback
  loss       N % random loss on every link (nftables) for a 10 s realtime step in place
  cut        the WBC host's link down for N ms while standing (and stepping) in realtime
  tbf        a tbf rate limit on the robot's link at a fraction of what it sends, 3 s, standing

  python3 tests/distributed/measure.py [--only bandwidth,loss,cut,tbf] [--json FILE]

DDS domains 230-232 (in the namespaces; the loopback reference run uses 232 in the root namespace)."""
import argparse
import contextlib
import json
import os
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "python"))
from testnet import TestNet, netns_permitted, realtime_priority  # noqa: E402
from stack_layout import HOSTS, PLACEMENT  # noqa: E402
from mftstack.testing import StackRunner  # noqa: E402


class Harness:
    def __init__(self):
        self.stacks = StackRunner(prefix="mft-distributed-measure-")
        self.tmp = self.stacks.path
        self.n = 0

    def stop_all(self):
        """Stops every stack still up (after a failure), by the supervisor's `down`."""
        self.stacks.down_all()

    @contextlib.contextmanager
    def network(self, domain):
        """Three fresh namespace hosts and their stack file; afterwards every stack is down and they are gone."""
        self.n += 1
        net = TestNet.for_test(f"m{self.n}", HOSTS, domain).create()
        stack = self.tmp / f"stack-{self.n}.yaml"
        stack.write_text(net.stack_yaml(PLACEMENT))
        try:
            yield net, stack
        finally:
            self.stop_all()
            net.destroy()

    def up(self, net_stack, scenario, domain, *extra):
        net, stack = net_stack
        return self.stacks.up(scenario, domain, "--mode", "realtime", "--stack", stack, *extra)

    def down(self, domain, st):
        return self.stacks.down(domain, st, names=PLACEMENT)

    def run(self, scenario, domain, *extra, during=None, stack=None):
        """A `run` to its end; `during(run_dir)` is called once the simulator is READY."""
        self.n += 1
        p = self.stacks.start_run(scenario, domain, "--mode", "realtime", *(["--stack", stack] if stack else []),
                                  *extra, run_dir=self.tmp / f"run-{self.n}")
        if during:
            self.stacks.wait_for_text(p.run_dir / "mft-sim.log", "READY mft-sim")
            during(p.run_dir)
        return self.stacks.finish(p)[1]


def sim_row(sim):
    lat = sim.get("latency_us") or {}
    return {"fell": sim["fell"], "fall_reason": sim.get("fall_reason", ""), "lost_commands": sim["lost_commands"],
            "deadline_misses": sim["deadline_misses"], "reader_deadline_misses": sim["reader_deadline_misses"],
            "damping_ticks": sim["damping_ticks"], "commands_received": sim["commands_received"],
            "latency_p50_us": lat.get("p50"), "latency_p99_us": lat.get("p99"), "latency_max_us": lat.get("max"),
            "sag_cm": round(sim["base_height_error_m"]["max"] * 100, 1), "episodes": sim["damping_episodes"]}


def measure_bandwidth(h, out):
    rows = []
    for record in (False, True):
        with h.network(230) as (net, stack):
            extra = ["--record", h.tmp / "bw.rawlog"] if record else []
            st = h.up((net, stack), "step-in-place.yaml", 230, *extra)
            time.sleep(2.0)
            c0 = {x: net.counters(x) for x in HOSTS}
            time.sleep(5.0)
            c1 = {x: net.counters(x) for x in HOSTS}
            h.down(230, st)
        for x in HOSTS:
            rows.append({"recorder": record, "host": x,
                         "tx_kBps": round((c1[x]["tx_bytes"] - c0[x]["tx_bytes"]) / 5e3, 1),
                         "rx_kBps": round((c1[x]["rx_bytes"] - c0[x]["rx_bytes"]) / 5e3, 1),
                         "tx_pps": round((c1[x]["tx_packets"] - c0[x]["tx_packets"]) / 5.0),
                         "rx_pps": round((c1[x]["rx_packets"] - c0[x]["rx_packets"]) / 5.0)})
        print(f"bandwidth (recorder {record}): {rows[-3:]}", file=sys.stderr, flush=True)
    out["bandwidth"] = rows
    # Latency: the default single-host stack on loopback vs the three hosts, 10 s step in place each.
    lat = []
    s = h.run("step-in-place.yaml", 232)
    lat.append(dict(where="one host (loopback, default)", **sim_row(s["services"]["mft-sim"])))
    with h.network(232) as (net, stack):
        s = h.run("step-in-place.yaml", 232, stack=stack)
    lat.append(dict(where="three hosts (veth, initial peers)", **sim_row(s["services"]["mft-sim"])))
    for r in lat:
        print(f"latency {r['where']}: p50 {r['latency_p50_us']} p99 {r['latency_p99_us']} max {r['latency_max_us']}, "
              f"misses {r['deadline_misses']}, fell {r['fell']}", file=sys.stderr, flush=True)
    out["latency"] = lat


def measure_loss(h, out, percents):
    rows = []
    for pct in percents:
        with h.network(231) as (net, stack):
            def during(run_dir):
                with realtime_priority():
                    for x in HOSTS:
                        net.set_loss(x, pct)

            s = h.run("step-in-place.yaml", 231, during=during if pct else None, stack=stack)
            drops = {x: net.loss_counters(x) for x in HOSTS}
        sim = s["services"]["mft-sim"]
        row = dict(loss_percent=pct, wbc_ticks=s["services"]["mft-wbc"]["ticks"], drops=drops, **sim_row(sim))
        row.pop("episodes")
        rows.append(row)
        print(f"loss {pct} %: {row}", file=sys.stderr, flush=True)
    out["loss"] = rows


def measure_cut(h, out, cuts_ms, scenarios=("stand.yaml",), long_cut_ms=None):
    rows = []
    plan = [(sc, ms) for sc in scenarios for ms in cuts_ms]
    if long_cut_ms:
        plan.append(("stand.yaml", long_cut_ms))
    for scenario, ms in plan:
        with h.network(232) as (net, stack):
            st = h.up((net, stack), scenario, 232)
            time.sleep(3.0)
            lo, hi = net.cut("ctrl", ms / 1000.0)
            time.sleep(3.0)
            s = h.down(232, st)
        sim = s["mft-sim"]
        ep = max(sim["damping_episodes"], key=lambda e: e[2]) if sim["damping_episodes"] else [0, 0, 0]
        silent = 3.0 + ep[1] + ep[2]
        row = {"scenario": scenario, "cut_ms": [round(lo * 1e3, 1), round(hi * 1e3, 1)], "damping_late_ms": ep[1],
               "damping_ms": ep[2], "recovery_after_link_ms": [round(silent - hi * 1e3, 1), round(silent - lo * 1e3, 1)],
               "watchdog_recoveries": sim["watchdog_recoveries"], "fall_criterion": sim["fell"],
               "fall_reason": sim.get("fall_reason", ""), "sag_cm": round(sim["base_height_error_m"]["max"] * 100, 1),
               "final_base_height_m": sim["final_base_height_m"], "wbc_new_clocks": s["mft-wbc"].get("new_clocks"),
               "wbc_refused_ticks": s["mft-wbc"].get("refused_ticks")}
        rows.append(row)
        print(f"cut: {row}", file=sys.stderr, flush=True)
    out["cut"] = rows


def measure_tbf(h, out, fractions):
    rows = []
    for frac in fractions:
        with h.network(231) as (net, stack):
            st = h.up((net, stack), "stand.yaml", 231)
            time.sleep(1.5)
            c0 = net.counters("robot")
            time.sleep(2.0)
            c1 = net.counters("robot")
            need_kbit = (c1["tx_bytes"] - c0["tx_bytes"]) * 8 / 2.0 / 1e3
            rate = int(need_kbit * frac)
            with realtime_priority():
                net.set_rate("robot", f"{rate}kbit", burst="16kb", latency="5ms")
                time.sleep(3.0)
                tbf = net.rate_stats("robot")
                net.clear_rate("robot")
            time.sleep(2.0)
            s = h.down(231, st)
        sim = s["mft-sim"]
        row = dict(fraction=frac, need_kbit=round(need_kbit), rate_kbit=rate, tbf=tbf, **sim_row(sim))
        row["episodes"] = len(row["episodes"])
        rows.append(row)
        print(f"tbf {frac}: {row}", file=sys.stderr, flush=True)
    out["tbf"] = rows


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--only", default="bandwidth,loss,cut,tbf")
    ap.add_argument("--loss", default="0,1,2,5", help="loss percentages")
    ap.add_argument("--cuts", default="50,100,150,200,300", help="cut durations [ms]")
    ap.add_argument("--tbf", default="0.5,0.8,1.0,1.25,1.5,2.0", help="rate as a fraction of what the robot sends")
    ap.add_argument("--json", help="write the results here")
    a = ap.parse_args()
    ok, why = netns_permitted()
    if not ok:
        print(f"measure: network namespaces are not permitted here: {why}", file=sys.stderr)
        return 2
    h = Harness()
    out = {"load_before": os.getloadavg()}
    only = a.only.split(",")
    try:
        if "bandwidth" in only:
            measure_bandwidth(h, out)
        if "loss" in only:
            measure_loss(h, out, [float(x) for x in a.loss.split(",")])
        if "cut" in only:
            measure_cut(h, out, [float(x) for x in a.cuts.split(",")], scenarios=("stand.yaml", "step-in-place.yaml"),
                        long_cut_ms=1500)
        if "tbf" in only:
            measure_tbf(h, out, [float(x) for x in a.tbf.split(",")])
    finally:
        h.stacks.close()
        out["load_after"] = os.getloadavg()
    text = json.dumps(out, indent=1)
    if a.json:
        Path(a.json).write_text(text)
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
