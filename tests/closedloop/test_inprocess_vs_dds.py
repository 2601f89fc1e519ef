#!/usr/bin/env python3
"""The control chain wired twice gives one result (issue 17): the same lockstep scenario run in-process
(mft-closedloop, the chain's nodes called in one thread) and through the DDS stack (services/mft-supervisor: four
processes driving the same nodes over topics, recorded by mft-record) must give the same trajectory, tick by tick,
bit for bit: the base pose and every joint angle of the truth of tick k, and the command answering tick k. The
stack runs twice: with its default lockstep transport (the chain's topics through the shared-memory chain channel,
DDS for the recorder) and with DDS alone (--chain-transport dds). Both paths take the simulator's time on the messages' nanosecond stamp (chain/estimator_node.hpp); everything else
crosses the topics as doubles. Own DDS domain; bounded in time; needs MFT_BIN_DIR (set by CTest)."""
import csv
import json
import subprocess
import sys
import unittest
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "python"))
from mftstack.testing import BIN, SCENARIOS, StackRunner  # noqa: E402

DOMAIN = 4  # a domain no other test uses (video 6-9, rawlog 10-89, experiments 90-99, stacks 100+, 220+)
Q = ["x", "z", "pitch", "q4", "q5", "q6", "q7", "q8", "q9", "q10", "q11"]
TAU = ["tau_q4", "tau_q6", "tau_q8", "tau_q10"]


def read_csv(path):
    with open(path, newline="") as f:
        return {int(row["tick"]): row for row in csv.DictReader(f)}


def first_difference(a, b, columns):
    """(tick, column, a, b, |a - b|) of the first tick where a column differs, and the largest |a - b| overall."""
    first, largest = None, 0.0
    for tick in sorted(a):
        for c in columns:
            x, y = float(a[tick][c]), float(b[tick][c])
            if x != y:
                largest = max(largest, abs(x - y))
                first = first or (tick, c, x, y, abs(x - y))
    return first, largest


class InProcessAndDdsGiveTheSameTrajectory(unittest.TestCase):
    scenario = "demo.yaml"  # step in place at 0.42 m, a 3 N s push at a right lift-off after 5 s

    @classmethod
    def setUpClass(cls):
        cls.stacks = StackRunner(prefix="mft-chain-twice-")
        cls.addClassCleanup(cls.stacks.close)
        path = cls.stacks.path
        cls.runs = {}
        for transport in ("shm", "dds"):
            rawlog = path / f"stack-{transport}.rawlog"
            code, summary, err = cls.stacks.run_json(cls.scenario, DOMAIN, "--record", rawlog,
                                                     *([] if transport == "shm" else ["--chain-transport", "dds"]),
                                                     timeout=300)
            export = subprocess.run([str(BIN / "mft-export"), str(rawlog), "--csv", str(path / f"csv-{transport}"),
                                     "--labels", "gt_q,joint_tau_cmd"], capture_output=True, text=True, timeout=120)
            cls.runs[transport] = (code, summary, err, export.returncode and export.stderr)
        loop = subprocess.run([str(BIN / "mft-closedloop"), "--scenario", str(SCENARIOS / cls.scenario), "--json",
                               "--trajectory", str(path / "inprocess.csv")], capture_output=True, text=True, timeout=300)
        cls.loop_code, cls.loop_out, cls.loop_err = loop.returncode, loop.stdout, loop.stderr
        cls.path = path

    def test_both_runs_complete_the_scenario(self):
        self.assertEqual(self.loop_code, 0, self.loop_err[-2000:])
        loop = json.loads(self.loop_out)
        self.assertEqual(loop["summary"]["ticks"], 10000)
        self.assertFalse(loop["summary"]["fell"])
        for transport, (code, summary, err, export_err) in self.runs.items():
            with self.subTest(transport=transport):
                self.assertEqual(code, 0, err[-2000:])
                self.assertFalse(export_err, export_err)
                self.assertTrue(summary["ok"], summary.get("error"))
                self.assertEqual(summary["chain_transport"], transport)  # the default is the chain channel
                self.assertEqual(summary["ticks"], 10000)
                self.assertFalse(summary["fell"])

    def test_trajectories_are_bit_identical(self):
        loop = read_csv(self.path / "inprocess.csv")
        self.assertEqual(len(loop), 10000, "in-process ticks")
        # The push (3 N s at the first right lift-off after 5 s) moved the base: the runs compared are not trivial.
        xs = [float(loop[k]["x"]) for k in sorted(loop)]
        self.assertGreater(max(xs) - min(xs), 0.005)
        for transport in self.runs:
            with self.subTest(transport=transport):
                stack_q = read_csv(self.path / f"csv-{transport}" / "gt_q.csv")
                stack_tau = read_csv(self.path / f"csv-{transport}" / "joint_tau_cmd.csv")
                self.assertEqual(sorted(stack_q), sorted(loop), "the recording must hold every tick once")
                self.assertEqual(sorted(stack_tau), sorted(loop))
                first, largest = first_difference(loop, stack_q, Q)
                self.assertIsNone(first, f"base pose / joint angles differ first at (tick, column, in-process, "
                                         f"{transport}, |d|) = {first}; largest |d| {largest}")
                first, largest = first_difference(loop, stack_tau, TAU)
                self.assertIsNone(first, f"commands differ first at {first}; largest |d| {largest} N m")


if __name__ == "__main__":
    unittest.main(verbosity=2)
