#!/usr/bin/env python3
"""mft-experiment's list options (--heights, --speeds): a value given twice is refused (it ran twice and filled
one table cell), as are values outside the planner's ranges and text that is not a number; a failed in-process
run reports the tool's reason, not its --help hint."""
import argparse
import sys
import unittest
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "python"))
from mftexp import cli  # noqa: E402


class ListOptionsTest(unittest.TestCase):
    def refusal(self, parse, text):
        with self.assertRaises(argparse.ArgumentTypeError) as e:
            parse(text)
        return str(e.exception)

    def test_a_height_given_twice_is_refused(self):
        self.assertEqual(self.refusal(cli.heights_list, "0.42,0.42"), "height 0.42 given twice")
        self.assertEqual(self.refusal(cli.heights_list, "0.40,0.4200,0.40,0.42"), "height 0.4, 0.42 given twice")
        self.assertEqual(self.refusal(cli.speeds_list, "0.3,0.30"), "speed 0.3 given twice")

    def test_distinct_values_pass_in_order(self):
        self.assertEqual(cli.heights_list("0.44,0.40"), [0.44, 0.40])

    def test_values_outside_the_range_and_text_are_refused(self):
        self.assertIn("outside the planner's window", self.refusal(cli.heights_list, "0.9"))
        self.assertIn("not a comma-separated list", self.refusal(cli.heights_list, "0.4,x"))
        self.assertIn("outside the planner's window", self.refusal(cli.heights_list, "nan"))


class ToolReasonTest(unittest.TestCase):
    """mft-experiment --inprocess with a bad config showed "Try 'mft-closedloop --help'." instead of the reason."""

    def test_the_reason_not_the_help_hint(self):
        from mftexp import common
        err = "mft-closedloop: planner.yaml: swing.lift_height_m: must lie in [0, 0.3] m (got 50)\n" \
              "Try 'mft-closedloop --help'.\n"
        self.assertEqual(common.tool_reason(err),
                         "mft-closedloop: planner.yaml: swing.lift_height_m: must lie in [0, 0.3] m (got 50)")
        self.assertEqual(common.tool_reason(""), "no output")


if __name__ == "__main__":
    unittest.main()
