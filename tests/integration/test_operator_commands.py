#!/usr/bin/env python3
"""Operator commands reach the stack and its verdict reaches the operator (docs/guide/operator-commands.md): real
mft-cmd processes against a real stack started through services/mft-supervisor (or single services), each test
on its own DDS domain (90-93), bounded in time, every process cleaned up even on failure. Needs MFT_BIN_DIR
(set by CTest) pointing at the built executables."""
import json
import re
import select
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import unittest
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "python"))
from mftstack.testing import BIN, SCENARIOS, StackUpTestCase, mft_cmd  # noqa: E402

DOMAIN_STACK, DOMAIN_EMPTY, DOMAIN_LATE = 90, 91, 92



class OperatorCommandsOnARunningStack(StackUpTestCase):
    """One realtime stack stepping in place (`up`: it runs until `down`, and on after a fall); the tests run in
    name order against it and the last one stops it and checks the services' counts."""

    tmp_prefix, stack_scenario, stack_domain, stack_run_dir = "mft-opcmd-test-", "step-in-place.yaml", DOMAIN_STACK, True

    @classmethod
    def setUpClass(cls):
        super().setUpClass()
        cls.sent = {"applied_commands": 0, "rejected_commands": 0, "pushes": []}

    def assert_applied(self, code, result, err, what):
        self.assertIsNotNone(result, f"{what}: no JSON from mft-cmd (exit {code}): {err}")
        self.assertEqual((code, result["result"]), (0, "applied"), f"{what}: {result} {err}")
        self.assertTrue(result["acknowledged"], result)
        applied = result["verdicts"][-1]
        self.assertEqual(applied["verdict"], "applied", result)
        return applied

    def test_1_ten_operator_commands_in_a_row_are_all_applied(self):
        commands = [("step_in_place", 0.42), ("step_in_place", 0.41), ("step_in_place", 0.40), ("step_in_place", 0.41),
                    ("step_in_place", 0.42), ("step_in_place", 0.40), ("step_in_place", 0.41), ("step_in_place", 0.42),
                    ("step_in_place", 0.41), ("step_in_place", 0.42)]
        last_tick = 0
        for i, (mode, height) in enumerate(commands):
            code, result, err, wall = mft_cmd(DOMAIN_STACK, "--mode", mode, "--height", height, "--speed", 0.0)
            applied = self.assert_applied(code, result, err, f"command {i + 1}")
            self.sent["applied_commands"] += 1
            self.sent.setdefault("after_s", []).append(applied["after_s"])
            self.sent.setdefault("wall_s", []).append(wall)
            self.assertIn(f"height {height:.3f} m", applied["reason"])
            self.assertGreater(applied["tick"], last_tick)  # each in force from a later tick of the one clock
            last_tick = applied["tick"]

    def test_2_six_pushes_in_a_row_are_all_applied(self):
        pushes = [("now", 2.0), ("right", 2.0), ("now", -2.0), ("left", 2.0), ("now", 1.5), ("right", -1.5)]
        for i, (when, impulse) in enumerate(pushes):
            extra = [] if when == "now" else ["--at-liftoff", when]
            code, result, err, wall = mft_cmd(DOMAIN_STACK, "--push", impulse, *extra)
            applied = self.assert_applied(code, result, err, f"push {i + 1}")
            self.sent.setdefault("after_s", []).append(applied["after_s"])
            self.sent.setdefault("wall_s", []).append(wall)
            self.sent["pushes"].append(impulse)
            self.assertEqual(result["verdicts"][0]["verdict"], "scheduled", result)
            if when != "now":
                self.assertIn(f"next {when}-foot lift-off", result["verdicts"][0]["reason"])
            self.assertIn(f"push of {impulse:.3f} N s applied at t = ", applied["reason"])
            self.assertGreater(applied["time_s"], 0.0)

    def test_3_a_height_outside_the_reachable_range_is_rejected_with_the_reason(self):
        code, result, err, _ = mft_cmd(DOMAIN_STACK, "--mode", "step_in_place", "--height", 0.9)
        self.assertEqual(code, 1, (result, err))
        self.assertEqual(result["result"], "rejected")
        self.assertIn("height 0.9 m outside the reachable range [0.3, 0.46] m", err)
        self.assertIn("rejected", err)
        self.sent["rejected_commands"] += 1
        code, result, err, _ = mft_cmd(DOMAIN_STACK, "--mode", "walk", "--height", 0.42, "--speed", 2.0)
        self.assertEqual(code, 1, (result, err))
        self.assertIn("speed 2 m/s beyond the limit +-0.6 m/s", err)
        self.sent["rejected_commands"] += 1
        # The simulator refuses a push beyond its limit (mft-sim --max-push, 200 N s) with the reason too.
        code, result, err, _ = mft_cmd(DOMAIN_STACK, "--push", 250)
        self.assertEqual(code, 1, (result, err))
        self.assertIn("impulse 250.000 N s beyond the largest accepted push 200.000 N s", err)

    def test_4_a_push_of_20_Ns_is_applied(self):
        code, result, err, _ = mft_cmd(DOMAIN_STACK, "--push", 20)
        applied = self.assert_applied(code, result, err, "push of 20 N s")
        self.sent["pushes"].append(20.0)
        self.assertIn("push of 20.000 N s applied at t = ", applied["reason"])

    def test_5_the_stack_counted_every_command(self):
        self.stacks.down(DOMAIN_STACK)
        planner = json.loads((self.run_dir / "mft-planner.summary.json").read_text())
        sim = json.loads((self.run_dir / "mft-sim.summary.json").read_text())
        ops = planner["operator_commands"]
        self.assertEqual(ops["applied"], self.sent["applied_commands"], planner)
        self.assertEqual(ops["rejected"], self.sent["rejected_commands"], planner)
        self.assertEqual(ops["received"], self.sent["applied_commands"] + self.sent["rejected_commands"], planner)
        self.assertEqual(sim["disturbances_applied"], len(self.sent["pushes"]), sim)
        self.assertEqual(sim["disturbances_rejected"], 1, sim)
        self.assertEqual([p[0] for p in sim["topic_pushes_applied"]], self.sent["pushes"], sim)
        # The impulse the simulator applied is the one asked for (one physics step of J/h).
        self.assertEqual(sim["impulses_applied"], len(self.sent["pushes"]), sim)
        print(f"\n{len(self.sent['wall_s'])} applied commands and pushes: mft-cmd took "
              f"{min(self.sent['wall_s']):.2f}-{max(self.sent['wall_s']):.2f} s, the 'applied' verdict came "
              f"{min(self.sent['after_s']):.3f}-{max(self.sent['after_s']):.3f} s after the write", file=sys.stderr)
        # The logs agree: one 'applied' line per command.
        log = (self.run_dir / "mft-planner.log").read_text(errors="replace")
        self.assertEqual(len(re.findall(r"mft-planner: command seq \d+: applied at tick \d+", log)),
                         self.sent["applied_commands"])
        log = (self.run_dir / "mft-sim.log").read_text(errors="replace")
        self.assertEqual(len(re.findall(r"mft-sim: command seq \d+: applied at tick \d+", log)), len(self.sent["pushes"]))


