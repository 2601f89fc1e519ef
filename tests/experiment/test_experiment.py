#!/usr/bin/env python3
"""mft-experiment push-sweep on real lockstep stacks, reduced (issue 9): one height (0.44 m), both controllers,
1 N s steps. Checks the table's shape (table.csv, table.md), that every cell's boundary is bracketed by a
recovered and a failed run of results.jsonl one grid step apart, that the kept rawlogs exist and reproduced their
runs; that an interrupted sweep (SIGINT) leaves no process behind and resumes to the same table without
re-running a finished run; and clear one-line errors on bad arguments. DDS domains 94-97 (90-99: besides only
operator_commands 90-93 and live_tuning 98-99; the integration tests take 100-219)."""
import csv
import json
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import unittest
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "python"))
from mftstack.simlog import reserve_cpu_share  # noqa: E402
from mftstack.testing import BIN, REPO, processes_mentioning  # noqa: E402

TOOL = REPO / "tools" / "mft-experiment" / "mft-experiment"
HEIGHT = "0.44"
SWEEP = ["push-sweep", "--heights", HEIGHT, "--step", "1.0", "--max-impulse", "20", "--bin-dir", str(BIN)]


def tool(*args, timeout=600):
    return subprocess.run([sys.executable, str(TOOL)] + [str(a) for a in args], capture_output=True, text=True,
                          timeout=timeout)


def lines(path):
    return [json.loads(l) for l in Path(path).read_text().splitlines() if l.strip()]



class ExperimentTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = Path(tempfile.mkdtemp(prefix="mft-experiment-test-"))
        cls.full = cls.tmp / "full"
        t0 = time.monotonic()
        cls.res = tool(*SWEEP, "--out", cls.full, "--domain-base", 94, "--json")
        cls.wall = time.monotonic() - t0
        print(f"reduced sweep: {cls.wall:.1f} s", file=sys.stderr)

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def test_1_table_shape_and_brackets(self):
        self.assertEqual(self.res.returncode, 0, self.res.stderr[-2000:])
        summary = json.loads(self.res.stdout)
        self.assertIn("left", self.res.stderr)  # progress lines with the time left
        with open(self.full / "table.csv") as f:
            rows = list(csv.DictReader(f))
        self.assertEqual(len(rows), 1)
        self.assertEqual(rows[0]["height_m"], HEIGHT)
        for col in ("sa_imax_Ns", "mft_imax_Ns", "increase_pct", "paper_sa_imax_Ns", "paper_mft_imax_Ns"):
            self.assertIn(col, rows[0])
        md = (self.full / "table.md").read_text()
        for row in ("I_max of SA-WBC", "I_max of MFT-WBC", "Percentage of increase"):
            self.assertIn(row, md)
        self.assertTrue((self.full / "push_sweep.png").stat().st_size > 1000)
        recs = lines(self.full / "results.jsonl")
        self.assertEqual(recs[0]["kind"], "sweep")
        runs = {(r["controller"], round(r["impulse_Ns"], 3)): r for r in recs if r["kind"] == "run"}
        cells = [r for r in recs if r["kind"] == "cell"]
        self.assertEqual(sorted(c["controller"] for c in cells), ["mft", "sa"])
        for c in cells:
            self.assertEqual(c["status"], "ok", c)
            lo, hi = c["recovered_Ns"], c["failed_Ns"]
            self.assertAlmostEqual(hi - lo, 1.0, places=6)
            self.assertTrue(runs[(c["controller"], round(lo, 3))]["recovered"], c)
            self.assertFalse(runs[(c["controller"], round(hi, 3))]["recovered"], c)
            self.assertEqual(c["i_max_Ns"], lo)
            csv_val = float(rows[0][f"{c['controller']}_imax_Ns"])
            self.assertAlmostEqual(csv_val, lo, places=6)
            # kept rawlogs of both boundary runs, re-run with identical outcomes (lockstep determinism)
            self.assertEqual(set(c["rawlogs"]), {"recovered", "failed"})
            for p in c["rawlogs"].values():
                self.assertTrue(Path(p).stat().st_size > 10000, p)
            self.assertTrue(c["deterministic"], c)
        self.assertEqual(len(summary["table"]), 1)
        self.assertEqual(processes_mentioning(str(self.tmp)), [])

    def test_2_interrupt_and_resume(self):
        out = self.tmp / "resume"
        args = SWEEP + ["--out", str(out), "--domain-base", "96", "--no-rawlogs"]
        p = subprocess.Popen([sys.executable, str(TOOL)] + args, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                             text=True)
        results = out / "results.jsonl"
        deadline = time.monotonic() + 120
        while True:
            if results.exists() and sum(1 for r in lines(results) if r["kind"] == "run") >= 4:
                break
            if time.monotonic() > deadline or p.poll() is not None:
                p.kill()
                self.fail(f"the sweep did not finish 4 runs within 120 s (exit {p.poll()})")
            time.sleep(0.2)
        p.send_signal(signal.SIGINT)
        _, err = p.communicate(timeout=60)
        self.assertEqual(p.returncode, 130, err[-2000:])
        self.assertIn("interrupted", err)
        self.assertNotIn("Traceback", err)
        deadline = time.monotonic() + 10  # no stack left behind: its processes are gone within a bound
        while processes_mentioning(str(out)) and time.monotonic() < deadline:
            time.sleep(0.1)
        self.assertEqual(processes_mentioning(str(out)), [])
        before = [r for r in lines(results) if r["kind"] == "run"]
        self.assertGreaterEqual(len(before), 4)
        res = tool(*args, "--json")
        self.assertEqual(res.returncode, 0, res.stderr[-2000:])
        self.assertIn("resuming", res.stderr)
        summary = json.loads(res.stdout)
        after = [r for r in lines(results) if r["kind"] == "run"]
        keys = [(r["controller"], round(r["impulse_Ns"], 3)) for r in after]
        self.assertEqual(len(keys), len(set(keys)), "a finished run was run again")
        self.assertEqual(summary["new_runs"], len(after) - len(before))
        # the same table as the uninterrupted sweep
        with open(out / "table.csv") as f1, open(self.full / "table.csv") as f2:
            self.assertEqual(f1.read(), f2.read())

    def test_4_ablation_smoke(self):
        """The ablation on a tiny grid (in process: mft-closedloop): the table's structure, and that toggling a
        profile changes what the runs were made with (the profile reaches the loop, and the loop says so)."""
        profiles = sorted(p.stem for p in (REPO / "config" / "profiles").glob("*.yaml"))
        self.assertTrue(profiles, "no configuration profile in config/profiles")
        toggle = profiles[0]
        out = self.tmp / "ablation"
        t0 = time.monotonic()
        r = tool("ablation", "--heights", HEIGHT, "--toggles", f"{toggle},rule-no-fall", "--step", "2", "--coarse", "4",
                 "--max-impulse", "15", "--values", "1e3", "--inprocess", "--bin-dir", BIN, "--out", out, "--json")
        print(f"ablation smoke: {time.monotonic() - t0:.1f} s", file=sys.stderr)
        self.assertEqual(r.returncode, 0, r.stderr[-2000:])
        self.assertIn("left", r.stderr)
        report = json.loads(r.stdout)
        self.assertEqual([row["variant"] for row in report["rows"]], ["defaults", toggle, "rule-no-fall"])
        for row in report["rows"]:
            cell = row["heights"][HEIGHT]
            for c in ("sa", "mft"):
                self.assertIsNotNone(cell[c], row)
                self.assertGreaterEqual(cell[c], 3.0)
                self.assertAlmostEqual((cell[c] - 3.0) / 2.0, round((cell[c] - 3.0) / 2.0), places=6)  # on the grid
            self.assertAlmostEqual(cell["ratio"], cell["mft"] / cell["sa"], places=2)
        with open(out / "ablation.csv") as f:
            rows = list(csv.reader(f))
        self.assertEqual(rows[0], ["variant", "profiles", "rule", f"sa_imax_Ns_{HEIGHT}", f"mft_imax_Ns_{HEIGHT}",
                                   f"mft_sa_ratio_{HEIGHT}"])
        self.assertEqual([r_[0] for r_ in rows[1:4]], ["defaults", toggle, "rule-no-fall"])
        self.assertEqual(rows[2][1], toggle)
        md = (out / "ablation.md").read_text()
        self.assertIn(f"| {toggle} |", md)
        self.assertIn("wbc.weights.slack", md)
        self.assertTrue((out / "ablation.png").stat().st_size > 1000)
        sens = report["sensitivity"]["rows"]
        self.assertEqual(len(sens), 1)
        self.assertTrue(0.30 < sens[0]["mft_stepping_height_m"] < 0.46, sens)
        runs = [l for l in lines(out / "results.jsonl") if l["kind"] == "run"]
        by_variant = {}
        for l in runs:
            by_variant.setdefault(l["variant"], []).append(l)
        self.assertEqual(set(by_variant), {"defaults", toggle, "rule-no-fall", "sens-slack-1e3"})
        for l in by_variant["defaults"] + by_variant["rule-no-fall"]:
            self.assertEqual(l["applied_profiles"], [])
        for l in by_variant[toggle]:
            self.assertEqual(l["applied_profiles"], [toggle])  # what the loop reports it ran with
        for l in by_variant["rule-no-fall"]:  # that variant's verdicts follow the other rule
            self.assertEqual(l["recovered"], l["no_fall"], l)
        self.assertEqual(processes_mentioning(str(out)), [])

    def test_3_clear_errors(self):
        cases = [
            (["push-sweep", "--heights", "0.9"], "outside"),
            (["push-sweep", "--step", "abc"], "not a number"),
            (["push-sweep", "--controllers", "pid"], "unknown controller"),
            (["case", "--impulse", "-3"], "positive"),
            (["push-sweep", "--bin-dir", str(self.tmp / "nope"), "--out", str(self.tmp / "x")], "does not exist"),
            (["terrain", "--terrain", "nope", "--bin-dir", str(BIN)], "does not exist"),
            (["push-sweep", "--heights", HEIGHT, "--step", "0.5", "--out", str(self.full), "--bin-dir", str(BIN)],
             "other settings"),
            (["bogus"], "invalid choice"),
            (["push-sweep", "--scheduler", "localhost", "--bin-dir", str(BIN)], "expected an address"),
            (["worker", "8786"], "expected an address"),
            (["worker", "tcp://127.0.0.1:8786", "--bin-dir", str(self.tmp / "nope")], "does not exist"),
        ]
        changed = self.tmp / "config-changed"  # resuming after a configuration change is refused
        shutil.copytree(REPO / "config", changed)
        with open(changed / "planner.yaml", "a") as f:
            f.write("# changed\n")
        cases.append((["push-sweep", "--heights", HEIGHT, "--step", "1.0", "--max-impulse", "20", "--out",
                       str(self.full), "--bin-dir", str(BIN), "--config-dir", str(changed)], "configuration"))
        notours = self.tmp / "notours"
        notours.mkdir()
        (notours / "results.jsonl").write_text("hello\n")
        cases.append((["push-sweep", "--out", str(notours), "--bin-dir", str(BIN)], "not a"))
        for argv, text in cases:
            r = tool(*argv, timeout=60)
            self.assertEqual(r.returncode, 2, f"{argv}: {r.returncode} {r.stderr}")
            self.assertIn(text, r.stderr, argv)
            self.assertNotIn("Traceback", r.stderr, argv)


if __name__ == "__main__":
    reserve_cpu_share()  # a share of the CPU whatever else runs (python/mftstack/simlog.py)
    unittest.main(verbosity=2)
