#!/usr/bin/env python3
"""`cmake --install` of this build into a temporary prefix, then, with nothing but that prefix:
- the exported package: find_package(mft_wbc) from a copy of examples/wbc_on_recorded_state configured with
  CMAKE_PREFIX_PATH=<prefix> (no path of the source or build tree in its build files), built and run;
- its torques: finite, within the robot's torque limit, every tick solved, and equal within 1e-9 to the same
  program built in the tree against the in-tree libraries (mft-example-reference);
- the installed tools and supervisor: their defaults are <prefix>/share/mft_wbc (config, scripts, python) and
  <prefix>/bin, and a short lockstep stack runs from the prefix (the supervisor, the four services);
- the Debian package (cpack -G DEB): control fields, contents, and a tool of the unpacked package.
Everything is written under one temporary folder, removed at the end (kept with --keep)."""
import argparse
import json
import math
import os
import re
import shutil
import subprocess
import sys
import tempfile
import unittest
from pathlib import Path

import yaml

ARGS = None
TOL = 1e-9


def run(argv, cwd=None, env=None, timeout=300):
    return subprocess.run([str(a) for a in argv], cwd=cwd, env=env, capture_output=True, text=True, errors="replace",
                          timeout=timeout)


class InstalledPrefix(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = Path(tempfile.mkdtemp(prefix="mft-install-test-"))
        cls.prefix = cls.tmp / "prefix"
        cls.env = {k: v for k, v in os.environ.items() if k not in ("MFT_BIN_DIR", "MFT_RUNS_DIR", "PYTHONPATH")}
        r = run([ARGS.cmake, "--install", ARGS.build_dir, "--prefix", cls.prefix], env=cls.env)
        if r.returncode != 0:
            raise AssertionError(f"cmake --install failed ({r.returncode}):\n{r.stdout[-3000:]}\n{r.stderr[-3000:]}")
        cls.share = cls.prefix / "share" / "mft_wbc"
        libdirs = [p for p in cls.prefix.glob("lib*/**/cmake/mft_wbc")]
        cls.cmake_dir = libdirs[0] if libdirs else None

    @classmethod
    def tearDownClass(cls):
        if ARGS.keep:
            print(f"kept {cls.tmp}", file=sys.stderr)
        else:
            shutil.rmtree(cls.tmp, ignore_errors=True)

    def test_1_layout(self):
        self.assertIsNotNone(self.cmake_dir, "no lib*/cmake/mft_wbc in the prefix")
        for name in ("mft_wbcConfig.cmake", "mft_wbcConfigVersion.cmake", "mft_wbcTargets.cmake"):
            self.assertTrue((self.cmake_dir / name).is_file(), name)
        for rel in ("include/mft/wbc/whole_body_controller.hpp", "include/mft/wbc/qp/qp_solver.hpp",
                    "include/mft/common/strict_yaml.hpp", "include/mft/model/five_bar.hpp",
                    "include/mft/planner/motion_planner.hpp", "include/mft/estimator/state_estimator.hpp",
                    "include/mft/sim/simulator.hpp", "share/mft_wbc/config/robot.yaml",
                    "share/mft_wbc/config/scenarios/stand.yaml", "share/mft_wbc/python/mftstack/paths.py",
                    "share/mft_wbc/scripts/mft-plot.py"):
            self.assertTrue((self.prefix / rel).is_file(), rel)
        for exe in ("mft-sim", "mft-wbc", "mft-estimator", "mft-planner", "mft-space", "mft-qp", "mft-participants",
                    "mft-supervisor"):
            self.assertTrue(os.access(self.prefix / "bin" / exe, os.X_OK), exe)
        self.assertFalse((self.prefix / "include" / "mft" / "sim" / "ode_robot.hpp").exists(),
                         "the simulator's ODE wrappers are private")
        self.assertFalse(list(self.prefix.rglob("__pycache__")))
        # The package must not point back into the trees it came from.
        for f in self.cmake_dir.iterdir():
            text = f.read_text()
            for tree in (ARGS.source_dir, ARGS.build_dir):
                self.assertNotIn(str(Path(tree).resolve()), text, f"{f.name} names {tree}")

    def build_example(self):
        src = self.tmp / "example-src"
        shutil.copytree(Path(ARGS.source_dir) / "examples" / "wbc_on_recorded_state", src)
        build = self.tmp / "example-build"
        r = run([ARGS.cmake, "-S", src, "-B", build, "-G", ARGS.generator, "-DCMAKE_BUILD_TYPE=Release",
                 f"-DCMAKE_PREFIX_PATH={self.prefix}", "-DCMAKE_FIND_PACKAGE_NO_PACKAGE_REGISTRY=ON",
                 "-DCMAKE_FIND_PACKAGE_NO_SYSTEM_PACKAGE_REGISTRY=ON", "-DCMAKE_EXPORT_COMPILE_COMMANDS=ON"],
                env=self.env)
        self.assertEqual(r.returncode, 0, f"configure:\n{r.stdout[-3000:]}\n{r.stderr[-3000:]}")
        self.assertIn(f"mft_wbc_DIR:PATH={self.cmake_dir}", (build / "CMakeCache.txt").read_text(),
                      "find_package(mft_wbc) did not take the temporary prefix")
        r = run([ARGS.cmake, "--build", build, "-j", "2"], env=self.env)
        self.assertEqual(r.returncode, 0, f"build:\n{r.stdout[-3000:]}\n{r.stderr[-3000:]}")
        commands = json.loads((build / "compile_commands.json").read_text())
        self.assertEqual(len(commands), 1)
        flags = commands[0]["command"]
        self.assertIn(f"{self.prefix}/include/mft", flags)
        for tree in (ARGS.source_dir, ARGS.build_dir):
            self.assertNotIn(str(Path(tree).resolve()), flags, f"the example's compile line names {tree}")
        return src, build / "wbc_on_recorded_state"

    def test_2_example_against_prefix(self):
        src, exe = self.build_example()
        state = src / "recorded_state.csv"
        r = run([exe, "--json"], env=self.env)
        self.assertEqual(r.returncode, 0, f"example: {r.stdout}\n{r.stderr}")
        out = json.loads(r.stdout)
        self.assertEqual(Path(out["config_dir"]), self.share / "config")  # its default: the installed configuration
        self.assertEqual(Path(out["state_file"]), state)
        ref_run = run([ARGS.reference, "--json", "--state", state], env=self.env)
        self.assertEqual(ref_run.returncode, 0, f"reference: {ref_run.stdout}\n{ref_run.stderr}")
        ref = json.loads(ref_run.stdout)
        self.assertEqual(Path(ref["config_dir"]), Path(ARGS.source_dir) / "config")

        robot = yaml.safe_load((Path(ARGS.source_dir) / "config" / "robot.yaml").read_text())
        wbc = yaml.safe_load((Path(ARGS.source_dir) / "config" / "wbc.yaml").read_text())
        limit = (robot["actuator"]["gear_ratio"] * robot["actuator"]["motor_peak_torque_Nm"]
                 * wbc["limits"]["torque_limit_fraction"])
        self.assertAlmostEqual(out["torque_limit_Nm"], limit, delta=1e-12)
        rows = [line for line in state.read_text().splitlines() if line and not line.startswith("#")]
        self.assertGreaterEqual(len(out["ticks"]), 5)
        self.assertEqual(len(out["ticks"]), len(rows) - 1)
        self.assertEqual(out["failed_ticks"], 0)
        self.assertEqual(len(ref["ticks"]), len(out["ticks"]))
        worst = 0.0
        for t, rt in zip(out["ticks"], ref["ticks"]):
            self.assertEqual(t["tick"], rt["tick"])
            self.assertTrue(t["ok"], t)
            for tau, tau_ref in zip(t["tau"], rt["tau"]):
                self.assertTrue(math.isfinite(tau), t)
                self.assertLessEqual(abs(tau), limit + TOL, t)
                worst = max(worst, abs(tau - tau_ref))
        self.assertLessEqual(worst, TOL, "installed example and in-tree reference disagree")
        self.assertGreater(max(abs(x) for t in out["ticks"] for x in t["tau"]), 1.0, "no torque at all")
        # For the record: how far the example's torques are from what the stack's WBC commanded in the run.
        header = rows[0].split(",")
        recorded = [[float(row.split(",")[header.index(f"recorded_tau_q{j}")]) for j in (4, 6, 8, 10)] for row in rows[1:]]
        gap = max(abs(a - b) for t, rec in zip(out["ticks"], recorded) for a, b in zip(t["tau"], rec))
        print(f"example vs in-tree reference: max |dtau| {worst:.3g} N m over {len(out['ticks'])} ticks; "
              f"vs the recorded run's commands: max |dtau| {gap:.3g} N m (a fresh controller, no history)", file=sys.stderr)

        bad = run([exe, "--state", self.tmp / "missing.csv"], env=self.env)
        self.assertEqual(bad.returncode, 2)
        self.assertRegex(bad.stderr, r"^wbc_on_recorded_state: error: cannot open the state file .*missing\.csv\n$")

    def test_3_installed_tools_use_the_prefix(self):
        config = self.share / "config"
        r = run([self.prefix / "bin" / "mft-space", "--help"], env=self.env)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn(f"(default: {config}/robot.yaml)", r.stdout)
        r = run([self.prefix / "bin" / "mft-sim", "--help"], env=self.env)
        self.assertIn(str(config), r.stdout + r.stderr)
        r = run([self.prefix / "bin" / "mft-participants", "--help"], env=self.env)
        self.assertIn(f"{config}/dds_profiles.xml", r.stdout + r.stderr)
        # The installed simulator checks a scenario against the installed configuration, no --config-dir.
        r = run([self.prefix / "bin" / "mft-sim", "--check-scenario", config / "scenarios" / "walk.yaml", "--json"],
                env=self.env)
        self.assertEqual(r.returncode, 0, r.stderr)
        json.loads(r.stdout)

    def test_4_supervisor_from_the_prefix(self):
        probe = ("import json, sys; sys.path.insert(0, sys.argv[1]); from mftstack import paths; "
                 "print(json.dumps({k: str(getattr(paths, k)) for k in "
                 "('INSTALLED', 'PREFIX', 'REPO', 'DEFAULT_BIN', 'DEFAULT_CONFIG', 'DEFAULT_RUNS', 'SUPERVISOR')}))")
        r = run([sys.executable, "-c", probe, self.share / "python"], cwd=self.tmp, env=self.env)
        self.assertEqual(r.returncode, 0, r.stderr)
        p = json.loads(r.stdout)
        self.assertEqual(p["INSTALLED"], "True")
        self.assertEqual(Path(p["PREFIX"]), self.prefix)
        self.assertEqual(Path(p["DEFAULT_BIN"]), self.prefix / "bin")
        self.assertEqual(Path(p["DEFAULT_CONFIG"]), self.share / "config")
        self.assertEqual(Path(p["SUPERVISOR"]), self.prefix / "bin" / "mft-supervisor")
        self.assertEqual(Path(p["DEFAULT_RUNS"]), self.tmp / "runs")  # the working folder: the prefix may be read-only

        supervisor = self.prefix / "bin" / "mft-supervisor"
        r = run([supervisor, "run", "--help"], cwd=self.tmp, env=dict(self.env, COLUMNS="1000"))  # no wrapped paths
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn(f"(default {self.prefix / 'bin'})", r.stdout)
        self.assertIn(f"(default {self.share / 'config'})", r.stdout)
        # A 1 s standing run entirely from the prefix (binaries, configuration, supervisor, its package).
        scenario = yaml.safe_load((self.share / "config" / "scenarios" / "stand.yaml").read_text())
        scenario["duration_s"] = 1.0
        scenario["commands"] = [c for c in scenario.get("commands", []) if c.get("at_s", 0.0) < 1.0]
        (self.tmp / "stand-1s.yaml").write_text(yaml.safe_dump(scenario))
        r = run([supervisor, "run", self.tmp / "stand-1s.yaml", "--domain", ARGS.domain, "--json",
                 "--run-dir", self.tmp / "run"], cwd=self.tmp, env=self.env, timeout=120)
        self.assertEqual(r.returncode, 0, f"{r.stdout[-2000:]}\n{r.stderr[-3000:]}")
        summary = json.loads(r.stdout)
        print(f"stack from the prefix: {json.dumps(summary)[:400]}", file=sys.stderr)
        self.assertTrue(summary["ok"], summary)
        self.assertFalse(summary["fell"], summary)
        self.assertEqual(summary["ticks"], 1000)
        self.assertEqual(summary["wbc_safety_events"], 0)
        logs = " ".join(f.read_text(errors="replace") for f in (self.tmp / "run").glob("*.log"))
        self.assertNotIn(str(Path(ARGS.source_dir).resolve()) + "/config", logs)

    def test_6_every_header_and_target(self):
        """One program including every installed header, linking all seven targets; the simulator (libode through
        the package file's pkg-config) steps ten control ticks."""
        src, build = self.tmp / "all-src", self.tmp / "all-build"
        src.mkdir()
        include = self.prefix / "include" / "mft"
        headers = sorted(str(h.relative_to(include)) for h in include.rglob("*.hpp"))
        self.assertGreater(len(headers), 40)
        components = ["common", "model", "qp", "wbc", "planner", "estimator", "sim"]
        (src / "CMakeLists.txt").write_text(
            "cmake_minimum_required(VERSION 3.22)\nproject(all_headers LANGUAGES CXX)\n"
            f"find_package(mft_wbc REQUIRED COMPONENTS {' '.join(components)})\n"
            "add_executable(all_headers main.cpp)\n"
            f"target_link_libraries(all_headers PRIVATE {' '.join('mft::' + c for c in components)})\n")
        (src / "main.cpp").write_text("".join(f'#include "{h}"\n' for h in headers) + """
#include <cstdio>
int main(int argc, char** argv) {
  if (argc < 2) return 2;
  const std::string dir = argv[1];
  const auto robot = mft::model::loadRobotDescription(dir + "/robot.yaml");
  mft::sim::Simulator sim(robot, mft::sim::loadSimOptions(dir + "/sim.yaml"), mft::sim::Terrain::flat());
  for (int i = 0; i < 10; ++i) sim.step();
  std::printf("%llu\\n", static_cast<unsigned long long>(sim.stats().control_steps));
  return 0;
}
""")
        r = run([ARGS.cmake, "-S", src, "-B", build, "-G", ARGS.generator, "-DCMAKE_BUILD_TYPE=Release",
                 f"-DCMAKE_PREFIX_PATH={self.prefix}", "-DCMAKE_FIND_PACKAGE_NO_PACKAGE_REGISTRY=ON"], env=self.env)
        self.assertEqual(r.returncode, 0, f"configure:\n{r.stdout[-3000:]}\n{r.stderr[-3000:]}")
        r = run([ARGS.cmake, "--build", build], env=self.env)
        self.assertEqual(r.returncode, 0, f"build:\n{r.stdout[-3000:]}\n{r.stderr[-3000:]}")
        r = run([build / "all_headers", self.share / "config"], env=self.env)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(r.stdout.strip(), "10")

    def test_5_debian_package(self):
        out = self.tmp / "deb"
        r = run([ARGS.cpack, "--config", Path(ARGS.build_dir) / "CPackConfig.cmake", "-G", "DEB", "-B", out], env=self.env)
        self.assertEqual(r.returncode, 0, f"{r.stdout[-3000:]}\n{r.stderr[-3000:]}")
        debs = list(out.glob("*.deb"))
        self.assertEqual(len(debs), 1, debs)
        self.assertRegex(debs[0].name, r"^mft-wbc_\d+\.\d+\.\d+_[a-z0-9]+\.deb$")
        fields = {}
        for name in ("Package", "Version", "Maintainer", "Depends"):
            fields[name] = run(["dpkg-deb", "-f", debs[0], name]).stdout.strip()
        self.assertEqual(fields["Package"], "mft-wbc")
        self.assertTrue(fields["Maintainer"])
        depends = {d.strip().split(" ")[0] for d in fields["Depends"].split(",")}
        for lib in ("python3", "python3-yaml", "libode8", "libyaml-cpp0.7", "libfastrtps2.9", "libstdc++6"):
            self.assertIn(lib, depends, fields["Depends"])
        listing = run(["dpkg-deb", "-c", debs[0]]).stdout
        for path in ("./usr/bin/mft-wbc", "./usr/bin/mft-supervisor", "./usr/include/mft/wbc/whole_body_controller.hpp",
                     "./usr/share/mft_wbc/config/robot.yaml", "./usr/share/mft_wbc/python/mftstack/cli.py"):
            self.assertIn(path, listing)
        self.assertRegex(listing, r"\./usr/lib/(.*/)?cmake/mft_wbc/mft_wbcConfig\.cmake")
        # Unpacked anywhere, its tools take their configuration from the package and agree with the build's.
        root = self.tmp / "debroot"
        r = run(["dpkg", "-x", debs[0], root])
        self.assertEqual(r.returncode, 0, r.stderr)
        usr = root / "usr"
        r = run([usr / "bin" / "mft-space", "--help"], env=self.env)
        self.assertIn(f"(default: {usr}/share/mft_wbc/config/robot.yaml)", r.stdout)
        index = ["index", "--rear", "-0.6", "--fore", "0.6", "--json"]
        packaged = run([usr / "bin" / "mft-space"] + index, env=self.env)
        built = run([Path(ARGS.build_dir) / "bin" / "mft-space"] + index, env=self.env)
        self.assertEqual(packaged.returncode, 0, packaged.stderr)
        a, b = json.loads(packaged.stdout), json.loads(built.stdout)
        self.assertGreater(a["lti"], 0.0)
        for key in ("lti", "gamma_I", "gamma_O", "foot_z"):
            self.assertAlmostEqual(a[key], b[key], delta=1e-12, msg=key)


if __name__ == "__main__":
    p = argparse.ArgumentParser()
    p.add_argument("--build-dir", required=True)
    p.add_argument("--source-dir", required=True)
    p.add_argument("--reference", required=True)
    p.add_argument("--generator", default="Ninja")
    p.add_argument("--cmake", default="cmake")
    p.add_argument("--cpack", default="cpack")
    p.add_argument("--domain", default="187")
    p.add_argument("--keep", action="store_true")
    ARGS, rest = p.parse_known_args()
    unittest.main(argv=[sys.argv[0]] + rest, verbosity=2)
