#!/usr/bin/env python3
"""Adding a topic (docs/adding-a-topic.md), done for real: a copy of the source tree gets one new message in
idl/mft_msgs.idl and its row in idl/topics.yaml, `gen_topics.py sync` rewrites the copies kept in the repository,
and a build of only the tools that carry it (mft-inject, mft-cyclone) must then, with no other edit, publish it,
hear it with `mft-inject --listen` and with Cyclone DDS, and grant it under DDS Security to the row's writers and
readers only. Checks that no other file needed a change.

The copy lives in the build folder (MFT_SCRATCH_DIR, default <bin>/../scratch-topic) and its build is kept between
runs (ccache makes a fresh one cheaper too). DDS domain 5 (no other test uses it)."""
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
import unittest
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "python"))
from mftstack.paths import DEFAULT_BIN, REPO  # noqa: E402

DOMAIN = 5
SCRATCH = Path(os.environ.get("MFT_SCRATCH_DIR", DEFAULT_BIN.parent / "scratch-topic"))
SRC = SCRATCH / "src"
BUILD = SRC / "build" / "release"  # the same layout as the project's, so ccache's relative paths match
BIN = BUILD / "bin"
# mft-cyclone where the project's build has it (Cyclone DDS installed).
TARGETS = ["mft-inject"] + (["mft-cyclone"] if (DEFAULT_BIN / "mft-cyclone").exists() else [])

STRUCT = """
      // tests/idl/test_add_a_topic.py: a topic added by the documented procedure
      struct ScratchProbe_ {
        unsigned long long tick;
        unsigned long long stamp_ns;
        double value[3];             // what the publisher sets
        octet mode;                  // SCRATCH_MODE_*
      };
"""
CONSTANTS = "    const octet SCRATCH_MODE_ON = 0;\n"
ROW = """
  - type: ScratchProbe
    wire: rt/mft/scratch_probe
    qos: chain
    chain: false
    record: false
    writers: [cmd]
    readers: [planner]
    faults: false
    bad_values: {mode: 42}
    content: a probe added by the test of the procedure
"""
# What the procedure may touch: the message, the row, and what `gen_topics.py sync` rewrites.
EXPECTED_CHANGES = {"idl/mft_msgs.idl", "idl/topics.yaml", "ros2/mft/msg/ScratchProbe.msg", "ros2/mft/CMakeLists.txt",
                    "docs/architecture.md"}


def run(cmd, timeout, **kw):
    return subprocess.run([str(c) for c in cmd], capture_output=True, text=True, timeout=timeout, **kw)


def copy_tree():
    """The repository's files (tracked and new, not ignored) into SRC; what differs from a previous copy only."""
    files = run(["git", "-C", REPO, "ls-files", "-co", "--exclude-standard"], 60).stdout.splitlines()
    if not files:  # not a git checkout: everything but the build and run folders
        files = [str(p.relative_to(REPO)) for p in REPO.rglob("*")
                 if p.is_file() and p.relative_to(REPO).parts[0] not in ("build", "runs", ".git")]
    for rel in files:
        src, dst = REPO / rel, SRC / rel
        if not src.is_file():
            continue
        if dst.exists() and dst.read_bytes() == src.read_bytes():
            continue
        dst.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(src, dst)
    return files


def add_the_topic():
    idl = SRC / "idl" / "mft_msgs.idl"
    text = (REPO / "idl" / "mft_msgs.idl").read_text()
    text = text.replace("    module dds_ {", CONSTANTS + "\n    module dds_ {", 1)
    text = text.replace("    };  // module dds_", STRUCT.rstrip("\n") + "\n    };  // module dds_", 1)
    write_if_changed(idl, text)
    write_if_changed(SRC / "idl" / "topics.yaml", (REPO / "idl" / "topics.yaml").read_text() + ROW)
    r = run([sys.executable, SRC / "idl" / "gen_topics.py", "sync"], 120)
    if r.returncode:
        raise AssertionError(f"gen_topics.py sync failed: {r.stderr}")


def write_if_changed(path, text):
    if not path.exists() or path.read_text() != text:
        path.write_text(text)


def changed_files(files):
    """The files of the copy that differ from the repository's, and those it has in addition (among the
    repository's files and the ROS 2 package)."""
    out = {rel for rel in files if (REPO / rel).is_file() and (SRC / rel).read_bytes() != (REPO / rel).read_bytes()}
    out |= {str(p.relative_to(SRC)) for p in (SRC / "ros2").rglob("*") if p.is_file() and not (REPO / p.relative_to(SRC)).exists()}
    return out


def build():
    env = dict(os.environ)
    if shutil.which("ccache"):
        env.setdefault("CMAKE_CXX_COMPILER_LAUNCHER", "ccache")
        env.setdefault("CMAKE_C_COMPILER_LAUNCHER", "ccache")
    if not (BUILD / "build.ninja").exists():
        r = run(["cmake", "-S", SRC, "-B", BUILD, "-G", "Ninja", "-DCMAKE_BUILD_TYPE=Release", "-DMFT_BUILD_TESTS=OFF",
                 "-DMFT_BUILD_BENCH=OFF", "-DMFT_WERROR=ON"], 600, env=env)
        if r.returncode:
            raise AssertionError(f"configure failed: {r.stdout[-3000:]}{r.stderr[-3000:]}")
    jobs = os.environ.get("MFT_BUILD_JOBS", "2")
    r = run(["cmake", "--build", BUILD, "-j", jobs, "--target"] + TARGETS, 3000, env=env)
    if r.returncode:
        raise AssertionError(f"build failed: {r.stdout[-5000:]}")


