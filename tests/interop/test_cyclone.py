#!/usr/bin/env python3
"""A second DDS vendor on the stack (docs/guide/interop.md): mft-cyclone, built with Eclipse Cyclone DDS from the
project's IDL, reads SensorData, JointCommand and Reference from a running Fast DDS stack (values sane, ticks
increasing) and sends an OperatorCommand that the stack obeys; a height out of reach is rejected with the
planner's reason. One realtime stack on DDS domain 226, started through the supervisor and stopped by it (by
pid) even when a test fails. Needs MFT_BIN_DIR (set by CTest)."""
import json
import math
import subprocess
import sys
import time
import unittest
from pathlib import Path

import yaml

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "python"))
from mftstack.testing import BIN, CONFIG, StackUpTestCase  # noqa: E402

DOMAIN = 226
ROBOT = yaml.safe_load((CONFIG / "robot.yaml").read_text())
PEAK_TORQUE = ROBOT["actuator"]["gear_ratio"] * ROBOT["actuator"]["motor_peak_torque_Nm"]
SCENARIO_HEIGHT = 0.42  # step-in-place.yaml
NEW_HEIGHT = 0.40
# The planner moves its height reference toward a new command at most this fast, so the Reference reaches
# NEW_HEIGHT this many ticks (1 kHz) after the command's tick, plus a few ticks for rounding.
HEIGHT_RATE = yaml.safe_load((CONFIG / "planner.yaml").read_text())["command"]["height_rate_mps"]
RAMP_TICKS = math.ceil(abs(SCENARIO_HEIGHT - NEW_HEIGHT) / HEIGHT_RATE * 1000) + 5
# At start-up the planner's height reference begins at the estimated base height and ramps to the scenario's
# z_cmd at the same rate; a start-up offset below 0.1 m has ramped away by tick 1000 (the scenario's
# step_in_place command at 1.0 s). Measured once: the first Reference was 0.420078 m.
STARTUP_TICKS = 1000


def cyclone(*args, timeout=90):
    """Runs mft-cyclone with --json; returns (exit code, parsed JSON or None, stderr)."""
    p = subprocess.run([str(BIN / "mft-cyclone")] + [str(a) for a in args] + ["--json"], capture_output=True,
                       text=True, timeout=timeout)
    try:
        return p.returncode, json.loads(p.stdout), p.stderr
    except ValueError:
        return p.returncode, None, p.stderr


class CycloneOnTheStack(StackUpTestCase):
    """The tests run in name order against one stack; the last one stops it and reads the planner's counts."""

    tmp_prefix, stack_scenario, stack_domain = "mft-interop-test-", "step-in-place.yaml", DOMAIN


    def listen(self, samples):
        code, r, err = cyclone("listen", "--domain", DOMAIN, "--min-samples", samples, "--seconds", 60)
        self.assertEqual(code, 0, err)
        self.assertIsNotNone(r, err)
        for name, t in r["topics"].items():
            self.assertGreaterEqual(t["samples"], samples, (name, t))
            self.assertEqual(t["tick_decreases"], 0, (name, t))
            self.assertEqual(t["nonfinite"], 0, (name, t))
            # 1 kHz ticks: never more samples than ticks, and best effort on loopback loses few of them.
            span = t["last_tick"] - t["first_tick"] + 1
            self.assertLessEqual(t["samples"], span, (name, t))
            self.assertGreaterEqual(t["samples"], 0.8 * span, (name, t))
        return r["topics"]

    def listen_from(self, samples, tick, what):
        """Listens until the Reference window starts at `tick` or later (bounded: 60 s)."""
        deadline = time.monotonic() + 60
        while True:
            topics = self.listen(samples)
            if topics["Reference"]["first_tick"] >= tick or time.monotonic() > deadline:
                break
        self.assertGreaterEqual(topics["Reference"]["first_tick"], tick, f"no Reference {what} within 60 s")
        return topics

    def test_1_cyclone_reads_the_control_topics(self):
        topics = self.listen_from(1000, STARTUP_TICKS, "past the start-up height ramp")
        joints = topics["SensorData"]
        self.assertGreater(joints["max"] - joints["min"], 0.1, joints)  # the hips move: the robot steps
        self.assertLessEqual(max(abs(joints["min"]), abs(joints["max"])), math.pi, joints)
        tau = topics["JointCommand"]
        self.assertLessEqual(max(abs(tau["min"]), abs(tau["max"])), PEAK_TORQUE + 1e-9, tau)
        self.assertGreater(tau["max"], 1.0, tau)  # holding the robot up takes torque
        ref = topics["Reference"]
        self.assertAlmostEqual(ref["min"], SCENARIO_HEIGHT, delta=1e-9)
        self.assertAlmostEqual(ref["max"], SCENARIO_HEIGHT, delta=1e-9)

    def test_2_an_operator_command_from_cyclone_is_obeyed(self):
        code, r, err = cyclone("command", "--domain", DOMAIN, "--mode", "step_in_place", "--height", NEW_HEIGHT,
                               "--wait", 30)
        self.assertIsNotNone(r, err)
        self.assertEqual((code, r["result"]), (0, "applied"), (r, err))
        self.assertIn("height 0.400 m", r["reason"])
        applied_tick = r["tick"]
        # The planner's Reference ramps from the applied tick on and holds NEW_HEIGHT after RAMP_TICKS (bounded
        # wait for samples past the ramp: a window that starts inside it sees the ramp, not the command).
        ref = self.listen_from(200, applied_tick + RAMP_TICKS, "after the height ramp")["Reference"]
        self.assertAlmostEqual(ref["min"], NEW_HEIGHT, delta=1e-9)
        self.assertAlmostEqual(ref["max"], NEW_HEIGHT, delta=1e-9)

    def test_3_a_height_out_of_reach_is_rejected_with_the_reason(self):
        code, r, err = cyclone("command", "--domain", DOMAIN, "--mode", "step_in_place", "--height", 0.9, "--wait", 30)
        self.assertIsNotNone(r, err)
        self.assertEqual((code, r["result"]), (1, "rejected"), (r, err))
        self.assertIn("0.9", r["reason"])

    def test_4_the_planner_counted_both_commands(self):
        planner = self.stacks.down(DOMAIN, self.status, names=("mft-planner",))["mft-planner"]
        ops = planner["operator_commands"]
        self.assertEqual((ops["received"], ops["applied"], ops["rejected"]), (2, 1, 1), ops)

if __name__ == "__main__":
    unittest.main(verbosity=2)
