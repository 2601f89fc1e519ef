#!/usr/bin/env python3
"""Bad input and misuse of files and tools (issue 16, part 3; docs/results/faults.md "Files and tools"): every case
is refused with one clear line and a documented exit status, fast, never an abort, a hang, a huge allocation
or a result that looks fine. Single processes only; the services are refused before they create a DDS
participant (domain 231 if one ever did)."""
import json
import re
import resource
import shutil
import subprocess
import sys
import tempfile
import unittest
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "python"))
from mftstack.testing import BIN, CONFIG, REPO  # noqa: E402
DEMO = CONFIG / "scenarios" / "demo.yaml"
DOMAIN = "231"


def cap_memory():
    # 4 GiB of address space: a regression that allocates what a file declares fails instead of swapping.
    resource.setrlimit(resource.RLIMIT_AS, (4 << 30, 4 << 30))


def cpu_of_children():
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def run(args, timeout=300):
    """Runs a tool; p.cpu_seconds is the CPU time it used (what "fast" means here: wall time on a loaded
    2-vCPU machine says little; a refusal costs milliseconds of CPU, allocating what a file declares costs
    seconds). The wall-clock timeout only catches hangs."""
    cpu0 = cpu_of_children()
    try:
        p = subprocess.run([str(a) for a in args], capture_output=True, text=True, timeout=timeout,
                           preexec_fn=cap_memory, errors="replace")
    except subprocess.TimeoutExpired as e:
        raise AssertionError(f"{args[0]} did not finish within {timeout} s (a hang): {args}") from e
    p.cpu_seconds = cpu_of_children() - cpu0
    return p


class BadInputCase(unittest.TestCase):
    def setUp(self):
        self.tmp = Path(tempfile.mkdtemp(prefix="mft-bad-input-"))

    def tearDown(self):
        shutil.rmtree(self.tmp, ignore_errors=True)

    def scenario(self, name="s.yaml", replace=()):
        text = DEMO.read_text()
        for old, new in replace:
            self.assertIn(old, text)
            text = text.replace(old, new)
        path = self.tmp / name
        path.write_text(text)
        return path

    def assertRefused(self, p, code, *expected, max_lines=2):
        """Exit `code`, every expected text in stderr, at most `max_lines` lines, no abort or crash."""
        where = f"exit {p.returncode}\nstderr: {p.stderr}"
        self.assertEqual(p.returncode, code, where)
        for e in expected:
            self.assertIn(e, p.stderr, where)
        self.assertNotIn("terminate called", p.stderr, where)
        self.assertNotIn("Traceback", p.stderr, where)
        self.assertGreaterEqual(len(p.stderr.strip().splitlines()), 1, where)
        self.assertLessEqual(len(p.stderr.strip().splitlines()), max_lines, where)


class ScenarioAgainstTheRobot(BadInputCase):
    """Item 3: a scenario is checked against the legs' reach and the planner's limits before anything starts."""

    def reach_in(self, stderr):
        m = re.search(r"base heights in \[([0-9.]+), ([0-9.]+)\] m", stderr)
        self.assertIsNotNone(m, stderr)
        return float(m.group(1)), float(m.group(2))

    def test_initial_height_beyond_reach_is_refused_with_the_range(self):
        for h in ("0.49", "0.7", "1.0"):
            s = self.scenario(replace=[("initial_base_height_m: 0.42", "initial_base_height_m: " + h)])
            p = run([BIN / "mft-sim", "--check-scenario", s])
            self.assertRefused(p, 2, "initial_base_height_m", "outside the legs' reach")
            lo, hi = self.reach_in(p.stderr)
            # thigh 0.22 + shank 0.26 = 0.48 m: the top of the reach is just below it (contact sink, knee stop)
            self.assertLess(hi, 0.48)
            self.assertGreater(hi, 0.46)
            self.assertLess(lo, 0.30)
        ok = run([BIN / "mft-sim", "--check-scenario", self.scenario(replace=[("initial_base_height_m: 0.42",
                                                                              "initial_base_height_m: 0.46")])])
        self.assertEqual(ok.returncode, 0, ok.stderr)

    def test_height_command_beyond_the_planner_is_refused(self):
        for z in ("0.9", "0.25", "0.47"):
            s = self.scenario(replace=[("z_cmd_m: 0.42, v_cmd_mps: 0.0}\n  - {at_s: 1.0",
                                        f"z_cmd_m: {z}, v_cmd_mps: 0.0}}\n  - {{at_s: 1.0")])
            p = run([BIN / "mft-sim", "--check-scenario", s])
            self.assertRefused(p, 2, "commands[0].z_cmd_m", "outside what the planner accepts: [0.300, 0.460] m")

    def test_speed_command_beyond_the_planner_is_refused(self):
        s = self.scenario(replace=[("mode: step_in_place, z_cmd_m: 0.42, v_cmd_mps: 0.0",
                                    "mode: walk, z_cmd_m: 0.42, v_cmd_mps: 2.0")])
        p = run([BIN / "mft-sim", "--check-scenario", s])
        self.assertRefused(p, 2, "commands[1].v_cmd_mps", "|v| <= 0.600 m/s")

    def test_fall_height_above_the_start_is_refused(self):
        s = self.scenario(replace=[("base_height_below_m: 0.25", "base_height_below_m: 0.43")])
        p = run([BIN / "mft-sim", "--check-scenario", s])
        self.assertRefused(p, 2, "fall.base_height_below_m", "would count as a fall at once")

    def test_services_refuse_it_at_start_without_an_abort(self):
        high = self.scenario("high.yaml", [("initial_base_height_m: 0.42", "initial_base_height_m: 0.49")])
        far = self.scenario("far.yaml", [("z_cmd_m: 0.42, v_cmd_mps: 0.0}\n  - {at_s: 1.0",
                                          "z_cmd_m: 0.9, v_cmd_mps: 0.0}\n  - {at_s: 1.0")])
        for service in ("mft-sim", "mft-planner", "mft-wbc", "mft-estimator"):
            for s, key in ((high, "initial_base_height_m"), (far, "z_cmd_m")):
                p = run([BIN / service, "--domain", DOMAIN, "--scenario", s])
                self.assertRefused(p, 2, key, max_lines=3)
                self.assertLess(p.cpu_seconds, 5.0, f"{service}: refused only after {p.cpu_seconds:.1f} s of CPU")

    def test_closedloop_refuses_a_height_beyond_reach(self):
        p = run([BIN / "mft-closedloop", "--height", "0.9", "--duration", "0.1"])
        self.assertRefused(p, 2, "outside the legs' reach")