class AddATopic(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        t0 = time.monotonic()
        SRC.mkdir(parents=True, exist_ok=True)
        cls.files = copy_tree()
        add_the_topic()
        cls.copy_s = time.monotonic() - t0
        build()
        cls.build_s = time.monotonic() - t0 - cls.copy_s
        print(f"\nscratch topic: copy {cls.copy_s:.1f} s, build of {', '.join(TARGETS)} {cls.build_s:.1f} s",
              file=sys.stderr)
        cls.procs = []

    def inject(self, *args, background=False, timeout=60):
        cmd = [str(BIN / "mft-inject"), "--domain", str(DOMAIN)] + [str(a) for a in args] + ["--json"]
        if background:
            p = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
            self.procs.append(p)
            return p
        r = run(cmd, timeout)
        return r.returncode, self.report(r.stdout, r.stderr)

    def report(self, out, err):
        try:
            return json.loads(out.strip().splitlines()[-1])
        except (ValueError, IndexError):
            self.fail(f"no JSON report: {out[-1000:]} {err[-2000:]}")

    def finish(self, p, timeout=60):
        out, err = p.communicate(timeout=timeout)
        return p.returncode, self.report(out, err)

    def tearDown(self):
        for p in self.procs:  # only what this test started, by its handle
            if p.poll() is None:
                p.kill()
                p.wait()

    def test_1_only_the_definition_and_the_row_changed(self):
        self.assertEqual(changed_files(self.files), EXPECTED_CHANGES)
        msg = (SRC / "ros2" / "mft" / "msg" / "ScratchProbe.msg").read_text()
        self.assertIn("float64[3] value  # what the publisher sets", msg)
        self.assertIn("uint8 SCRATCH_MODE_ON=0", msg)
        self.assertIn("| `ScratchProbe` | `rt/mft/scratch_probe` | mft-cmd → mft-planner |",
                      (SRC / "docs" / "architecture.md").read_text())

    def test_2_published_and_heard_by_mft_inject(self):
        listener = self.inject("--listen", "ScratchProbe", "--wait-writers", 20, "--seconds", 2, background=True)
        code, pub = self.inject("--publish", "ScratchProbe", "--value", "nan", "--rate", 200, "--seconds", 6,
                                "--wait-match", 20, timeout=90)
        self.assertEqual(code, 0, pub)
        self.assertGreater(pub["written"], 0, pub)
        code, heard = self.finish(listener)
        self.assertEqual(code, 0, heard)
        probe = heard["listen"]["ScratchProbe"]
        self.assertGreater(probe["received"], 50, heard)
        # Every sample had its three doubles set to NaN: the generated field visitor reached them.
        self.assertEqual(probe["nonfinite"], probe["received"], heard)

    def test_3_heard_by_cyclone(self):
        if "mft-cyclone" not in TARGETS:
            self.skipTest("no Cyclone DDS in this build (mft-cyclone)")
        publisher = self.inject("--publish", "ScratchProbe", "--value", 2.5, "--rate", 200, "--seconds", 20,
                                "--wait-match", 20, background=True)
        r = run([BIN / "mft-cyclone", "listen", "--domain", DOMAIN, "--topics", "ScratchProbe", "--min-samples", 100,
                 "--seconds", 25, "--json"], 60)
        publisher.kill()
        publisher.wait()
        self.assertEqual(r.returncode, 0, r.stderr)
        probe = json.loads(r.stdout)["topics"]["ScratchProbe"]
        self.assertGreaterEqual(probe["samples"], 100, probe)
        self.assertEqual(probe["value"], "value", probe)
        self.assertEqual((probe["min"], probe["max"]), (2.5, 2.5), probe)
        self.assertEqual(probe["tick_decreases"], 0, probe)

    def test_4_permitted_under_dds_security_to_its_writers_and_readers_only(self):
        with tempfile.TemporaryDirectory(prefix="mft-scratch-sec-") as sec:
            r = run(["bash", SRC / "scripts" / "make-security.sh", sec, "--force"], 120)
            self.assertEqual(r.returncode, 0, r.stderr)
            perm = {i: (Path(sec) / f"permissions_{i}.xml").read_text() for i in ("cmd", "planner", "estimator")}
            self.assertIn("<topic>rt/mft/scratch_probe</topic>", perm["cmd"].split("<subscribe>")[0])
            self.assertIn("<topic>rt/mft/scratch_probe</topic>", perm["planner"].split("<subscribe>")[1])
            self.assertNotIn("scratch_probe", perm["estimator"])
            secure = ["--secure", sec]
            listener = self.inject(*secure, "--identity", "planner", "--listen", "ScratchProbe", "--wait-writers", 30,
                                   "--seconds", 2, background=True)
            code, pub = self.inject(*secure, "--identity", "cmd", "--publish", "ScratchProbe", "--value", 1,
                                    "--rate", 100, "--seconds", 8, "--wait-match", 30, timeout=120)
            self.assertEqual((code, pub["writer"]), (0, "created"), pub)
            code, heard = self.finish(listener, timeout=90)
            self.assertGreater(heard["listen"]["ScratchProbe"]["received"], 0, heard)
            code, refused = self.inject(*secure, "--identity", "estimator", "--publish", "ScratchProbe", "--seconds", 0.2,
                                        "--wait-match", 0, timeout=60)
            self.assertEqual((code, refused["writer"]), (4, "refused"), refused)


if __name__ == "__main__":
    unittest.main(verbosity=2)
