#!/usr/bin/env python3
"""Adding a topic (docs/guide/adding-a-topic.md), done for real: a copy of the source tree gets one new message in
idl/mft_msgs.idl and its row in idl/topics.yaml (recorded, with the next rawlog id), `gen_topics.py sync` rewrites
the copies kept in the repository, and a build of only the tools that carry it (mft-inject, mft-record,
mft-replay, mft-export, mft-cyclone) must then, with no other edit, publish it, hear it with `mft-inject --listen`
and with Cyclone DDS, grant it under DDS Security to the row's writers and readers only, record it with mft-record
(every value as published, read back by mft-export) and play it back with mft-replay. Checks that no other file
needed a change: by hand only the definition and the row (the writer and the reader here are mft-inject's and the
recorder's, which need no code), and what `sync` rewrote.

The copy lives in the build folder (MFT_SCRATCH_DIR, default <bin>/../scratch-topic) and its build is kept between
runs (ccache makes a fresh one cheaper too). DDS domain 5 (no other test uses it)."""
import csv
import json
import math
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import unittest
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "python"))
from mftstack import topics  # noqa: E402
from mftstack.paths import DEFAULT_BIN, REPO  # noqa: E402

DOMAIN = 5
SCRATCH = Path(os.environ.get("MFT_SCRATCH_DIR", DEFAULT_BIN.parent / "scratch-topic"))
SRC = SCRATCH / "src"
BUILD = SRC / "build" / "release"  # the same layout as the project's, so ccache's relative paths match
BIN = BUILD / "bin"
# mft-cyclone where the project's build has it (Cyclone DDS installed).
TARGETS = ["mft-inject", "mft-record", "mft-replay", "mft-export"] + (
    ["mft-cyclone"] if (DEFAULT_BIN / "mft-cyclone").exists() else [])

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
# A recorded topic takes the rawlog id after the highest (idl/topics.yaml).
NEXT_RAWLOG_ID = max(r.rawlog_id for r in topics.load().recorded()) + 1
ROW = f"""
  - type: ScratchProbe
    wire: rt/mft/scratch_probe
    qos: chain
    chain: false
    record: true
    rawlog_id: {NEXT_RAWLOG_ID}
    writers: [cmd]
    readers: [planner]
    faults: false
    bad_values: {{mode: 42}}
    content: a probe added by the test of the procedure
"""
# What the procedure may touch: by hand the message and the row; `gen_topics.py sync` rewrites the kept copies.
BY_HAND = {"idl/mft_msgs.idl", "idl/topics.yaml"}
REWRITTEN_BY_SYNC = {"ros2/mft/msg/ScratchProbe.msg", "ros2/mft/CMakeLists.txt", "docs/reference/architecture.md"}


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
        self.assertEqual(changed_files(self.files), BY_HAND | REWRITTEN_BY_SYNC)
        # The rewritten files are exactly what the registry makes of them: nothing there was edited by hand.
        r = run([sys.executable, SRC / "idl" / "gen_topics.py", "check"], 120)
        self.assertEqual(r.returncode, 0, r.stderr)
        msg = (SRC / "ros2" / "mft" / "msg" / "ScratchProbe.msg").read_text()
        self.assertIn("float64[3] value  # what the publisher sets", msg)
        self.assertIn("uint8 SCRATCH_MODE_ON=0", msg)
        self.assertIn("| `ScratchProbe` | `rt/mft/scratch_probe` | mft-cmd → mft-planner, mft-record | chain | no | yes |",
                      (SRC / "docs" / "reference" / "architecture.md").read_text())

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

    def test_5_recorded_by_mft_record_and_replayed_by_mft_replay(self):
        with tempfile.TemporaryDirectory(prefix="mft-scratch-rec-") as tmp:
            rawlog = Path(tmp) / "probe.rawlog"
            recorded = self.record(rawlog, Path(tmp))
            self.assertEqual(self.exported_rows(rawlog, Path(tmp) / "csv", recorded), recorded["written"])
            self.replayed(rawlog, recorded)

    def record(self, rawlog, tmp):
        """mft-record's counts of the probe while mft-inject publishes it with NaN in every double."""
        log = (tmp / "record.out").open("w")
        recorder = subprocess.Popen([str(BIN / "mft-record"), "--domain", str(DOMAIN), "--mode", "realtime",
                                     "--scenario", str(SRC / "config" / "scenarios" / "stand.yaml"),
                                     "--output", str(rawlog), "--summary", str(tmp / "record.json")],
                                    stdout=log, stderr=subprocess.STDOUT, text=True)
        self.procs.append(recorder)
        end = time.monotonic() + 60
        while "READY mft-record" not in (tmp / "record.out").read_text() and time.monotonic() < end:
            self.assertIsNone(recorder.poll(), (tmp / "record.out").read_text())
            time.sleep(0.1)
        self.assertIn("READY mft-record", (tmp / "record.out").read_text())
        code, pub = self.inject("--publish", "ScratchProbe", "--value", "nan", "--rate", 200, "--seconds", 2,
                                "--wait-match", 20, timeout=60)
        self.assertEqual((code, pub["matched_readers"]), (0, 1), pub)
        recorder.send_signal(signal.SIGTERM)
        self.assertEqual(recorder.wait(timeout=30), 0, (tmp / "record.out").read_text())
        log.close()
        got = json.loads((tmp / "record.json").read_text())["topics"]["ScratchProbe"]
        # Every sample received is written, in tick order; at most a tenth lost on the way (best effort, loopback).
        self.assertEqual((got["written"], got["out_of_order"], got["dropped_queue"]), (got["received"], 0, 0), got)
        self.assertGreaterEqual(got["received"], 0.9 * pub["written"], (got, pub))
        self.assertEqual(got["last"] - got["first"] + 1 - got["tick_gaps"], got["written"], got)
        return got

    def exported_rows(self, rawlog, csv_dir, recorded):
        """The probe's generic label (scratch_probe) read back by mft-export: every value as published."""
        r = run([BIN / "mft-export", rawlog, "--csv", csv_dir, "--labels", "scratch_probe", "--json"], 120)
        self.assertEqual(r.returncode, 0, r.stderr)
        with (csv_dir / "scratch_probe.csv").open() as f:
            rows = list(csv.reader(f))
        head, rows = rows[0], rows[1:]
        self.assertEqual(head[2:], ["tick", "stamp_ns", "value_0", "value_1", "value_2", "mode"])
        ticks = [int(row[2]) for row in rows]
        self.assertEqual(ticks, sorted(set(ticks)))
        self.assertEqual((ticks[0], ticks[-1]), (recorded["first"], recorded["last"]))
        for row in rows:
            self.assertTrue(all(math.isnan(float(v)) for v in row[4:7]), row)
            self.assertEqual((row[3], row[7]), ("0", "0"), row)  # stamp_ns and mode: not set by --value nan
        return len(rows)

    def replayed(self, rawlog, recorded):
        """mft-replay publishes every recorded sample; a listener hears them with the recorded (NaN) values."""
        r = run([BIN / "mft-replay", rawlog, "--domain", DOMAIN, "--topics", "ScratchProbe", "--json"], 120)
        self.assertEqual(r.returncode, 0, r.stderr)
        once = json.loads(r.stdout)
        self.assertEqual((once["published"], once["end"]), ({"ScratchProbe": recorded["written"]}, "complete"), once)
        # The recorded stamps are all 0 (mft-inject sets none), so a pass is one burst: played in a loop until a
        # listener has heard some, whatever the order in which the two endpoints matched.
        listener = self.inject("--listen", "ScratchProbe", "--wait-writers", 30, "--seconds", 2, background=True)
        loop = subprocess.Popen([str(BIN / "mft-replay"), str(rawlog), "--domain", str(DOMAIN), "--topics",
                                 "ScratchProbe", "--loop", "--wait-subscribers", "30", "--json"],
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        self.procs.append(loop)
        code, heard = self.finish(listener, timeout=90)
        self.assertEqual(code, 0, heard)
        loop.send_signal(signal.SIGTERM)
        out, err = loop.communicate(timeout=30)
        self.assertEqual(loop.returncode, 0, err)
        self.assertGreater(json.loads(out)["published"]["ScratchProbe"], 0, out)
        probe = heard["listen"]["ScratchProbe"]
        self.assertGreater(probe["received"], 0, heard)
        self.assertEqual(probe["nonfinite"], probe["received"], heard)  # the recorded NaNs, not a default message
        self.assertGreaterEqual(probe["first_tick"], recorded["first"], heard)
        self.assertLessEqual(probe["last_tick"], recorded["last"], heard)


if __name__ == "__main__":
    unittest.main(verbosity=2)
