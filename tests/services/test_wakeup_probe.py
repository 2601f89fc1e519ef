#!/usr/bin/env python3
"""mft-wakeup, the machine's own wake-up latency (docs/loop-benchmark.md): every case reports as many wake-ups as
asked, with ordered, positive figures; the probe keeps its period (the wall time says so); bad options are one
line and exit 2. Needs MFT_BIN_DIR (set by CTest)."""
import json
import os
import subprocess
import sys
import time
import unittest
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "python"))
from mftstack.testing import BIN  # noqa: E402

PROBE = BIN / "mft-wakeup"
CPUS = os.cpu_count()


class WakeupProbe(unittest.TestCase):
    def test_every_case_reports_ordered_figures_at_its_period(self):
        samples, period_us = 300, 500
        t0 = time.monotonic()
        p = subprocess.run([str(PROBE), "--samples", str(samples), "--period-us", str(period_us), "--json"],
                           capture_output=True, text=True, timeout=120)
        wall = time.monotonic() - t0
        self.assertEqual(p.returncode, 0, p.stderr)
        r = json.loads(p.stdout)
        kinds = [(c["kind"], c["from_cpu"], c["to_cpu"]) for c in r["cases"]]
        pairs = [0, 1] if CPUS > 1 else [0]
        expected = [("timer", -1, c) for c in range(CPUS)] + [(k, 0, to) for k in ("futex", "udp") for to in pairs]
        self.assertEqual(kinds, expected)
        for c in r["cases"]:
            lat = c["latency_us"]
            self.assertNotIn("error", c)
            self.assertEqual(lat["count"], samples, c)
            # A wake-up takes time (p50 > 0: a clock or stamp mix-up would give 0 or less) and the order holds.
            self.assertGreater(lat["p50"], 0.0, c)
            self.assertLessEqual(lat["p50"], lat["p99"], c)
            self.assertLessEqual(lat["p99"], lat["max"], c)
            self.assertLessEqual(lat["mean"], lat["max"], c)
            self.assertLess(lat["max"], 1e6, c)  # no wake-up took a second
        # One wake-up per period: the run cannot be shorter than cases x samples x period.
        self.assertGreaterEqual(wall, len(expected) * samples * period_us * 1e-6, "the probe did not keep its period")
        self.assertIn("case 1 of", p.stderr)  # progress on stderr

    def test_bad_options_are_one_line_and_exit_2(self):
        for args in (["--samples", "0"], ["--period-us", "abc"], ["--cpus", str(CPUS + 1)], ["--bogus"]):
            p = subprocess.run([str(PROBE)] + args, capture_output=True, text=True, timeout=30)
            self.assertEqual(p.returncode, 2, (args, p.stderr))
            self.assertEqual(p.stdout, "", args)
            self.assertTrue(p.stderr.startswith("mft-wakeup:"), (args, p.stderr))


if __name__ == "__main__":
    unittest.main(verbosity=2)
