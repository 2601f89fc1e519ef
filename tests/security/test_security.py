#!/usr/bin/env python3
"""Security tests of the stack (docs/guide/security.md): a secured stack (services/mft-supervisor --secure, material
from scripts/make-security.sh in a temporary directory) refuses participants without a valid identity and
writers without permission, and still steps in place. Real processes, DDS domains 220-224, bounded in time,
every process cleaned up (by pid, through the supervisor's `down`) even on failure."""
import json
import shutil
import subprocess
import sys
import tempfile
import unittest
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "python"))
from mftstack.simlog import SimLog, helper_realtime_prefix, reserve_cpu_share  # noqa: E402
from mftstack.testing import BIN, REPO, SCENARIOS, StackTestCase  # noqa: E402

MAKE = REPO / "scripts" / "make-security.sh"
DOMAIN = 220
# How long a new secured participant may take to match the stack's writers: the supervisor's own bound for a
# secured chain to connect (SECURE_START_TIMEOUT_S in python/mftstack/processes.py), past which Fast DDS's handshake
# is taken as stuck. On an idle machine it takes 0.3-1.2 s.
SECURE_MATCH_TIMEOUT_S = 10
# Fast DDS 2.9.1's handshake between two participants sometimes never completes (docs/guide/security.md; seen here
# with the other core busy: a new participant of the recorder's identity matched neither the simulator's nor
# the WBC's writer within 10 s). The supervisor then starts a new participant (SECURE_RUN_ATTEMPTS = 2), which
# authenticates afresh; the test does the same with its listener, at most this many times, and says so.
SECURE_MATCH_ATTEMPTS = 3


