#!/usr/bin/env python3
"""Integration tests of the multi-process stack: real mft-sim, mft-estimator, mft-planner and mft-wbc processes
started through services/mft-supervisor, each test on its own DDS domain, bounded in time, every process
cleaned up even on failure. Needs MFT_BIN_DIR (set by CTest) pointing at the built executables."""
import importlib.util
import os
import shutil
import signal
import sys
import time
import unittest
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "python"))
from mftstack.simlog import SimLog, reserve_cpu_share  # noqa: E402
from mftstack.testing import CONFIG, SCENARIOS, StackTestCase, pid_alive  # noqa: E402

_spec = importlib.util.spec_from_file_location("hop_table", Path(__file__).resolve().parents[2] / "scripts" / "hop-table.py")
_hop_module = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(_hop_module)
hop_table = _hop_module.hop_table  # scripts/hop-table.py: the per-hop split of a traced lockstep run
# A domain block of its own per test process so that parallel CTest runs never meet.
DOMAIN_BASE = 100 + (os.getpid() % 40) * 3


class StackTest(StackTestCase):
    tmp_prefix = "mft-stack-test-"

    def test_lockstep_steps_in_place_with_ticks_matching_on_every_topic(self):
        hops = self.stacks.path / "hops"  # the per-hop trace of this run (docs/results/loop-benchmark.md), checked at the end
        hops.mkdir()
        code, s, err = self.stacks.run_json("step-in-place.yaml", DOMAIN_BASE,
                                            env=dict(self.stacks.env, MFT_HOP_TRACE=str(hops)))
        self.assertEqual(code, 0, err[-3000:])
        self.assertFalse(s["fell"], s["services"]["mft-sim"].get("fall_reason"))
        self.assertEqual(s["ticks"], 10000)
        self.assertAlmostEqual(s["sim_time_s"], 10.0, places=6)
        for name in ("mft-estimator", "mft-planner", "mft-wbc"):
            svc = s["services"][name]
            self.assertEqual(svc["ticks"], 10000, name)       # every tick answered once
            self.assertEqual(svc["last_tick"], 9999, name)    # on the simulator's clock
        self.assertEqual(s["services"]["mft-wbc"]["non_optimal_solves"], 0)
        self.assertEqual(s["wbc_safety_events"], 0)
        # Lockstep: the chain ran on the one CPU its domain picks (docs/results/loop-benchmark.md).
        allowed = sorted(os.sched_getaffinity(0))
        self.assertEqual(s["chain_cpu"], allowed[DOMAIN_BASE % len(allowed)])
        sim = s["services"]["mft-sim"]
        self.assertLess(sim["max_closure_error_m"], 1e-5)
        self.assertGreater(sim["touchdowns"][0], 5)          # it really steps
        self.assertLess(abs(sim["average_speed_mps"]), 0.05)
        # The hop trace: every service stamped every tick, the stamps of the four processes are in causal order
        # (no interval below zero), the intervals add up to the tick, and the WBC's interval holds its own tick.
        table = hop_table(hops)
        self.assertEqual(table["ticks"], 10000 - 100 - 1)  # all but the start-up ticks and the last
        for row in table["intervals"]:
            self.assertEqual(row["count"], table["ticks"], row["interval"])
            self.assertGreaterEqual(row["min"], 0.0, row["interval"])
        self.assertAlmostEqual(sum(r["mean"] for r in table["intervals"]), table["tick_us"]["mean"],
                               delta=0.01 * table["tick_us"]["mean"])
        wbc = next(r for r in table["intervals"] if r["interval"] == "WBC compute")
        self.assertGreaterEqual(wbc["p50"], 0.9 * s["services"]["mft-wbc"]["tick_time_us"]["p50"])
        print(f"\nlockstep per tick: mean {table['tick_us']['mean']:.0f} us, p50 {table['tick_us']['p50']:.0f} us; "
              + ", ".join(f"{r['interval'].split(' ->')[0]} {r['p50']:.0f}" for r in table["intervals"]), file=sys.stderr)

    def test_realtime_steps_in_place(self):
        code, s, err = self.stacks.run_json("step-in-place.yaml", DOMAIN_BASE + 1, "--mode", "realtime", "--stall-probe")
        self.assertEqual(code, 0, err[-3000:])
        sim = s["services"]["mft-sim"]
        self.assertFalse(s["fell"], sim.get("fall_reason"))
        self.assertEqual(s["ticks"], 10000)
        self.assertGreater(s["wall_time_s"], 9.9)             # it ran on the wall clock
        allowed = sorted(os.sched_getaffinity(0))            # realtime too: the chain on the CPU its domain picks
        self.assertEqual(s["chain_cpu"], allowed[(DOMAIN_BASE + 1) % len(allowed)])
        self.assertEqual(s["rt_threads"], "loop")             # only the 1 kHz threads SCHED_FIFO on that core
        self.assertGreater(sim["latency_us"]["count"], 9000)  # nearly every command answered within its period
        print(f"\nrealtime: deadline misses {sim['deadline_misses']}, damping ticks {sim['damping_ticks']}, "
              f"latency p50 {sim['latency_us']['p50']:.0f} us p99 {sim['latency_us']['p99']:.0f} us, simulator "
              f"stalls {sim['sim_stalls']}, its worst lateness before each miss {sim['damping_onset_sim_late_ms']} ms; "
              f"CPU stalls {sim['cpu_stalls']}, misses during them {sim['deadline_misses_during_cpu_stalls']}, "
              f"unexplained {sim['deadline_misses_unexplained']} (stalled ms per miss {sim['miss_cpu_stalled_ms']})",
              file=sys.stderr)
        # The stall probe ran on every CPU of the stack and judged every miss it kept.
        self.assertEqual(sim["cpu_stalls"]["probe_cpus"], len(os.sched_getaffinity(0)))
        self.assertEqual(len(sim["miss_cpu_stalled_ms"]), min(sim["deadline_misses"], 256))
        self.assertEqual(sim["deadline_misses_during_cpu_stalls"] + sim["deadline_misses_unexplained"], sim["deadline_misses"])
        # Deadline misses. On this 2-vCPU VM an idle machine gives 0 in most 10 s runs, but the hypervisor's
        # steal comes in bursts (one CI run: 8 misses with 8 simulator stalls; another: a 6.5 ms stall and an
        # 8 ms damping episode; a stall of only the controller's vCPU cannot be told from the chain's). The
        # test asserts what a slow or broken chain violates (a dead controller damps for hundreds of ms, a slow
        # one on most ticks): every episode short and damping on at most 5 % of the ticks (a run with 113
        # simulator stalls in 10 s damped 94 ticks); it prints the rest.
        self.assertEqual(len(sim["damping_onset_sim_late_ms"]), min(sim["deadline_misses"], 64))
        self.assertLessEqual(sim["damping_ticks"], 500, sim["damping_episodes"])
        for onset, late_ms, duration_ms in sim["damping_episodes"]:
            self.assertLessEqual(duration_ms, 50.0, sim["damping_episodes"])  # commands resume at once

    def test_killed_controller_puts_the_sim_into_damping_and_is_restarted(self):
        domain = DOMAIN_BASE + 2
        st = self.stacks.up("stand.yaml", domain, "--mode", "realtime")
        wbc_pid = st["services"]["mft-wbc"]["pid"]
        run_dir = Path(st["run_dir"])
        sim_log = SimLog(run_dir / "mft-sim.log")
        sim_log.wait_for_sim_time(2.0)  # standing
        os.kill(wbc_pid, signal.SIGKILL)
        deadline = time.time() + 20
        restarted = False
        while time.time() < deadline and not restarted:
            time.sleep(0.2)
            log = (run_dir / "mft-wbc.log").read_text(errors="replace")
            restarted = log.count("READY mft-wbc") >= 2
        self.assertTrue(restarted, "the supervisor did not restart mft-wbc")
        # Commands flow again: a whole second of sim time without damping after the restart (not a fixed sleep).
        sim_log.wait_for_commands_flowing(sim_log.sim_time(), timeout=30)
        sim = self.stacks.down(domain, st)["mft-sim"]
        self.assertFalse(pid_alive(wbc_pid))
        self.assertGreaterEqual(sim["deadline_misses"], 1)
        self.assertGreaterEqual(sim["watchdog_recoveries"], 1)   # back to normal commands after the restart
        self.assertGreater(sim["damping_ticks"], 0)
        # The kill is the longest damping episode (the others are single late commands): the sim must have
        # gone into damping within 5 ms after the deadline, and stayed there until the restarted WBC answered.
        onset, late_ms, duration_ms = max(sim["damping_episodes"], key=lambda e: e[2])
        self.assertGreater(duration_ms, 50.0, sim["damping_episodes"])
        self.assertLessEqual(late_ms, 5.0, sim["damping_episodes"])
        print(f"\nkill -9 mft-wbc: damping {late_ms:.2f} ms after the deadline, for {duration_ms:.0f} ms until the "
              f"restarted controller answered; all episodes {sim['damping_episodes']}", file=sys.stderr)

    def test_bad_inputs_give_clear_errors_and_start_nothing(self):
        bad = self.tmp / "bad"
        bad.mkdir()
        (bad / "malformed.yaml").write_text("name: [unclosed\n")
        text = (SCENARIOS / "stand.yaml").read_text()
        (bad / "unknown-key.yaml").write_text(text.replace("duration_s: 10.0", "duration_s: 10.0\nspeed_up: 2"))
        (bad / "bad-controller.yaml").write_text(text.replace("controller: mft", "controller: pid"))
        cases = [
            (bad / "malformed.yaml", [], "not valid YAML"),
            (bad / "unknown-key.yaml", [], "unknown key speed_up"),
            (bad / "bad-controller.yaml", [], "controller: unknown value 'pid'"),
            (SCENARIOS / "stand.yaml", ["--domain", "999"], "bad domain id 999"),
        ]
        for scenario, extra, expect in cases:
            args = ["run", scenario] + (extra or ["--domain", DOMAIN_BASE])
            code, out, err = self.stacks.supervisor(*args, timeout=60)
            self.assertEqual(code, 2, (scenario, err))
            self.assertIn(expect, err)
        cfg = self.tmp / "config"
        shutil.copytree(CONFIG, cfg)
        (cfg / "wbc.yaml").unlink()
        code, out, err = self.stacks.supervisor("run", SCENARIOS / "stand.yaml", "--domain", DOMAIN_BASE, "--config-dir", cfg)
        self.assertEqual(code, 2)
        self.assertIn("missing configuration", err)
        self.assertFalse((self.tmp / "runs").exists(), "a run folder was created: something started")


if __name__ == "__main__":
    reserve_cpu_share()  # a share of the CPU whatever else runs (python/mftstack/simlog.py)
    unittest.main(verbosity=2)
