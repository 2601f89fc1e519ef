#!/usr/bin/env python3
"""recovery-map's statistics against values worked out by hand (no binaries): Wilson intervals, the I_50 / I_90
interpolation, the bootstrap interval's bounds, the paper's first-failure I_max and the phase points."""
import sys
import unittest
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "python"))
from mftexp.wilson import Z95, bootstrap, crossing, curve, wilson  # noqa: E402
from mftexp.recovery_report import first_failure_imax  # noqa: E402
from mftexp.recovery_map import phase_points, impulse_grid, run_scenario_dict  # noqa: E402
from mftexp.push import PushSetup  # noqa: E402


class WilsonTest(unittest.TestCase):
    def test_edges_have_closed_forms(self):
        # k = 0: the upper bound is z^2 / (n + z^2); k = n: the lower bound is n / (n + z^2).
        z2 = Z95 * Z95
        self.assertEqual(wilson(0, 8)[0], 0.0)
        self.assertAlmostEqual(wilson(0, 8)[1], z2 / (8 + z2), places=12)
        self.assertAlmostEqual(wilson(8, 8)[0], 8 / (8 + z2), places=12)
        self.assertAlmostEqual(wilson(0, 8)[1], 0.3244, places=4)
        self.assertAlmostEqual(wilson(8, 8)[0], 0.6756, places=4)

    def test_three_of_eight(self):
        # centre (3/8 + z^2/16) / (1 + z^2/8) = 0.41552; half width z sqrt(15/512 + z^2/256) / (1 + z^2/8) = 0.27874
        lo, hi = wilson(3, 8)
        self.assertAlmostEqual(lo, 0.1368, places=4)
        self.assertAlmostEqual(hi, 0.6943, places=4)
        self.assertAlmostEqual((lo + hi) / 2, 0.41552, places=4)

    def test_no_trials(self):
        self.assertEqual(wilson(0, 0), (0.0, 1.0))


class CrossingTest(unittest.TestCase):
    X = [3.0, 3.25, 3.5, 3.75]
    P = [1.0, 1.0, 0.75, 0.25]

    def test_linear_between_grid_points(self):
        # 0.9 between 3.25 (1.0) and 3.5 (0.75): 3.25 + 0.1 / 0.25 * 0.25 = 3.35
        self.assertAlmostEqual(crossing(self.X, self.P, 0.9), 3.35, places=12)
        # 0.5 between 3.5 (0.75) and 3.75 (0.25): 3.5 + 0.25 / 0.5 * 0.25 = 3.625
        self.assertAlmostEqual(crossing(self.X, self.P, 0.5), 3.625, places=12)

    def test_first_point_below_and_never_below(self):
        self.assertEqual(crossing(self.X, [0.4, 0.3, 0.2, 0.1], 0.5), 3.0)
        self.assertIsNone(crossing(self.X, [1.0, 1.0, 0.9, 0.9], 0.9))

    def test_curve_counts_a_row_that_stopped_as_failed(self):
        rows = [{3.0: True, 3.25: True}, {3.0: True, 3.25: False}]  # the second row stopped at 3.25
        self.assertEqual(curve(rows, [3.0, 3.25, 3.5]), [1.0, 0.5, 0.0])

    def test_bootstrap_interval_holds_the_point_estimate(self):
        rows = [{3.0: True, 3.25: True, 3.5: ok} for ok in (True, False, False, True)] + \
               [{3.0: True, 3.25: False, 3.5: False}, {3.0: False, 3.25: False, 3.5: False}]
        grid = [3.0, 3.25, 3.5]
        point = crossing(grid, curve(rows, grid), 0.5)  # curve 5/6, 4/6, 2/6: 3.25 + (4/6 - 0.5) / (2/6) * 0.25
        self.assertAlmostEqual(point, 3.375, places=12)
        lo, hi = bootstrap(rows, grid, 0.5, samples=500, seed=3)
        self.assertLessEqual(lo, point)
        self.assertGreaterEqual(hi, point)
        self.assertGreaterEqual(lo, 3.0)
        self.assertLessEqual(hi, 3.5)
        self.assertEqual(bootstrap(rows, grid, 0.5, samples=500, seed=3), (lo, hi))  # seeded: reproducible


class PaperStatisticTest(unittest.TestCase):
    def test_first_failure_imax(self):
        grid = [3.0, 3.25, 3.5, 3.75]
        self.assertEqual(first_failure_imax({3.0: True, 3.25: True, 3.5: False, 3.75: True}, grid), 3.25)
        self.assertIsNone(first_failure_imax({3.0: False, 3.25: True}, grid))
        self.assertEqual(first_failure_imax({3.0: True, 3.25: True}, grid), 3.25)  # the row ended before a failure


class PhaseTest(unittest.TestCase):
    def test_eight_points_of_one_cycle(self):
        pts = phase_points(8)
        self.assertEqual(pts[0], ("liftoff", 0.0, None, None))
        self.assertEqual([(p[2], p[3]) for p in pts[1:]],
                         [("left", 0.25), ("left", 0.5), ("left", 0.75), ("right", 0.0), ("right", 0.25),
                          ("right", 0.5), ("right", 0.75)])

    def test_scenarios(self):
        setup = PushSetup()
        lift = run_scenario_dict(setup, 0.44, "sa", "backward", phase_points(8)[0], 7.5)
        self.assertEqual(lift["pushes"], [{"impulse_Ns": -7.5, "at_s": 3.0, "at_liftoff": "right"}])
        mid = run_scenario_dict(setup, 0.44, "sa", "forward", phase_points(8)[3], 7.5)
        self.assertEqual(mid["pushes"], [{"impulse_Ns": 7.5, "at_s": 3.0, "at_phase": 0.75, "stance": "left"}])
        self.assertEqual(impulse_grid(3.0, 0.25, 4.0), [3.0, 3.25, 3.5, 3.75, 4.0])


if __name__ == "__main__":
    unittest.main()
