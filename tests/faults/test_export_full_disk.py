#!/usr/bin/env python3
"""mft-export --csv onto a full disk: the error names the folder and the cut files, and removes them (it left
CSV files cut mid-number that looked like a short run). The disk is a 16 kB tmpfs in a mount namespace of its
own (unshare -m; root only, skipped otherwise); the recording is the small fixture tests/data/rawlog/schema1.rawlog.
Needs MFT_BIN_DIR (set by CTest)."""
import os
import shutil
import subprocess
import tempfile
import unittest
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
EXPORT = Path(os.environ.get("MFT_BIN_DIR", ROOT / "build" / "release" / "bin")) / "mft-export"
FIXTURE = ROOT / "tests" / "data" / "rawlog" / "schema1.rawlog"


@unittest.skipUnless(os.geteuid() == 0 and shutil.which("unshare"), "needs root and unshare for a small tmpfs")
class ExportFullDisk(unittest.TestCase):
    def test_cut_csv_files_are_named_and_removed(self):
        out = Path(tempfile.mkdtemp(prefix="mft-export-full-"))
        self.addCleanup(shutil.rmtree, out)
        script = (f"mount -t tmpfs -o size=16k tmpfs {out} && {EXPORT} {FIXTURE} --csv {out / 'c'}; echo rc=$?; "
                  f"ls -A {out / 'c'}")
        r = subprocess.run(["unshare", "-m", "--propagation", "private", "sh", "-c", script], capture_output=True,
                           text=True, timeout=120)
        if "rc=" not in r.stdout:
            self.skipTest(f"cannot mount a tmpfs here: {r.stderr.strip()}")
        self.assertEqual(r.stdout.split()[-1], "rc=2", r.stdout + r.stderr)  # exit 2, and the folder is empty
        self.assertRegex(r.stderr, r"mft-export: writing the CSV files in .*/c failed \(disk full\?\): removed the "
                                   r"\d+ cut files \(.*gt_q\.csv.*\)")


if __name__ == "__main__":
    unittest.main()