class RobotPlausibility(BadInputCase):
    """Item 4: absurd robot quantities are refused by the strict loader before anything starts (the full
    table of ranges is tests/model RobotDescription.EveryQuantityOutsideItsPlausibleRange...)."""

    def test_absurd_masses_are_refused_before_anything_starts(self):
        for line, value, key, rng in (("  mass_kg: 16.4", "1e308", "torso.mass_kg", "[0.5, 500] kg"),
                                      ("    mass_kg: 0.50", "1e-300", "leg.thigh.mass_kg", "[0.01, 100] kg")):
            cfg = self.tmp / f"config-{key}"
            shutil.copytree(CONFIG, cfg)
            text = (cfg / "robot.yaml").read_text()
            self.assertIn(line, text)
            (cfg / "robot.yaml").write_text(text.replace(line, line.split(":")[0] + ": " + value, 1))
            p = run([BIN / "mft-sim", "--check-scenario", DEMO, "--config-dir", cfg])
            self.assertRefused(p, 2, key + ": must lie in " + rng)


class QpInput(BadInputCase):
    """Item 8: mft-qp never reports "optimal" for data that is not a valid QP or an answer that fails KKT."""

    def qp(self, H, g, name="q.txt", dims=None):
        n = len(g)
        text = (f"WBCQP 1\nname bad\ndims {dims or f'{n} 0 0'}\nH {n} {n}\n" + "\n".join(" ".join(map(str, r)) for r in H)
                + f"\ng {n}\n" + " ".join(map(str, g)) + f"\nAeq 0 {n}\nbeq 0\n\nAin 0 {n}\nlbA 0\n\nubA 0\n\n"
                f"lb {n}\n" + " ".join(["-inf"] * n) + f"\nub {n}\n" + " ".join(["inf"] * n) + "\nend\n")
        path = self.tmp / name
        path.write_text(text)
        return path

    def test_asymmetric_H_is_refused(self):
        p = run([BIN / "mft-qp", "solve", self.qp([[2, 5], [0, 1]], [1, -1])])
        self.assertRefused(p, 2, "H is not symmetric", "H(1,0) = 0")

    def test_overflowing_g_is_not_reported_optimal(self):
        f = self.qp([[2, 0], [0, 1]], ["1e308", 0])
        p = run([BIN / "mft-qp", "solve", f, "--json"])
        self.assertEqual(p.returncode, 1, p.stdout + p.stderr)
        out = json.loads(p.stdout)
        self.assertNotEqual(out["status"], "optimal", p.stdout)
        text = run([BIN / "mft-qp", "solve", f])
        self.assertEqual(text.returncode, 1)
        self.assertNotIn("status          optimal", text.stdout)

    def test_a_valid_qp_is_still_optimal(self):
        p = run([BIN / "mft-qp", "solve", self.qp([[2, 1], [1, 2]], [1, -1]), "--json"])
        self.assertEqual(p.returncode, 0, p.stdout + p.stderr)
        out = json.loads(p.stdout)
        self.assertEqual(out["status"], "optimal")
        self.assertAlmostEqual(out["x"][0], -1.0, places=12)  # H x = -g: x = (-1, 1)
        self.assertAlmostEqual(out["x"][1], 1.0, places=12)

    def test_dims_the_file_cannot_hold_are_refused_fast(self):
        f = self.qp([[2, 0], [0, 1]], [1, -1], dims="100000 0 0")
        p = run([BIN / "mft-qp", "solve", f])
        self.assertRefused(p, 2, "more than the file of")
        self.assertLess(p.cpu_seconds, 1.0)


