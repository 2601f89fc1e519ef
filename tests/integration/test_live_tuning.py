#!/usr/bin/env python3
"""Live tuning (docs/guide/live-tuning.md): `mft-cmd --set` against real stacks through services/mft-supervisor.

Lockstep (domain 98): the same 72 s standing run twice, recorded, once as it is and once with
`--set wbc.gains.base_z.kp=100 --at 12` sent while it runs. The torques are identical up to the tick of 12 s
and differ from it on; the base settles lower by about what config/wbc.yaml's note predicts for the weaker height
gain (w_fc m^2 g / (2 w_z kp): 2.6 m/s^2 / kp); the recording holds the applied change at its tick, and
`mft-replay --through-wbc` reproduces the recorded torques with it (and does not without it). Refusals in
lockstep: no --at, a time already passed.
Realtime (domain 99): changes at the next tick, refusals with the strict loader's message (invalid value, unknown
key, key not tunable) and a non-zero exit, and `mft-supervisor status` listing what was applied.
Needs MFT_BIN_DIR (set by CTest)."""
import csv
import concurrent.futures
import contextlib
import json
import os
import signal
import subprocess
import sys
import time
import unittest
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "python"))
from mftstack import testing  # noqa: E402
from mftstack.testing import BIN, SCENARIOS, StackRunner, StackUpTestCase  # noqa: E402

DOMAIN_LOCKSTEP, DOMAIN_REALTIME = 98, 99
AT_S = 12.0        # the change's simulated time
# Of the standing run: 60 s after the change for the base to settle (the refusals are sent with the run held).
DURATION_S = 72.0
KP_BEFORE, KP_AFTER = 400.0, 100.0



def mft_cmd(domain, *args, timeout=120):
    """mft-cmd --json; returns (exit code, parsed JSON or None, stderr)."""
    return testing.mft_cmd(domain, *args, timeout=timeout)[:3]


def export(rawlog, out, labels):
    p = subprocess.run([str(BIN / "mft-export"), str(rawlog), "--csv", str(out), "--labels", ",".join(labels)],
                       capture_output=True, text=True, timeout=300)
    if p.returncode != 0:
        raise AssertionError(f"mft-export {rawlog}: exit {p.returncode}: {p.stderr}")
    tables = {}
    for label in labels:  # a label without observations gets no file
        path = out / f"{label}.csv"
        with open(path) if path.exists() else open("/dev/null") as f:
            tables[label] = list(csv.DictReader(f))
    return tables


def by_tick(rows, column):
    return {int(float(r["tick"])): float(r[column]) for r in rows}


def taus(rows):
    return {int(float(r["tick"])): [float(r[c]) for c in ("tau_q4", "tau_q6", "tau_q8", "tau_q10")] for r in rows}


def replay(rawlog, *extra):
    p = subprocess.run([str(BIN / "mft-replay"), str(rawlog), "--through-wbc", "--json", *extra],
                       capture_output=True, text=True, timeout=600)
    try:
        return p.returncode, json.loads(p.stdout), p.stderr
    except ValueError:
        raise AssertionError(f"mft-replay printed no JSON (exit {p.returncode}): {p.stderr[-2000:]}")


def simulator_of(proc):
    """The pid of the mft-sim the supervisor process `proc` started."""
    pids = [pid for pid, comm, _, _ in testing.child_processes(proc.pid) if comm == "mft-sim"]
    assert len(pids) == 1, f"the stack's mft-sim is not running (the run ended early?): {pids}"
    return pids[0]


@contextlib.contextmanager
def held(pid):
    """A lockstep stack stands still while its simulator (our child's child, by pid) is stopped."""
    os.kill(pid, signal.SIGSTOP)
    try:
        yield
    finally:
        os.kill(pid, signal.SIGCONT)


