#!/usr/bin/env python3
"""The loop benchmark's tools (docs/results/loop-benchmark.md): mft-wakeup, the machine's wake-up floor, and
scripts/measure-stack.py, the lockstep/in-process ratio with the per-hop split (one short round of the real stack,
DDS domain 204), and their one-line errors."""
import json
import os
import subprocess
import sys
import unittest
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "python"))
from mftstack.paths import DEFAULT_BIN, REPO  # noqa: E402

MEASURE = REPO / "scripts" / "measure-stack.py"
WAKEUP = DEFAULT_BIN / "mft-wakeup"


def run(cmd, timeout=300):
    return subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)


class WakeupProbeTest(unittest.TestCase):
    def test_reports_every_cpu_and_both_placements(self):
        r = run([str(WAKEUP), "--json", "--timer-samples", "50", "--wakeups", "200"], timeout=60)
        self.assertEqual(r.returncode, 0, r.stderr)
        d = json.loads(r.stdout)
        allowed = sorted(os.sched_getaffinity(0))
        self.assertEqual(sorted(d["timer_late_us"]), sorted(f"cpu{c}" for c in allowed))
        for s in d["timer_late_us"].values():
            self.assertEqual(s["count"], 50)
            self.assertGreaterEqual(s["p50"], 0.0)  # a sleep never ends before its deadline
            self.assertLessEqual(s["p50"], s["p99"])
            self.assertLessEqual(s["p99"], s["max"])
        placements = ["same_core", "cross_core"] if len(allowed) > 1 else ["same_core"]
        self.assertEqual(sorted(d["wakeup_us"]), sorted(placements))
        for s in d["wakeup_us"].values():
            self.assertEqual(s["count"], 2 * 200 - 1)  # each hand-off but the very first send is timed
            self.assertGreater(s["p50"], 0.0)
            self.assertLess(s["p50"], 1e5, "a thread wake-up taking 0.1 s at the median is no wake-up probe")

    def test_bad_input_is_one_line(self):
        r = run([str(WAKEUP), "--wakeups", "1"], timeout=30)
        self.assertEqual(r.returncode, 2)
        self.assertIn("--wakeups", r.stderr)
        self.assertNotIn("Traceback", r.stderr)


class MeasureStackTest(unittest.TestCase):
    def measure(self, *args, timeout=300):
        return run([sys.executable, str(MEASURE), "--bin-dir", str(DEFAULT_BIN)] + list(args), timeout=timeout)

    def test_bad_inputs(self):
        for args, code, expect in ((["--runs", "0"], 2, "--runs"), (["--variant", "x"], 1, "expected LABEL="),
                                   (["--scenario", "/nonexistent.yaml"], 2, "no scenario file"),
                                   (["--bin-dir", "/nonexistent"], 2, "no mft-sim in /nonexistent")):
            r = self.measure(*args, "--skip-realtime", "--runs", args[1] if args[0] == "--runs" else "1", timeout=60)
            self.assertEqual(r.returncode, code, (args, r.stderr))
            self.assertIn(expect, r.stderr)
            self.assertNotIn("Traceback", r.stderr)

    def test_one_round_gives_the_ratio_and_a_hop_table_that_adds_up(self):
        r = self.measure("--runs", "1", "--skip-realtime", "--skip-recording", "--domain", "204", "--json",
                         "--variant", "pinned=--chain-cpu auto", "--variant", "free=--chain-cpu none")
        self.assertEqual(r.returncode, 0, r.stderr[-2000:])
        d = json.loads(r.stdout)
        self.assertEqual(d["inprocess"]["sim_s"], 10)
        self.assertEqual(sorted(d["lockstep"]), ["free", "pinned"])
        for label, v in d["lockstep"].items():
            (wall,) = v["wall_s"]
            ratio = d["inprocess"]["wall_s"][0] / wall
            self.assertAlmostEqual(v["ratio_to_inprocess_median"], ratio, places=3)
            self.assertGreater(ratio, 0.0)
            table = v["hop_table"]
            self.assertGreater(table["ticks"], 9000, label)
            # The intervals are consecutive: their means add up to the mean tick (every tick has every stamp).
            total = sum(row["mean"] for row in table["intervals"])
            self.assertAlmostEqual(total, table["tick_us"]["mean"], delta=0.02 * table["tick_us"]["mean"], msg=label)
            self.assertEqual(len(table["intervals"]), 10)
        self.assertIn("1min", d["load_average_before"])

    def test_the_realtime_run_is_traced_hop_by_hop_and_agrees_with_the_simulators_own_latency(self):
        r = self.measure("--runs", "1", "--skip-recording", "--realtime-s", "3", "--domain", "205", "--json")
        self.assertEqual(r.returncode, 0, r.stderr[-2000:])
        rt = json.loads(r.stdout)["realtime"]
        table = rt["hop_table"]
        self.assertTrue(table["realtime"])
        self.assertEqual(len(table["intervals"]), 7)  # sensor sample out ... command in, not the simulator's loop
        self.assertGreater(table["ticks"], 2500)
        total = sum(row["mean"] for row in table["intervals"])
        self.assertAlmostEqual(total, table["tick_us"]["mean"], delta=0.02 * table["tick_us"]["mean"])
        # Two clocks of one quantity: the hop trace's stamps (publish -> command_in) against the simulator's own
        # SensorData-out to JointCommand-in latency, over nearly the same ticks (the trace leaves out the first 100).
        own = rt["sensor_to_command_latency_us"]
        self.assertGreater(own["count"], 2500)
        self.assertAlmostEqual(table["tick_us"]["p50"], own["p50"], delta=10.0 + 0.1 * own["p50"])
        floor = rt["hops_against_the_floor"]
        self.assertEqual(len(floor["hops"]), 4)  # sim -> estimator -> planner -> WBC -> sim
        worst = max(floor["wakeup_p99_us"].values())
        for h in floor["hops"]:
            self.assertAlmostEqual(h["p99_over_wakeup_floor"], h["p99"] - worst, delta=0.11)


if __name__ == "__main__":
    unittest.main()
