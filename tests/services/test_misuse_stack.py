#!/usr/bin/env python3
"""Bad input and misuse with the real executables (issue 16; docs/results/faults.md "Bad input and misuse"): a busy DDS
domain seen by mft-participants, a broken configuration file refused by the services' --check-config before
anything starts, mft-record refusing to replace a recording, files that are not UTF-8. The supervisor's own
handling of the same cases is tested against fake services in test_supervisor.py. Needs MFT_BIN_DIR (set by
CTest); run it in a network namespace of its own (README: unshare -n)."""
import json
import os
import shutil
import signal
import subprocess
import sys
import time
import unittest
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "python"))
from mftstack.simlog import fifo_priority  # noqa: E402
from mftstack.testing import BIN, CONFIG, SCENARIOS, StackRunner, StackTestCase  # noqa: E402

DOMAIN_BASE = 140 + (os.getpid() % 20) * 3  # a block of its own, apart from the integration tests' 100-219


class MisuseStackTest(StackTestCase):
    tmp_prefix = "mft-misuse-test-"

    def setUp(self):
        super().setUp()
        self.env = self.stacks.env
        self.up_domains = []  # (domain, env) of background stacks to take down whatever happens

    def tearDown(self):
        for domain, env in self.up_domains:
            subprocess.run(self.stacks.command("down", "--domain", domain), env=env, capture_output=True, timeout=60)

    def sup(self, *args, env=None, timeout=240):
        return subprocess.run(self.stacks.command(*args), env=env or self.env, capture_output=True, text=True,
                              timeout=timeout)

    def run_dirs(self, runs=None):
        runs = Path(runs or self.tmp / "runs")
        return [d for d in runs.iterdir() if d.is_dir()] if runs.exists() else []

    def test_a_domain_in_use_by_a_running_stack_is_refused(self):
        domain = DOMAIN_BASE
        # A realtime stack started by another user (another runs folder: no state file of ours names it).
        other_env = dict(os.environ, MFT_RUNS_DIR=str(self.tmp / "other-runs"))
        r = self.sup("up", SCENARIOS / "stand.yaml", "--domain", domain, "--mode", "realtime", "--no-rt", env=other_env)
        self.up_domains.append((domain, other_env))
        self.assertEqual(r.returncode, 0, r.stderr)
        before = json.loads(self.sup("status", "--domain", domain, "--json", env=other_env).stdout)
        for command in ("run", "up"):
            t0 = time.monotonic()
            r = self.sup(command, SCENARIOS / "stand.yaml", "--domain", domain, "--mode", "realtime")
            took = time.monotonic() - t0
            self.assertEqual(r.returncode, 2, (command, r.stderr))
            self.assertIn(f"domain {domain} is in use:", r.stderr)
            # Within the 1 s bound at least one of the stack's services answers (under load not always all four).
            self.assertTrue(any(f"{n} at 127.0.0.1" in r.stderr for n in ("mft-sim", "mft-estimator", "mft-planner",
                                                                            "mft-wbc")), r.stderr)
            self.assertNotIn("Traceback", r.stderr)
            self.assertEqual(self.run_dirs(), [], f"{command} created a run folder")
            print(f"\n{command} on a busy domain refused in {took:.2f} s", file=sys.stderr)
        after = json.loads(self.sup("status", "--domain", domain, "--json", env=other_env).stdout)
        self.assertEqual(before["services"], after["services"])  # the running stack was not disturbed
        self.assertTrue(all(s["alive"] for s in after["services"].values()), after)

    def test_kill_9_of_the_supervisor_closes_the_recording_and_the_next_start_removes_the_segment(self):
        # The recorder gets SIGTERM when its supervisor dies (the other services SIGKILL): the sidecar said
        # "status: recording" for good. The chain segment of a realtime stack outlived it: the next start removes it.
        domain = DOMAIN_BASE + 1
        rawlog = self.tmp / "killed.rawlog"
        r = self.sup("up", SCENARIOS / "stand.yaml", "--domain", domain, "--mode", "realtime", "--no-rt",
                     "--record", rawlog)
        self.up_domains.append((domain, self.env))
        self.assertEqual(r.returncode, 0, r.stderr)
        st = json.loads(self.sup("status", "--domain", domain, "--json").stdout)
        segments = [n for n in os.listdir("/dev/shm") if n.startswith(f"mft-chain-d{domain}-{st['supervisor_pid']}-")]
        self.assertEqual(len(segments), 1, os.listdir("/dev/shm"))
        time.sleep(1.0)
        os.kill(st["supervisor_pid"], signal.SIGKILL)
        sidecar = Path(str(rawlog) + ".yaml")
        deadline = time.monotonic() + 20
        while time.monotonic() < deadline and "status: complete" not in (sidecar.read_text() if sidecar.exists() else ""):
            time.sleep(0.1)
        recording_section = sidecar.read_text().rsplit("\nrecording:\n", 1)[-1]  # the section is last
        self.assertIn("  status: complete", recording_section)
        # Nobody is left to remove the segment until the next start: this one below, or any other supervisor's on
        # the machine, since /dev/shm is shared (beside a push sweep or a Dask study, their next stack removed it
        # before this test could even look, so whether it is still there now is not this test's to assert).
        r = self.sup("run", SCENARIOS / "stand.yaml", "--domain", domain + 1, "--run-dir", self.tmp / "next")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertFalse((Path("/dev/shm") / segments[0]).exists(), r.stderr)

    def test_the_chain_channel_refuses_secure_and_bad_names_and_leaves_nothing_in_dev_shm(self):
        base = [str(BIN / "mft-estimator"), "--domain", str(DOMAIN_BASE + 2), "--scenario", str(SCENARIOS / "stand.yaml")]
        for extra, message in ((["--chain-shm", "/mft-chain-x", "--secure", str(self.tmp)], "not with --secure"),
                               (["--chain-shm", "no-leading-slash"], "expected a name like /mft-chain-NAME")):
            r = subprocess.run(base + extra, capture_output=True, text=True, timeout=60)
            self.assertEqual(r.returncode, 2, (extra, r.stdout, r.stderr))
            self.assertIn(message, r.stderr)
        self.assertFalse(Path("/dev/shm/mft-chain-x").exists())
        # Only this stack's domain: /dev/shm is shared, and another test's stack may start meanwhile.
        mine = f"mft-chain-d{DOMAIN_BASE + 2}-*"
        before = {p.name for p in Path("/dev/shm").glob(mine)}
        code, summary, err = self.stacks.run_json("stand.yaml", DOMAIN_BASE + 2, timeout=240)
        self.assertEqual(code, 0, err[-2000:])
        self.assertEqual(summary["chain_transport"], "shm")
        self.assertGreater(summary["ticks"], 0)
        self.assertEqual({p.name for p in Path("/dev/shm").glob(mine)} - before, set(),
                         "the stack left its chain segment behind")
        # A stack whose simulator never attached (it exits at once after passing its configuration check): the
        # other three opened the segment; the supervisor removes it.
        bin_dir = self.tmp / "bin-sim-fails"
        bin_dir.mkdir()
        for exe in BIN.iterdir():
            (bin_dir / exe.name).symlink_to(exe)
        (bin_dir / "mft-sim").unlink()
        (bin_dir / "mft-sim").write_text(f'#!/bin/sh\ncase "$*" in *--check*) exec {BIN / "mft-sim"} "$@";; esac\n'
                                         'echo "mft-sim: failing on purpose" >&2; exit 3\n')
        (bin_dir / "mft-sim").chmod(0o755)
        failing = StackRunner(prefix="mft-misuse-sim-fails-", bin_dir=bin_dir)
        self.addCleanup(failing.close)
        code, summary, err = failing.run_json("stand.yaml", DOMAIN_BASE + 2, timeout=240)
        self.assertNotEqual(code, 0)
        self.assertIn("mft-sim", summary["error"])
        self.assertEqual({p.name for p in Path("/dev/shm").glob(mine)} - before, set())  # its own domain only

    def test_mft_participants_lists_what_is_on_a_domain(self):
        domain = DOMAIN_BASE + 1
        probe = [str(BIN / "mft-participants"), "--domain", str(domain), "--json", "--wait-ms", "2000"]
        r = subprocess.run(probe, capture_output=True, text=True, timeout=30)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(json.loads(r.stdout)["participants"], [])
        # One participant held on the domain: a second probe listening for 3 s.
        holder = subprocess.Popen(probe[:-1] + ["8000"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        try:
            time.sleep(2.0)  # its participant exists (creating one took up to ~1 s on the loaded VM)
            r = subprocess.run(probe, capture_output=True, text=True, timeout=30)
        finally:
            holder.wait(timeout=30)
        seen = json.loads(r.stdout)["participants"]
        self.assertEqual([p["name"] for p in seen], ["mft-participants"])
        self.assertEqual(seen[0]["addresses"], ["127.0.0.1"])
        self.assertLess(seen[0]["discovered_ms"], 2000)
        r = subprocess.run(probe[:2] + ["233"], capture_output=True, text=True, timeout=30)
        self.assertEqual(r.returncode, 2)
        self.assertIn("--domain: 233 is outside [0, 232]", r.stderr)

    def broken_config(self, file, edit):
        cfg = self.tmp / f"config-{file}"
        shutil.copytree(CONFIG, cfg)
        path = cfg / file
        path.write_text(edit(path.read_text()))
        return cfg

    def test_every_configuration_file_is_checked_before_anything_starts(self):
        add_key = lambda text: text + "\nbogus_key_16: 1\n"
        cases = [("wbc.yaml", add_key, "bogus_key_16"), ("planner.yaml", add_key, "bogus_key_16"),
                 ("estimator.yaml", add_key, "bogus_key_16"), ("mft_space.yaml", add_key, "bogus_key_16"),
                 ("dds_profiles.xml", lambda t: t.replace("<useBuiltinTransports>", "<bogusElement16/><useBuiltinTransports>", 1),
                  "bogusElement16")]
        for file, edit, key in cases:
            cfg = self.broken_config(file, edit)
            r = self.sup("run", SCENARIOS / "stand.yaml", "--domain", DOMAIN_BASE + 2, "--config-dir", cfg)
            self.assertEqual(r.returncode, 2, (file, r.stderr))
            # planner.yaml is also read by the scenario check (the height window), which comes first: either
            # refusal is before anything starts (no run folder, below), naming the file and the key.
            if file != "planner.yaml":
                self.assertIn("configuration refused before anything started", r.stderr, file)
            self.assertIn(f"{cfg / file}", r.stderr, file)
            self.assertIn(key, r.stderr, file)
            self.assertNotIn("Traceback", r.stderr)
            self.assertEqual(self.run_dirs(), [], f"{file}: a run folder was made: something started")
        # The intact configuration passes every service's check.
        for name in ("mft-sim", "mft-estimator", "mft-planner", "mft-wbc"):
            r = subprocess.run([str(BIN / name), "--check-config", "--domain", "0", "--scenario",
                                str(SCENARIOS / "stand.yaml")], capture_output=True, text=True, timeout=30)
            self.assertEqual((r.returncode, r.stdout.strip()), (0, f"{name}: configuration ok"), r.stderr)

    @unittest.skipUnless((BIN / "mft-record").exists(), "mft-record not built")
    def test_mft_record_never_replaces_a_recording_silently(self):
        out = self.tmp / "old.rawlog"
        out.write_bytes(b"an earlier recording")
        base = [str(BIN / "mft-record"), "--domain", str(DOMAIN_BASE + 2), "--scenario", str(SCENARIOS / "stand.yaml"),
                "--output", str(out)]
        r = subprocess.run(base, capture_output=True, text=True, timeout=30)
        self.assertEqual(r.returncode, 2, r.stderr)
        self.assertIn(f"{out} already exists: refusing to replace a recording (--overwrite replaces it)", r.stderr)
        self.assertEqual(out.read_bytes(), b"an earlier recording")
        r = subprocess.run(base + ["--overwrite", "--check-config"], capture_output=True, text=True, timeout=30)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(out.read_bytes(), b"an earlier recording")  # a check changes nothing

    def test_files_that_are_not_utf8_give_one_line(self):
        scenario = self.tmp / "latin1.yaml"
        scenario.write_bytes((SCENARIOS / "stand.yaml").read_bytes().replace(b"name:", b"bogus_caf\xe9: 1\nname:", 1))
        r = self.sup("run", scenario, "--domain", DOMAIN_BASE + 2)
        self.assertNotIn("Traceback", r.stderr)
        self.assertNotIn("UnicodeDecodeError", r.stderr)
        robot_cfg = self.broken_config("robot.yaml", lambda t: t)
        (robot_cfg / "robot.yaml").write_bytes(b"\xff\xfe\xfa" + (CONFIG / "robot.yaml").read_bytes())
        r2 = self.sup("run", SCENARIOS / "stand.yaml", "--domain", DOMAIN_BASE + 2, "--config-dir", robot_cfg)
        self.assertNotIn("Traceback", r2.stderr)
        self.assertNotIn("UnicodeDecodeError", r2.stderr)
        for res in (r, r2):
            self.assertEqual(res.returncode, 2, res.stderr)
            self.assertEqual(len([l for l in res.stderr.splitlines() if l.startswith("mft-supervisor: error")]), 1,
                             res.stderr)

    def test_ctrl_c_right_at_spawn_stops_the_real_stack_promptly(self):
        p = subprocess.Popen(self.stacks.command("run", SCENARIOS / "stand.yaml", "--domain", DOMAIN_BASE + 2,
                                                 "--run-dir", self.tmp / "run"),
                             env=self.env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                             start_new_session=True)
        try:
            # The services are ready ~80 ms after the first one is spawned: the watch runs at SCHED_FIFO 85 so that
            # a loaded machine cannot delay the Ctrl-C past that (it did once at load ~5, polling at normal priority).
            with fifo_priority():
                deadline = time.time() + 60
                while not (self.tmp / "run" / "mft-estimator.log").exists() and time.time() < deadline:
                    time.sleep(0.001)
                spawned = (self.tmp / "run" / "mft-estimator.log").exists()
                t0 = time.monotonic()
                if spawned:
                    os.killpg(p.pid, signal.SIGINT)  # a terminal's Ctrl-C: the whole foreground process group
            self.assertTrue(spawned, "no service started within 60 s")
            out, err = p.communicate(timeout=30)
            took = time.monotonic() - t0
        finally:
            if p.poll() is None:
                os.killpg(p.pid, signal.SIGKILL)
                p.wait()
        self.assertEqual(p.returncode, 130, err)
        self.assertIn("interrupted", err)
        self.assertNotIn("running stand", err)
        self.assertNotIn("Traceback", err)
        self.assertLess(took, 1.5, f"the supervisor took {took:.2f} s to stop after Ctrl-C")
        print(f"\nCtrl-C at spawn (real services): supervisor ended {took:.2f} s after SIGINT", file=sys.stderr)


if __name__ == "__main__":
    unittest.main(verbosity=2)
