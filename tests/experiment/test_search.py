#!/usr/bin/env python3
"""The I_max search of mft-experiment (mftexp.sweep.find_imax) on synthetic outcome patterns: linear is the paper's
rule (last recovery before the first failure) whatever the pattern, and reports recoveries above the first
failure; coarse finds the same boundary unless a failure hides between two recovered coarse points; every run is
asked at most once per impulse."""
import sys
import unittest
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "python"))
from mftexp.sweep import find_imax  # noqa: E402


def outcomes(pattern):
    """pattern: the recovered impulses on the grid k = 0..len-1 as a string of R / F."""
    asked = []

    def rec(k):
        asked.append(k)
        return k < len(pattern) and pattern[k] == "R"
    return rec, asked


class SearchTest(unittest.TestCase):
    def test_linear_is_the_papers_rule(self):
        pattern = "RRRRRRRRRRFRFRRFFFFFFFFFFF"  # first failure at k = 10, recoveries at 11, 13, 14 above it
        rec, asked = outcomes(pattern)
        lo, fail, info = find_imax(rec, kmax=len(pattern) - 1, search="linear", coarse_k=5, above_k=10)
        self.assertEqual((lo, fail), (9, 10))
        self.assertEqual([k for k, ok in info["above"] if ok], [11, 13, 14])
        self.assertEqual(asked, list(range(0, 21)))  # 0..10, then 10 steps above
        self.assertEqual(len(asked), len(set(asked)))

    def test_linear_first_point_fails_and_no_failure(self):
        rec, _ = outcomes("FRRR")
        lo, fail, _ = find_imax(rec, kmax=3, search="linear", above_k=2)
        self.assertEqual((lo, fail), (None, 0))
        rec, _ = outcomes("RRRRRR")
        lo, fail, _ = find_imax(rec, kmax=5, search="linear")
        self.assertEqual((lo, fail), (5, None))

    def test_coarse_refines_at_the_first_coarse_failure(self):
        pattern = "R" * 23 + "F" * 20  # boundary at 22/23
        rec, asked = outcomes(pattern)
        lo, fail, _ = find_imax(rec, kmax=40, search="coarse", coarse_k=5, above_k=10)
        self.assertEqual((lo, fail), (22, 23))
        self.assertLess(len(set(asked)), 15)  # 0, 5, ..., 25, then 21..23, then above: far fewer than 24
        self.assertEqual(len(asked), len(set(asked)))

    def test_coarse_misses_only_a_failure_between_recovered_coarse_points(self):
        pattern = "RRRRRRRFRRRRRRRRRRRRRRRFFFFFFFFFFFFFFFF"  # an isolated failure at 7, between coarse 5 and 10
        rec, _ = outcomes(pattern)
        self.assertEqual(find_imax(rec, kmax=35, search="linear", above_k=0)[:2], (6, 7))
        rec, _ = outcomes(pattern)
        self.assertEqual(find_imax(rec, kmax=35, search="coarse", coarse_k=5, above_k=0)[:2], (22, 23))


if __name__ == "__main__":
    unittest.main(verbosity=2)