class SecurityTest(StackTestCase):
    tmp_prefix = "mft-security-test-"

    @classmethod
    def setUpClass(cls):
        cls.tmp = Path(tempfile.mkdtemp(prefix="mft-security-test-"))
        cls.sec = cls.tmp / "sec"
        cls.rogue = cls.tmp / "rogue"  # a second CA with the same identity names: self-consistent, not trusted
        for d in (cls.sec, cls.rogue):
            p = subprocess.run(["bash", str(MAKE), str(d)], capture_output=True, text=True, timeout=120)
            if p.returncode != 0:
                raise RuntimeError(f"make-security.sh failed: {p.stderr}")

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def setUp(self):
        super().setUp()
        self.procs = self.stacks.procs  # mft-inject processes too: ended by close() whatever happens

    # ------------------------------------------------------------------------------------------ helpers
    def up(self, domain, scenario, *extra):
        return self.stacks.up(scenario, domain, "--mode", "realtime", *extra)

    def down(self, domain, status):
        return self.stacks.down(domain, status)

    def inject(self, *args, timeout=60):
        # At SCHED_FIFO just below the stack (python/mftstack/simlog.py): a listener's counts do not depend on the load.
        cmd = helper_realtime_prefix() + [str(BIN / "mft-inject")] + [str(a) for a in args] + ["--json"]
        p = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        self.procs.append(p)
        out, err = p.communicate(timeout=timeout)
        try:
            return p.returncode, json.loads(out.strip().splitlines()[-1])
        except (ValueError, IndexError):
            self.fail(f"mft-inject printed no JSON (exit {p.returncode}): {err[-2000:]}")

    # -------------------------------------------------------------------------------------------- tests
    def test_secured_stack_refuses_strangers_and_unpermitted_writers(self):
        domain = DOMAIN
        st = self.up(domain, "stand.yaml", "--secure", self.sec)
        SimLog(Path(st["run_dir"]) / "mft-sim.log").wait_for_sim_time(1.0)
        # (1) No identity at all: nothing matches, nothing arrives, on any topic.
        code, r = self.inject("--domain", domain, "--listen", "all", "--seconds", 3)
        self.assertEqual(code, 0, r)
        self.assertEqual(sum(t["received"] for t in r["listen"].values()), 0, r)
        self.assertEqual(sum(t["matched_writers"] for t in r["listen"].values()), 0, r)
        # (2) A self-consistent identity of another CA (same names): authentication fails, 0 samples.
        code, r = self.inject("--domain", domain, "--secure", self.rogue, "--identity", "record",
                              "--listen", "SensorData,JointCommand", "--seconds", 2)
        self.assertEqual(code, 0, r)
        self.assertEqual(sum(t["received"] for t in r["listen"].values()), 0, r)
        # (3) The recorder's valid identity receives: the secured topics do flow (the test can see data). The
        # secure handshake with each of the stack's participants must finish before a reader matches: 0.3-1.2 s
        # on an idle machine, longer with the CPU busy (public-key operations at normal priority beside a
        # SCHED_FIFO stack). A fixed 3 s window that included it failed once under load with the JointCommand
        # reader never matched; the window now starts once both readers have a writer (bounded), and from then
        # on every tick arrives.
        for attempt in range(1, SECURE_MATCH_ATTEMPTS + 1):
            code, r = self.inject("--domain", domain, "--secure", self.sec, "--identity", "record",
                                  "--listen", "SensorData,JointCommand", "--wait-writers", SECURE_MATCH_TIMEOUT_S,
                                  "--seconds", 3)
            if r["writers_matched_after_s"] >= 0.0:
                break
            print(f"\nrecorder identity, participant {attempt}: no writer matched on every topic within "
                  f"{SECURE_MATCH_TIMEOUT_S} s (stuck secure handshake): {r['listen']}", file=sys.stderr)
        self.assertGreaterEqual(r["writers_matched_after_s"], 0.0,
                                f"the recorder identity's readers had no matched writer on every topic within "
                                f"{SECURE_MATCH_TIMEOUT_S} s, with {SECURE_MATCH_ATTEMPTS} new participants "
                                f"(secure handshake not finished): {r}")
        handshake_s = r["writers_matched_after_s"]
        for topic in ("SensorData", "JointCommand"):
            self.assertGreater(r["listen"][topic]["received"], 1000, r)
        # Every SensorData the simulator wrote in the window reached the permitted reader. JointCommand is not
        # held to every tick: it exists only for the ticks the chain answered in time, and a secured chain uses
        # about 70 % of its core (docs/guide/security.md); in a busy-core series its core once stalled for 57 ms
        # (RT throttling) and the WBC answered 2,429 of 3,066 ticks while all 3,006 SensorData arrived.
        t = r["listen"]["SensorData"]
        self.assertGreaterEqual(t["received"], 0.95 * (t["last_tick"] - t["first_tick"] + 1), r)
        # (4) A valid identity without permission for JointCommand (the operator tool's) is refused at
        # writer creation, and may not read SensorData either.
        code, r = self.inject("--domain", domain, "--secure", self.sec, "--identity", "cmd", "--publish", "JointCommand",
                              "--value", "40", "--seconds", 0.5, "--wait-match", 0)
        self.assertEqual(code, 4, r)
        self.assertEqual(r["participant"], "created")
        self.assertEqual(r["writer"], "refused", r)
        self.assertEqual(r["written"], 0)
        code, r = self.inject("--domain", domain, "--secure", self.sec, "--identity", "cmd", "--listen", "SensorData",
                              "--seconds", 0.5)
        self.assertEqual(code, 4, r)
        self.assertIn("reader refused on SensorData", r["participant"])
        # (5) Without an identity, 3 s of JointCommand at 1 kHz with 40 N m on every joint (beyond what the
        # WBC commands at stance, within the actuators' peak): the simulator never receives one.
        code, r = self.inject("--domain", domain, "--publish", "JointCommand", "--value", "40", "--rate", 1000,
                              "--seconds", 3, "--wait-match", 0)
        self.assertEqual(code, 0, r)
        self.assertGreater(r["written"], 2000, r)
        self.assertEqual(r["matched_readers"], 0, r)
        s = self.down(domain, st)
        sim, wbc = s["mft-sim"], s["mft-wbc"]
        # Every command the simulator received came from the WBC (one per tick it answered, at most): none of the
        # stranger's (whose writer matched no reader, above). Whether the robot then stands is not asserted: that
        # is the secured chain's speed, not access control. A secured chain rides DDS over UDP and takes about
        # 70 % of its core; with both cores loaded by busy loops it once ended 4.4 cm low, and beside a push sweep
        # (load 10) it fell (docs/guide/security.md). The plain test below shows the check has teeth.
        self.assertLessEqual(sim["commands_received"], wbc["ticks"], (sim["commands_received"], wbc["ticks"]))
        self.assertGreater(sim["commands_received"], 5000)
        self.assertEqual(sum(sim["commands_rejected"].values()), 0)
        print(f"\nsecured stack: stranger listened 0 samples, stranger wrote {r['written']} JointCommands, sim received "
              f"{sim['commands_received']} commands for {wbc['ticks']} WBC ticks, final base height "
              f"{sim['final_base_height_m']:.4f} m; the recorder identity matched after {handshake_s:.2f} s "
              f"(participant {attempt})", file=sys.stderr)

    def test_plain_stack_would_take_the_strangers_commands(self):
        # The same stranger on a stack without --secure: its commands do reach the simulator. This is what
        # the secured test above rules out, and shows that the test would see an effect.
        domain = DOMAIN + 1
        st = self.up(domain, "stand.yaml")
        SimLog(Path(st["run_dir"]) / "mft-sim.log").wait_for_sim_time(1.0)
        code, r = self.inject("--domain", domain, "--publish", "JointCommand", "--value", "40", "--rate", 1000,
                              "--seconds", 1, "--wait-match", 5)
        self.assertGreater(r["matched_readers"], 0, r)
        s = self.down(domain, st)
        sim, wbc = s["mft-sim"], s["mft-wbc"]
        self.assertGreater(sim["commands_received"] - wbc["ticks"], 500, (sim["commands_received"], wbc["ticks"]))

    def test_secured_stack_steps_in_place_in_lockstep(self):
        run_dir = self.tmp / "run-lockstep"
        code, out, err = self.stacks.supervisor("run", SCENARIOS / "step-in-place.yaml", "--domain", DOMAIN + 2, "--secure", self.sec,
                                  "--json", "--run-dir", run_dir)
        self.assertEqual(code, 0, err[-3000:] + "".join(  # every service's last lines: which hop stopped answering
            f"\n{name}.log:\n" + SimLog(run_dir / f"{name}.log").text()[-1500:]
            for name in ("mft-sim", "mft-estimator", "mft-planner", "mft-wbc") if (run_dir / f"{name}.log").exists()))
        s = json.loads(out)
        self.assertTrue(s["secure"])
        self.assertFalse(s["fell"], s["services"]["mft-sim"].get("fall_reason"))
        self.assertEqual(s["ticks"], 10000)
        for name in ("mft-estimator", "mft-planner", "mft-wbc"):
            self.assertEqual(s["services"][name]["ticks"], 10000, name)
        self.assertGreater(s["services"]["mft-sim"]["touchdowns"][0], 5)
        self.assertLess(abs(s["services"]["mft-sim"]["average_speed_mps"]), 0.05)
        print(f"\nsecured lockstep step-in-place 10 s: wall {s['wall_time_s']} s", file=sys.stderr)

    def test_bad_security_directory_is_refused_before_anything_starts(self):
        code, out, err = self.stacks.supervisor("run", SCENARIOS / "stand.yaml", "--domain", DOMAIN + 3, "--secure", self.tmp / "nope")
        self.assertEqual(code, 2)
        self.assertIn("is not a directory", err)
        partial = self.tmp / "partial"
        shutil.copytree(self.sec, partial)
        (partial / "permissions_wbc.p7s").unlink()
        code, out, err = self.stacks.supervisor("run", SCENARIOS / "stand.yaml", "--domain", DOMAIN + 3, "--secure", partial)
        self.assertEqual(code, 2)
        self.assertIn("permissions_wbc.p7s", err)
        # A service given another CA's identity with this CA's governance cannot even create its participant.
        mixed = self.tmp / "mixed"
        shutil.copytree(self.sec, mixed)
        shutil.copy(self.rogue / "wbc.pem", mixed / "wbc.pem")
        shutil.copy(self.rogue / "wbc.key", mixed / "wbc.key")
        code, out, err = self.stacks.supervisor("run", SCENARIOS / "stand.yaml", "--domain", DOMAIN + 3, "--secure", mixed, timeout=120)
        self.assertNotEqual(code, 0)
        self.assertIn("mft-wbc", err)

    def test_make_security_refuses_the_repository(self):
        p = subprocess.run(["bash", str(MAKE), str(REPO / "secure-test-should-not-exist")], capture_output=True, text=True)
        self.assertEqual(p.returncode, 2)
        self.assertIn("inside the repository", p.stderr)
        self.assertFalse((REPO / "secure-test-should-not-exist").exists())
        keys = sorted(self.sec.glob("*.key"))
        self.assertEqual([k.stem for k in keys], sorted(["sim", "estimator", "planner", "wbc", "record", "cmd", "ca"]))
        for k in keys:
            self.assertEqual(k.stat().st_mode & 0o077, 0, k)  # private keys readable by the owner only


if __name__ == "__main__":
    reserve_cpu_share()  # a share of the CPU whatever else runs (python/mftstack/simlog.py)
    unittest.main(verbosity=2)
