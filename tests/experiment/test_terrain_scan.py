#!/usr/bin/env python3
"""mft-experiment terrain-scan (in process, no stack): the course is really shifted by each offset, each run is
judged against its own shifted course, the table counts what the runs say, and bad arguments are one line."""
import csv
import json
import os
import subprocess
import sys
import tempfile
import unittest
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
BIN = Path(os.environ.get("MFT_BIN_DIR", REPO / "build" / "release" / "bin"))
TOOL = REPO / "tools" / "mft-experiment" / "mft-experiment"
BOARD = (1.0, 1.6)  # config/terrain/course.yaml: the board's x range, start_x_m 1.0
LAST_OBSTACLE_END = 7.6  # board 0.6 + flat 1 + slope 2 + flat 1 + rough 2 after x = 1.0 (then 1 m of flat)


def tool(*args, timeout=300):
    return subprocess.run([sys.executable, str(TOOL)] + list(args), capture_output=True, text=True, timeout=timeout)


class TerrainScanTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory(prefix="mft-terrain-scan-test-")
        cls.out = Path(cls.tmp.name) / "scan"
        cls.r = tool("terrain-scan", "--heights", "0.44", "--speeds", "0.25", "--controllers", "mft",
                     "--shift-span", "0.02", "--shift-step", "0.02", "--bin-dir", str(BIN), "--out", str(cls.out),
                     "--json", "--quiet", "--no-snapshot")

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def test_every_offset_runs_on_its_own_shifted_course(self):
        self.assertEqual(self.r.returncode, 0, self.r.stderr[-2000:])
        report = json.loads(self.r.stdout)
        self.assertEqual(report["offsets_m"], [-0.02, 0.0, 0.02])
        self.assertEqual(report["profiles"], ["kv-0.145"])
        for o in report["offsets_m"]:
            text = (self.out / "config-shifts" / f"shift{o:+.3f}" / "terrain" / "course.yaml").read_text()
            starts = [line for line in text.splitlines() if line.startswith("start_x_m:")]
            self.assertEqual(len(starts), 1)
            self.assertAlmostEqual(float(starts[0].split(":")[1]), BOARD[0] + o, places=9)
        self.assertEqual(len(report["runs"]), 3)
        for run in report["runs"]:
            o = run["offset_m"]
            # the verdicts from the run's own figures and the shifted course (0.3 m clearance past an obstacle)
            self.assertEqual(run["crossed_board"], run["max_base_x_m"] >= BOARD[1] + o + 0.3, run)
            self.assertEqual(run["traversed"], (not run["fell"]) and run["max_base_x_m"] >= LAST_OBSTACLE_END + o + 0.3, run)
            if run["traversed"]:
                self.assertTrue(run["crossed_board"])
            if run["fell"]:
                self.assertGreater(run["fall_time_s"], 2.0)  # walking starts at 2 s
                self.assertLess(run["max_base_x_m"], LAST_OBSTACLE_END + o + 0.3)

    def test_the_tables_count_what_the_runs_say(self):
        self.assertEqual(self.r.returncode, 0, self.r.stderr[-2000:])
        report = json.loads(self.r.stdout)
        (cell,) = report["cells"]
        runs = report["runs"]
        self.assertEqual(cell["runs"], 3)
        self.assertEqual(cell["crossed_board"], sum(bool(r["crossed_board"]) for r in runs))
        self.assertEqual(cell["traversed"], sum(r["traversed"] for r in runs))
        failed = [r for r in runs if not r["traversed"] and r["first_body_contact"]]
        self.assertEqual(sum(cell["failed_first_body_contact"].values()), len(failed))
        with open(self.out / "terrain_scan.csv", newline="") as f:
            rows = list(csv.DictReader(f))
        self.assertEqual([float(r["offset_m"]) for r in rows], [r["offset_m"] for r in runs])
        md = (self.out / "terrain_scan.md").read_text()
        self.assertIn(f"| {cell['crossed_board']}/3 | {cell['traversed']}/3 |", md)
        self.assertGreater((self.out / "terrain_scan.png").stat().st_size, 1000)

    def test_the_docs_grid_counts_each_controller_and_height(self):
        sys.path.insert(0, str(REPO / "python"))
        from mftexp.terrain_scan import grid_lines

        def cell(h, c, crossed, traversed, z):
            return {"height_m": h, "speed_mps": 0.25, "controller": c, "runs": 3, "crossed_board": crossed,
                    "traversed": traversed, "walking_height_on_flat_m": z}
        report = {"terrain": "course", "profiles": ["kv-0.145"], "offsets_m": [-0.02, 0.0, 0.02],
                  "cells": [cell(0.44, "mft", 2, 1, 0.4251), cell(0.44, "sa", 3, 3, 0.4262),
                            cell(0.46, "mft", 0, 0, None), cell(0.46, "sa", 1, 0, 0.443)]}
        report["cells"][0]["failed_first_body_contact"] = {"left fore shank": 2}
        report["cells"][2]["failed_first_body_contact"] = {"left fore shank": 1, "right rear shank": 1}
        lines = grid_lines(report)
        self.assertIn("- course, course shifted by 3 offsets (-2 ... +2 cm), 3 runs per cell; profiles: kv-0.145",
                      lines)
        self.assertEqual(lines[-4:-2], ["| 0.44 (0.425–0.426) | 2 / 3 (1 / 3) |", "| 0.46 (0.443, fell) | 0 / 1 (0 / 0) |"])
        self.assertEqual(lines[-1], "- of the 8 runs that did not traverse, the first body other than a foot to touch "
                                    "the ground: left fore shank 3, right rear shank 1; no such contact in 4")

    def test_the_walking_height_shows_the_contact_weights_sag(self):
        # Table I's w_fc = 1e-3 holds the base below its command by w_fc m^2 g / (n_st w_z kp): 13.0 mm predicted in
        # single support (docs/guide/profiles.md, contact-weights-small; 15 mm measured stepping in place).
        self.assertEqual(self.r.returncode, 0, self.r.stderr[-2000:])
        (cell,) = json.loads(self.r.stdout)["cells"]
        sag = 0.44 - cell["walking_height_on_flat_m"]
        self.assertGreater(sag, 0.008)
        self.assertLess(sag, 0.022)

    def test_sigterm_stops_the_runs_in_flight(self):
        out = Path(self.tmp.name) / "stopped"
        p = subprocess.Popen([sys.executable, str(TOOL), "terrain-scan", "--bin-dir", str(BIN), "--out", str(out),
                              "--no-snapshot"], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
        try:
            for line in p.stderr:  # the first finished run's progress line: runs are in flight now
                if "runs/min]" in line:
                    break
            p.terminate()
            _, err = p.communicate(timeout=30)
        finally:
            if p.poll() is None:
                p.kill()
                p.wait()
        self.assertEqual(p.returncode, 130, err)
        self.assertIn("interrupted", err)
        self.assertNotIn("Traceback", err)
        left = subprocess.run(["pgrep", "-f", str(out)], capture_output=True, text=True).stdout.split()
        self.assertEqual(left, [], "mft-closedloop runs of the stopped scan are still running")
        self.assertFalse((out / "terrain_scan.md").exists())

    def test_bad_arguments_are_one_line(self):
        for args, expect in ((["--shift-step", "0"], "--shift-step"), (["--shift-step", "0.2"], "--shift-step"),
                             (["--speeds", "0.9"], "outside"), (["--terrain", "nowhere"], "does not exist"),
                             (["--shift-span", "5", "--shift-step", "0.001"], "at most 401")):
            r = tool("terrain-scan", "--bin-dir", str(BIN), "--out", str(Path(self.tmp.name) / "bad"), "--no-snapshot",
                     *args, timeout=60)
            self.assertEqual(r.returncode, 2, (args, r.stderr))
            self.assertIn(expect, r.stderr, args)
            self.assertNotIn("Traceback", r.stderr)


if __name__ == "__main__":
    unittest.main()