class JsonAndPlaceholders(BadInputCase):
    """Item 12: valid JSON whatever the names hold; no placeholder numbers for an empty window."""

    def test_check_scenario_json_escapes_control_characters(self):
        s = self.scenario(replace=[("name: demo", 'name: "tab\\there\\x01 \\"quoted\\" back\\\\slash"')])
        p = run([BIN / "mft-sim", "--check-scenario", s, "--json"])
        self.assertEqual(p.returncode, 0, p.stderr)
        out = json.loads(p.stdout)  # strict: control characters must be escaped
        self.assertEqual(out["name"], 'tab\there\x01 "quoted" back\\slash')
        self.assertEqual(out["initial_base_height_m"], 0.42)

    def test_closedloop_empty_window_prints_na_and_null(self):
        args = [BIN / "mft-closedloop", "--duration", "0.2", "--stats-from", "1"]
        p = run(args)
        self.assertEqual(p.returncode, 0, p.stderr)
        self.assertIn("n/a", p.stdout)
        self.assertNotIn("1000000000", p.stdout)
        self.assertIn("window empty", p.stdout)
        j = run(args + ["--json"])
        summary = json.loads(j.stdout)["summary"]
        self.assertEqual(summary["window_samples"], 0)
        for key in ("min_base_z_m", "max_base_z_m", "mean_base_z_m", "max_mft_violation", "min_lti"):
            self.assertIsNone(summary[key], key)
        full = json.loads(run([BIN / "mft-closedloop", "--duration", "0.3", "--stats-from", "0.1", "--json"]).stdout)["summary"]
        self.assertGreater(full["window_samples"], 100)
        self.assertAlmostEqual(full["min_base_z_m"], 0.42, delta=0.02)


class ToolIoErrors(BadInputCase):
    """Item 5, the generic check: every C++ main goes through the guard, and each tool's file arguments
    pointing at a folder, /proc or a file where a folder belongs give one line and exit 2."""

    def test_every_main_goes_through_the_guard(self):
        mains = sorted(list(REPO.glob("services/*/main.cpp")) + list(REPO.glob("tools/*/main.cpp"))
                       + [REPO / "tools" / "mft-bench" / "bench_main.cpp"])
        self.assertGreaterEqual(len(mains), 13)
        for m in mains:
            self.assertRegex(m.read_text(), r"int main\(int argc, char\*\* argv\) \{\n  return (mft::)?config::guardedMain\(",
                             f"{m.relative_to(REPO)}: main must run through config::guardedMain")

    def test_file_arguments_that_cannot_work(self):
        folder = self.tmp / "a-folder"
        folder.mkdir()
        existing = self.tmp / "existing.txt"
        existing.write_text("x\n")
        cases = [
            (["mft-export", folder, "--info"], "is a directory"),
            (["mft-replay", folder, "--through-wbc"], "is a directory"),
            (["mft-qp", "solve", folder], "is a directory"),
            (["mft-qp", "bench", existing], ""),
            (["mft-closedloop", "--duration", "0.1", "--csv", "/proc/mft-no-such-dir/x.csv"], "cannot write"),
            (["mft-sim", "--domain", DOMAIN, "--scenario", folder], str(folder) + ": is a directory"),
            (["mft-sim", "--check-scenario", folder], str(folder) + ": is a directory"),
            (["mft-sim", "--domain", DOMAIN, "--scenario", DEMO, "--profiles", folder], "is a directory"),
            (["mft-cmd", "--domain", DOMAIN, "--mode", "stand", "--profiles", folder], "is a directory"),
            (["mft-inject", "--domain", DOMAIN, "--listen", "all", "--seconds", "0.1", "--profiles", folder], str(folder)),
        ]
        for args, expect in cases:
            with self.subTest(args=" ".join(map(str, args))):
                p = run([BIN / args[0]] + args[1:])
                self.assertRefused(p, 2, expect, max_lines=3)


if __name__ == "__main__":
    unittest.main(verbosity=2)
