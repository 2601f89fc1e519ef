#!/usr/bin/env python3
"""mft-cmd --set refuses a value outside the key's physical range, or text where a number belongs, before it
sends anything (no stack is needed): the range is the configuration schema's (docs/reference/config-reference.md).
Before, 'planner.swing.lift_height_m=50' and 'planner.foot_placement.k_v=1e308' were applied by a running stack.
Needs MFT_BIN_DIR (set by CTest)."""
import os
import subprocess
import unittest
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
CMD = Path(os.environ.get("MFT_BIN_DIR", ROOT / "build" / "release" / "bin")) / "mft-cmd"


class LiveValues(unittest.TestCase):
    def refused(self, item):
        r = subprocess.run([str(CMD), "--domain", "231", "--timeout", "0.5", "--set", item], capture_output=True,
                           text=True, timeout=60)
        self.assertEqual(r.returncode, 2, r.stderr)
        return r.stderr.splitlines()[0]

    def test_out_of_range_and_text_are_refused_before_sending(self):
        self.assertEqual(self.refused("planner.swing.lift_height_m=50"),
                         "mft-cmd: --set 'planner.swing.lift_height_m=50': swing.lift_height_m: must lie in [0, 0.3] m "
                         "(got 50)")
        self.assertEqual(self.refused("planner.foot_placement.k_v=1e308"),
                         "mft-cmd: --set 'planner.foot_placement.k_v=1e308': foot_placement.k_v: must lie in [0, 2] s "
                         "(got 1e+308)")
        self.assertIn("expected a number or a list of numbers, got '!!str 5'",
                      self.refused("planner.foot_placement.k_v=!!str 5"))
        self.assertIn("gains.swing_foot.kp: must lie in [0, 100000] 1/s^2 (got 1e+09)",
                      self.refused("wbc.gains.swing_foot.kp=[300, 1e9]"))


if __name__ == "__main__":
    unittest.main()
