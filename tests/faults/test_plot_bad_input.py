#!/usr/bin/env python3
"""mft-plot.py on bad input: a CSV that is not UTF-8 or holds a word where a number belongs, and a full output
disk, each give one line naming the file and exit 2 (they were tracebacks); a figure cut by the full disk is
removed. The full disk is a 16 kB tmpfs in a mount namespace of its own (unshare -m; root only)."""
import os
import shutil
import subprocess
import tempfile
import unittest
from pathlib import Path

PLOT = Path(__file__).resolve().parents[2] / "tools" / "mft-export" / "mft-plot.py"
GOOD = "time_s,x,z,pitch,q4,q6,q8,q10\n" + "".join(f"{i * 0.01},{i * 0.001},0.42,0.01,0.1,0.2,0.3,0.4\n"
                                                   for i in range(200))


class PlotBadInput(unittest.TestCase):
    def setUp(self):
        self.dir = Path(tempfile.mkdtemp(prefix="mft-plot-test-"))
        self.addCleanup(shutil.rmtree, self.dir)

    def plot(self, argv=None):
        return subprocess.run(argv or [str(PLOT), str(self.dir), str(self.dir / "out")], capture_output=True,
                              text=True, timeout=120)

    def test_a_csv_that_is_not_utf8_is_named(self):
        (self.dir / "gt_q.csv").write_bytes(b"t,q4\n0,1\n1,2\xe9\n")
        r = self.plot()
        self.assertEqual(r.returncode, 2, r.stderr)
        self.assertEqual(r.stderr.strip(), f"mft-plot: {self.dir / 'gt_q.csv'}: not UTF-8 text (byte 12); "
                                           "expected a CSV written by mft-export")

    def test_a_word_where_a_number_belongs_is_named(self):
        (self.dir / "gt_q.csv").write_text("t,q4\n0,1\n1,x\n")
        r = self.plot()
        self.assertEqual(r.returncode, 2, r.stderr)
        self.assertEqual(r.stderr.strip(), f"mft-plot: {self.dir / 'gt_q.csv'}: line 3, column q4: not a number: 'x'")

    @unittest.skipUnless(os.geteuid() == 0 and shutil.which("unshare"), "needs root and unshare for a small tmpfs")
    def test_a_full_disk_is_one_line_and_leaves_no_cut_figure(self):
        (self.dir / "gt_q.csv").write_text(GOOD)
        out = self.dir / "out"
        out.mkdir()
        script = f"mount -t tmpfs -o size=16k tmpfs {out} && {PLOT} {self.dir} {out}; echo rc=$?; ls -A {out}"
        r = subprocess.run(["unshare", "-m", "--propagation", "private", "sh", "-c", script], capture_output=True,
                           text=True, timeout=120)
        if "rc=" not in r.stdout:
            self.skipTest(f"cannot mount a tmpfs here: {r.stderr.strip()}")
        self.assertEqual(r.stdout.split(), ["rc=2"], r.stderr)  # exit 2 and nothing left in the folder
        self.assertRegex(r.stderr.strip(), r"^mft-plot: cannot write .*/out/floating_base\.png: No space left on "
                                           r"device \(disk full\?\)$")
        self.assertNotIn("Traceback", r.stderr)


if __name__ == "__main__":
    unittest.main()