class OperatorCommandsWithoutAStack(unittest.TestCase):
    def setUp(self):
        self.tmp = Path(tempfile.mkdtemp(prefix="mft-opcmd-test-"))
        self.procs = []

    def tearDown(self):
        for p in self.procs:
            if p.poll() is None:
                p.send_signal(signal.SIGTERM)
                try:
                    p.wait(timeout=10)
                except subprocess.TimeoutExpired:
                    p.kill()
                    p.wait()
            for f in (p.stdout, p.stderr):
                f.close()
        shutil.rmtree(self.tmp, ignore_errors=True)

    def test_no_stack_on_the_domain_fails_within_the_bound(self):
        code, result, err, wall = mft_cmd(DOMAIN_EMPTY, "--mode", "stand", "--timeout", 2)
        self.assertEqual(code, 3, err)
        self.assertIn(f"no stack answered on domain {DOMAIN_EMPTY} within 2 s", err)
        self.assertEqual(result["result"], "no_stack")
        self.assertGreaterEqual(wall, 2.0)
        self.assertLess(wall, 8.0, "mft-cmd did not keep its bound")
        print(f"\nmft-cmd on an empty domain with --timeout 2: exit 3 after {wall:.2f} s", file=sys.stderr)
        code, result, err, wall = mft_cmd(DOMAIN_EMPTY, "--push", 3, "--timeout", 1)
        self.assertEqual(code, 3, err)
        self.assertIn(f"no stack answered on domain {DOMAIN_EMPTY} within 1 s", err)

    def start(self, *argv):
        p = subprocess.Popen([str(a) for a in argv], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        self.procs.append(p)
        return p

    def read_line_matching(self, proc, pattern, timeout):
        """The first stdout line of `proc` matching `pattern`, within `timeout` seconds (else a failure)."""
        end = time.monotonic() + timeout
        seen = []
        while time.monotonic() < end:
            ready, _, _ = select.select([proc.stdout], [], [], 0.2)
            if ready:
                line = proc.stdout.readline()
                if not line:
                    break
                seen.append(line)
                if re.search(pattern, line):
                    return line
        self.fail(f"no line matching {pattern!r} within {timeout} s (exit {proc.poll()}): {''.join(seen)[-2000:]}")

    def test_a_planner_that_joins_after_the_command_was_written_still_gets_it(self):
        # The recorder reads OperatorCommand but never answers: mft-cmd writes to it and waits for a verdict.
        recorder = self.start(BIN / "mft-record", "--domain", DOMAIN_LATE, "--scenario", SCENARIOS / "stand.yaml",
                              "--output", self.tmp / "late.rawlog")
        self.read_line_matching(recorder, r"^READY mft-record", 30)
        # A reader that acknowledges but never answers: no verdict within the bound is a failure, not "sent".
        code, result, err, wall = mft_cmd(DOMAIN_LATE, "--mode", "stand", "--height", 0.4, "--verdict-timeout", 1.5)
        self.assertEqual(code, 5, (result, err))
        self.assertEqual((result["result"], result["acknowledged"], result["readers_matched"]), ("no_verdict", True, 1))
        self.assertIn("no verdict from mft-planner on OperatorCommand seq", err)
        cmd = self.start(BIN / "mft-cmd", "--domain", DOMAIN_LATE, "--mode", "stand", "--height", 0.9,
                         "--verdict-timeout", 60)
        self.read_line_matching(cmd, r"OperatorCommand seq \d+ .* written to 1 reader\(s\) on domain \d+, acknowledged", 30)
        time.sleep(0.5)
        self.assertIsNone(cmd.poll(), "mft-cmd ended before any planner existed")
        # Now the planner starts: it never saw the write, yet it judges the command.
        planner = self.start(BIN / "mft-planner", "--domain", DOMAIN_LATE, "--scenario", SCENARIOS / "stand.yaml")
        try:
            out, err = cmd.communicate(timeout=60)
        except subprocess.TimeoutExpired:
            self.fail("mft-cmd got no verdict from the late planner within 60 s")
        self.assertEqual(cmd.returncode, 1, (out, err))
        self.assertIn("mft-planner rejected OperatorCommand", err)
        self.assertIn("height 0.9 m outside the reachable range [0.3, 0.46] m", err)
        planner.send_signal(signal.SIGTERM)
        p_out, p_err = planner.communicate(timeout=30)
        self.assertIn("rejected: height 0.9 m outside the reachable range", p_err)


if __name__ == "__main__":
    unittest.main(verbosity=2)
