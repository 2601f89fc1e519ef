#!/usr/bin/env python3
"""mftstack.paths from the source tree: the repository's config/, build/release/bin, services/mft-supervisor and
runs/ (the installed layout is tested by test_install.py on a real install)."""
import os
import sys
import unittest
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "python"))
os.environ.pop("MFT_BIN_DIR", None)
os.environ.pop("MFT_RUNS_DIR", None)
from mftstack import paths  # noqa: E402


class SourceTreePaths(unittest.TestCase):
    def test_source_layout(self):
        self.assertFalse(paths.INSTALLED)
        self.assertIsNone(paths.PREFIX)
        self.assertEqual(paths.REPO, ROOT)
        self.assertEqual(paths.DEFAULT_CONFIG, ROOT / "config")
        self.assertTrue((paths.DEFAULT_CONFIG / "robot.yaml").is_file())
        self.assertEqual(paths.DEFAULT_BIN, ROOT / "build" / "release" / "bin")
        self.assertEqual(paths.SUPERVISOR, ROOT / "services" / "mft-supervisor")
        self.assertTrue(paths.SUPERVISOR.is_file())
        self.assertEqual(paths.DEFAULT_RUNS, ROOT / "runs")
        self.assertEqual(paths.SCENARIOS, ROOT / "config" / "scenarios")


if __name__ == "__main__":
    unittest.main()
