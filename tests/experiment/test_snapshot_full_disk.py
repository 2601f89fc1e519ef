#!/usr/bin/env python3
"""mft-experiment's snapshot of the executables (mftexp.common.snapshot_binaries) onto a full disk: the error
names the folder written (it named the executable read) and the partial copy (bin.tmp) is removed. The disk is
a 256 kB tmpfs in a mount namespace of its own (unshare -m; root only, skipped otherwise)."""
import os
import shutil
import subprocess
import sys
import tempfile
import textwrap
import unittest
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


@unittest.skipUnless(os.geteuid() == 0 and shutil.which("unshare"), "needs root and unshare for a small tmpfs")
class SnapshotFullDisk(unittest.TestCase):
    def test_full_disk_names_the_destination_and_leaves_no_tmp(self):
        work = Path(tempfile.mkdtemp(prefix="mft-snapshot-test-"))
        self.addCleanup(shutil.rmtree, work)
        (work / "bin").mkdir()
        (work / "bin" / "mft-sim").write_bytes(b"\0" * 1_000_000)
        (work / "out").mkdir()
        code = textwrap.dedent(f"""
            import sys
            sys.path.insert(0, {str(ROOT / "python")!r})
            from mftexp import common
            try:
                common.snapshot_binaries({str(work / "bin")!r}, {str(work / "out" / "bin")!r})
                print("copied")
            except common.ExperimentError as e:
                print("error", e)
            import os
            print("left", sorted(os.listdir({str(work / "out")!r})))
            """)
        script = f"mount -t tmpfs -o size=256k tmpfs {work / 'out'} && exec {sys.executable} -c \"$0\""
        r = subprocess.run(["unshare", "-m", "--propagation", "private", "sh", "-c", script, code],
                           capture_output=True, text=True, timeout=60)
        if r.returncode != 0 and "mount" in r.stderr:
            self.skipTest(f"cannot mount a tmpfs here: {r.stderr.strip()}")
        lines = r.stdout.strip().splitlines()
        self.assertEqual(lines[0], f"error cannot copy the executables into {work / 'out' / 'bin'}: "
                                   "No space left on device (disk full?)", r.stderr)
        self.assertEqual(lines[1], "left []")


if __name__ == "__main__":
    unittest.main()