class LiveTuningInLockstep(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.stacks = StackRunner(prefix="mft-live-tuning-")
        tmp = cls.stacks.path
        scenario = (SCENARIOS / "stand.yaml").read_text().replace("duration_s: 10.0", f"duration_s: {DURATION_S}")
        assert f"duration_s: {DURATION_S}" in scenario
        cls.scenario = tmp / "stand-live.yaml"
        cls.scenario.write_text(scenario)
        cls.plain, cls.tuned = tmp / "plain.rawlog", tmp / "tuned.rawlog"
        # The run as it is.
        code, cls.plain_summary, err = cls.stacks.run_json(cls.scenario, DOMAIN_LOCKSTEP, "--record", cls.plain,
                                                           timeout=600)
        assert code == 0, f"plain run: exit {code}: {err[-3000:]}"
        # The same run with the change sent while it runs. mft-cmd starts once mft-wbc has created its live-tuning
        # endpoints (it writes its empty mft-wbc.tuning.json then): earlier, the supervisor's busy-domain probe would
        # see mft-cmd's participant and refuse the domain.
        proc = cls.stacks.start_run(cls.scenario, DOMAIN_LOCKSTEP, "--record", cls.tuned)
        cls.tuned_run_dir = proc.run_dir
        deadline = time.monotonic() + 120
        while not (proc.run_dir / "mft-wbc.tuning.json").exists():
            assert proc.poll() is None, f"the tuned run ended before mft-wbc was up: {proc.communicate()[1][-3000:]}"
            assert time.monotonic() < deadline, "mft-wbc did not come up within 120 s"
            time.sleep(0.05)
        cls.set_result = mft_cmd(DOMAIN_LOCKSTEP, "--set", f"wbc.gains.base_z.kp={KP_AFTER:g}", "--at", AT_S,
                                 "--timeout", 60, "--verdict-timeout", 60)
        # Refused by a lockstep stack: a change without a stated time, and one at a time already passed (both sent
        # at once). The simulator is held (SIGSTOP) meanwhile: the WBC judges requests off its loop, but a run that
        # ends before a new mft-cmd's discovery is done never hears it (seconds with both cores loaded).
        with held(simulator_of(proc)):
            with concurrent.futures.ThreadPoolExecutor(max_workers=2) as pool:
                no_at = pool.submit(mft_cmd, DOMAIN_LOCKSTEP, "--set", "wbc.weights.slack=1e4", "--timeout", 30)
                passed = pool.submit(mft_cmd, DOMAIN_LOCKSTEP, "--set", "wbc.weights.slack=1e4", "--at", 0.5,
                                     "--timeout", 30)
                cls.no_at, cls.passed = no_at.result(), passed.result()
        code, cls.tuned_summary, err = cls.stacks.finish(proc, timeout=600)
        assert code == 0, f"tuned run: exit {code}: {err[-3000:]}"
        labels = ["gt_q", "joint_tau_cmd", "config_change", "command_verdict"]
        cls.a = export(cls.plain, tmp / "plain-csv", labels)
        cls.b = export(cls.tuned, tmp / "tuned-csv", labels)

    @classmethod
    def tearDownClass(cls):
        cls.stacks.close()

    def applied_record(self):
        rows = [r for r in self.b["config_change"] if float(r["applied"]) == 1.0]
        self.assertEqual(len(rows), 1, self.b["config_change"])
        return rows[0]

    def test_1_the_change_was_applied_at_the_stated_time(self):
        code, result, err = self.set_result
        self.assertEqual((code, result and result["result"]), (0, "applied"), (result, err))
        change = result["changes"][0]
        self.assertEqual(change["answered_by"], "mft-wbc")
        self.assertEqual([v["verdict"] for v in change["verdicts"]], ["scheduled", "applied"], change)
        applied = change["verdicts"][-1]
        self.assertAlmostEqual(applied["time_s"], AT_S, delta=1e-9 + 1e-3)
        self.assertIn(f"gains.base_z.kp = {KP_AFTER:g} in force from tick {applied['tick']}", applied["reason"])
        self.assertIn(f"(was {KP_BEFORE:g})", change["verdicts"][0]["reason"])
        print(f"\nlockstep: --set wbc.gains.base_z.kp={KP_AFTER:g} --at {AT_S} applied at tick {applied['tick']} "
              f"(t = {applied['time_s']} s), verdict {applied['after_s']} s after the write", file=sys.stderr)

    def test_2_a_lockstep_stack_refuses_a_change_without_a_time_or_in_its_past(self):
        code, result, err = self.no_at
        self.assertEqual(code, 1, (result, err))
        self.assertIn("a lockstep stack takes a change at a stated simulated time only (mft-cmd --at T)", err)
        code, result, err = self.passed
        self.assertEqual(code, 1, (result, err))
        self.assertRegex(err, r"t = 0\.500 s has passed \(the stack is at t = \d+\.\d+ s\): give a later --at")

    def test_3_the_recording_holds_the_change_at_its_tick(self):
        row = self.applied_record()
        tick = int(float(row["tick"]))
        self.assertEqual(tick, self.set_result[1]["changes"][0]["verdicts"][-1]["tick"])
        self.assertEqual(float(row["target"]), 0.0)    # wbc.yaml
        self.assertEqual(float(row["key"]), 9.0)       # tunableKeys()[9] = gains.base_z.kp
        self.assertEqual(float(row["count"]), 1.0)
        self.assertEqual(float(row["value_0"]), KP_AFTER)
        self.assertEqual(float(row["at_s"]), AT_S)
        # Every request is recorded as a request (applied 0), the refused ones too: mft-cmd waits until every reader
        # of ConfigChange, the recorder included, has acknowledged it (docs/guide/operator-commands.md#every-reader-gets-it);
        # only the change in force is an applied record.
        requests = [r for r in self.b["config_change"] if float(r["applied"]) == 0.0]
        for result in (self.set_result, self.no_at, self.passed):
            self.assertEqual(result[1]["changes"][0]["not_delivered_to"], [], result)
        self.assertEqual(sorted(float(r["key"]) for r in requests), [6.0, 6.0, 9.0], requests)  # slack twice, base_z.kp
        self.assertEqual(self.tuned_summary["services"]["mft-wbc"]["live_changes"],
                         {"received": 3, "rejected": 2, "applied": 1})

    def test_4_torques_identical_before_the_tick_different_from_it(self):
        tick = int(float(self.applied_record()["tick"]))
        ta, tb = taus(self.a["joint_tau_cmd"]), taus(self.b["joint_tau_cmd"])
        common = sorted(set(ta) & set(tb))
        self.assertGreater(len(common), DURATION_S * 1000 * 0.99)
        differing = [k for k in common if max(abs(x - y) for x, y in zip(ta[k], tb[k])) > 0.0]
        self.assertTrue(differing, "the change made no difference")
        self.assertEqual(differing[0], tick, "the runs part at another tick than the recorded one")

    def test_5_the_base_settles_lower_by_the_predicted_offset(self):
        za, zb = by_tick(self.a["gt_q"], "z"), by_tick(self.b["gt_q"], "z")
        tick = int(float(self.applied_record()["tick"]))
        window = [k for k in za if k in zb and tick + 6000 <= k < tick + 11000]  # 6-11 s after the change
        self.assertGreater(len(window), 4900)
        mean_a = sum(za[k] for k in window) / len(window)
        mean_b = sum(zb[k] for k in window) / len(window)
        # config/wbc.yaml: the height settles w_fc m^2 g / (2 w_z kp) = 2.6 m/s^2 / kp below its reference.
        predicted = 2.6 / KP_AFTER - 2.6 / KP_BEFORE
        measured = mean_a - mean_b
        print(f"\nlockstep: mean base height 6-11 s after the change: {mean_a:.5f} m as it is, {mean_b:.5f} m with "
              f"kp {KP_AFTER:g}: {1000 * measured:.2f} mm lower (predicted {1000 * predicted:.2f} mm)", file=sys.stderr)
        self.assertGreater(measured, 0.5 * predicted)
        self.assertLess(measured, 1.5 * predicted)

    def test_6_replay_through_the_wbc_reproduces_the_torques_with_the_change(self):
        code, r, err = replay(self.tuned)
        self.assertEqual(code, 0, (r, err))
        self.assertTrue(r["ok"], r)
        self.assertEqual((r["live_changes"], r["live_changes_applied"]), (1, 1), r)
        self.assertGreater(r["ticks_compared"], DURATION_S * 1000 * 0.99)
        self.assertLessEqual(r["max_abs_diff_Nm"], 1e-9, r)
        # Without the recorded change the replay parts from the recording exactly at the change's tick.
        code, r2, err = replay(self.tuned, "--ignore-live-changes")
        self.assertNotEqual(code, 0, r2)
        self.assertEqual(r2["first_differing_tick"], int(float(self.applied_record()["tick"])), r2)
        print(f"\nreplay --through-wbc: {r['ticks_compared']} ticks, max |dtau| {r['max_abs_diff_Nm']:.3g} N m with the "
              f"recorded change; {r2['max_abs_diff_Nm']:.3g} N m without it (first at tick "
              f"{r2['first_differing_tick']})", file=sys.stderr)

    def test_7_the_recording_holds_the_verdicts_with_their_reasons(self):
        # The WBC's answers (source 2): the change scheduled then applied, and the two refusals, each with the
        # reason mft-cmd printed, exactly as text, and the seq of its request.
        rows = [r for r in self.b["command_verdict"] if int(r["source"]) == 2]
        change = self.set_result[1]["changes"][0]
        applied = [r for r in rows if int(r["verdict"]) == 2]
        self.assertEqual(len(applied), 1, rows)
        self.assertEqual(applied[0]["reason"], change["verdicts"][-1]["reason"])
        self.assertEqual(int(applied[0]["tick"]), change["verdicts"][-1]["tick"])
        self.assertEqual([int(r["verdict"]) for r in rows if r["seq"] == applied[0]["seq"]], [1, 2], rows)
        rejected = [r for r in rows if int(r["verdict"]) == 0]
        self.assertEqual(len(rejected), 2, rows)
        reasons = " | ".join(r["reason"] for r in rejected)
        self.assertIn("a lockstep stack takes a change at a stated simulated time only (mft-cmd --at T)", reasons)
        self.assertRegex(reasons, r"t = 0\.500 s has passed")
        self.assertEqual(self.a["command_verdict"], [])  # the plain run was asked nothing


class LiveTuningInRealtime(StackUpTestCase):
    """One realtime stack standing (`up`); the tests run in name order and the last one stops it."""

    tmp_prefix, stack_scenario, stack_domain, stack_run_dir = "mft-live-tuning-rt-", "stand.yaml", DOMAIN_REALTIME, True


    def test_1_changes_apply_at_the_next_tick(self):
        code, result, err = mft_cmd(DOMAIN_REALTIME, "--set", "wbc.weights.slack=1e5",
                                    "--set", "planner.foot_placement.k_v=0.145")
        self.assertEqual((code, result and result["result"]), (0, "applied"), (result, err))
        wbc, planner = result["changes"]
        self.assertEqual((wbc["answered_by"], planner["answered_by"]), ("mft-wbc", "mft-planner"))
        self.assertIn("weights.slack = 100000 in force from tick", wbc["verdicts"][-1]["reason"])
        self.assertIn("(was 1000) accepted: in force from the next tick", wbc["verdicts"][0]["reason"])
        self.assertIn("foot_placement.k_v = 0.145 in force from tick", planner["verdicts"][-1]["reason"])
        self.assertGreater(wbc["verdicts"][-1]["tick"], 0)

    def test_2_invalid_changes_are_refused_with_the_loaders_message(self):
        # A value that is no number, or out of its key's range (common/config_schema.cpp), is refused by mft-cmd
        # before it is sent (exit 2); the rest reach the stack, which refuses them with its loader's message.
        local = [("wbc.weights.slack=abc", "weights.slack: expected a number or a list of numbers, got 'abc'"),
                 ("wbc.gains.base_z.kp=-5", "gains.base_z.kp: must lie in [0, 100000] 1/s^2 (got -5)")]
        for item, message in local:
            code, result, err = mft_cmd(DOMAIN_REALTIME, "--set", item)
            self.assertEqual(code, 2, (item, result, err))
            self.assertIn(message, err, item)
        cases = [("wbc.weights.slak=1", "wbc.yaml (live change): unknown key weights.slak"),
                 ("wbc.variant=sa", "wbc.yaml (live change): variant: not tunable while the stack runs"),
                 ("planner.gait.step_duration_s=0.3",
                  "planner.yaml (live change): gait.step_duration_s: not tunable while the stack runs")]
        for item, message in cases:
            code, result, err = mft_cmd(DOMAIN_REALTIME, "--set", item)
            self.assertEqual(code, 1, (item, result, err))
            self.assertEqual(result["result"], "rejected", result)
            self.assertIn(message, err, item)
        # Not a file the stack tunes: a usage error of mft-cmd itself.
        code, result, err = mft_cmd(DOMAIN_REALTIME, "--set", "robot.mass=3")
        self.assertEqual(code, 2, err)
        self.assertIn("'robot' is not a live-tunable file (wbc or planner)", err)

    def test_3_status_lists_the_applied_changes(self):
        st = self.stacks.status(DOMAIN_REALTIME)
        wbc, planner = st["live_changes"]["mft-wbc"], st["live_changes"]["mft-planner"]
        self.assertEqual([(c["key"], c["value"], c["previous"]) for c in wbc], [("weights.slack", "100000", "1000")])
        self.assertEqual([(c["key"], c["value"], c["previous"]) for c in planner], [("foot_placement.k_v", "0.145", "0.16")])
        self.assertGreater(wbc[0]["tick"], 0)
        self.assertAlmostEqual(wbc[0]["time_s"], wbc[0]["tick"] * 1e-3, delta=1e-6)
        text = subprocess.run(self.stacks.command("status", "--domain", DOMAIN_REALTIME), env=self.stacks.env,
                              capture_output=True, text=True, timeout=30).stdout
        self.assertIn("live change    mft-wbc: weights.slack = 100000 (was 1000) from tick", text)

    def test_4_the_services_counted_them(self):
        status = self.stacks.status(DOMAIN_REALTIME)
        summaries = self.stacks.down(DOMAIN_REALTIME, status)
        # the two refused by mft-cmd itself never reached the stack
        self.assertEqual(summaries["mft-wbc"]["live_changes"], {"received": 3, "rejected": 2, "applied": 1})
        self.assertEqual(summaries["mft-planner"]["live_changes"], {"received": 2, "rejected": 1, "applied": 1})


if __name__ == "__main__":
    unittest.main(verbosity=2)
