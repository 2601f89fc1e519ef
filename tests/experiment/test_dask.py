#!/usr/bin/env python3
"""mft-experiment on Dask distributed (issue 20), on test hosts made of network namespaces (tests/distributed/
testnet.py): `head` runs dask-scheduler and the client, `w1` and `w2` run one `mft-experiment worker` each
(one thread), joined by veths through a bridge on 10.77.<octet>.0/24; every stack runs inside a worker's
namespace. A reduced push sweep (0.44 m, both controllers, 1 N s steps from 6 N s) runs first on the local
backend (inside `head`) as the reference.

  SweepOnDask:   the same sweep through the scheduler gives exactly the local table, the same runs with the same
                 outcomes and lockstep signatures, both workers ran some, the boundary rawlogs came back from the
                 workers and reproduced their runs; a worker whose build differs (a copy of the tool without the
                 git commit, one config file changed) is refused with a clear one-line error.
  WorkerKilled:  w1 is killed (SIGKILL, by pid) while it runs a stack; the sweep still ends with the local
                 table, no run twice and none missing in results.jsonl, the killed worker's stack gone.

Skipped with a clear message where network namespaces cannot be made. DDS domains 90-93 (inside the test's own
namespaces); both workers share one scratch folder, so they also show that two workers on one machine take
different domains. Run: /usr/bin/python3 tests/experiment/test_dask.py [SweepOnDask|WorkerKilled]"""
import csv
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import unittest
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "distributed"))
sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "python"))
from testnet import TestNet, netns_permitted  # noqa: E402
from mftstack.testing import BIN, REPO, child_processes, pid_alive, processes_mentioning  # noqa: E402

TOOL = REPO / "tools" / "mft-experiment" / "mft-experiment"
PY = "/usr/bin/python3" if Path("/usr/bin/python3").exists() else sys.executable
SWEEP = ["push-sweep", "--heights", "0.44", "--start", "6", "--step", "1.0", "--max-impulse", "20", "--quiet"]
OCTET = 91  # 10.77.91.0/24: no other test's subnet (the distributed tests use their domains, 100-232)
PORT = 8786
PERMITTED, WHY_NOT = netns_permitted()


def log(msg):
    print(msg, file=sys.stderr, flush=True)


def lines(path):
    return [json.loads(l) for l in Path(path).read_text().splitlines() if l.strip()]


def runs_of(out):
    """{(controller, impulse): (recovered, signature)} and the list of run keys in file order."""
    recs = [r for r in lines(Path(out) / "results.jsonl") if r["kind"] == "run"]
    keys = [(r["controller"], round(r["impulse_Ns"], 3)) for r in recs]
    return {(r["controller"], round(r["impulse_Ns"], 3)): (r["recovered"], r["signature"]) for r in recs}, keys, recs


def table(out):
    with open(Path(out) / "table.csv") as f:
        return list(csv.DictReader(f))



def _die_with_test():
    # Runs in the child before exec: SIGKILL when this test process dies (CTest's timeout kills it with
    # SIGKILL), so no scheduler or worker outlives it in a namespace that a later test deletes as stale (a
    # dask-worker whose scheduler is gone does not end on SIGTERM); a worker's stacks die with it in turn.
    import ctypes
    try:
        ctypes.CDLL("libc.so.6", use_errno=True).prctl(1, signal.SIGKILL)  # PR_SET_PDEATHSIG
    except OSError:
        pass


def children(pid):
    """[(pid, command line)] of the children of pid."""
    return [(c, cmd) for c, _, _, cmd in child_processes(pid)]


class Cluster:
    """A scheduler in `head` and one worker per other host, every process started here and stopped by pid."""

    def __init__(self, tmp, tag, workers=("w1", "w2")):
        self.tmp = Path(tmp)
        self.net = TestNet.for_test(tag, ("head",) + tuple(workers), OCTET)
        self.worker_names = workers
        self.procs = {}
        self.scratch = self.tmp / "scratch"
        self.address = f"tcp://{self.net.address('head')}:{PORT}"

    def start(self):
        self.net.create()
        try:
            self._spawn("scheduler", "head", [PY, "-m", "distributed.cli.dask_scheduler", "--host",
                                              self.net.address("head"), "--port", str(PORT), "--no-dashboard"])
            self.wait_log("scheduler", "Scheduler at", 60)
            for w in self.worker_names:
                self.start_worker(w)
            for w in self.worker_names:
                self.wait_log(w, "Registered to", 60)
        except Exception:
            self.stop()
            raise
        return self

    def start_worker(self, name, tool=TOOL, env=None, bin_dir=BIN):
        self._spawn(name, name, [PY, str(tool), "worker", self.address, "--nthreads", "1", "--no-nanny", "--name", name,
                                 "--bin-dir", str(bin_dir), "--", "--host", self.net.address(name),
                                 "--local-directory", str(self.tmp / f"dask-{name}")], env=env)

    def _spawn(self, name, host, argv, env=None):
        e = dict(os.environ, MFT_EXPERIMENT_SCRATCH=str(self.scratch), **(env or {}))
        with open(self.tmp / f"{name}.log", "w") as logf:
            self.procs[name] = subprocess.Popen(["ip", "netns", "exec", self.net.ns(host)] + argv, stdout=logf,
                                                stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL, env=e,
                                                preexec_fn=_die_with_test)

    def wait_log(self, name, text, timeout_s):
        deadline = time.monotonic() + timeout_s
        path = self.tmp / f"{name}.log"
        while text not in path.read_text(errors="replace"):
            if self.procs[name].poll() is not None or time.monotonic() > deadline:
                raise AssertionError(f"{name} did not log {text!r} within {timeout_s} s "
                                     f"(exit {self.procs[name].poll()}): {path.read_text()[-2000:]}")
            time.sleep(0.2)

    def client(self, *args, wait=True, timeout=900):
        argv = ["ip", "netns", "exec", self.net.ns("head"), PY, str(TOOL)] + [str(a) for a in args]
        if not wait:
            return subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                                    preexec_fn=_die_with_test)
        return subprocess.run(argv, capture_output=True, text=True, timeout=timeout, preexec_fn=_die_with_test)

    def kill(self, name, sig=signal.SIGKILL):
        p = self.procs.get(name)
        if p and p.poll() is None:
            p.send_signal(sig)
            try:
                p.wait(timeout=30)
            except subprocess.TimeoutExpired:
                p.kill()
                p.wait()

    def stop(self):
        try:
            for name in list(self.procs)[::-1]:  # workers before the scheduler
                self.kill(name, signal.SIGTERM)
        finally:
            self.net.destroy()


@unittest.skipUnless(PERMITTED, f"Dask tests skipped: network namespaces are not permitted here ({WHY_NOT})")
class DaskTestBase(unittest.TestCase):
    tag = "dx"

    def setUp(self):
        self.tmp = Path(tempfile.mkdtemp(prefix="mft-dask-test-"))
        self.cluster = Cluster(self.tmp, self.tag).start()

    def tearDown(self):
        try:
            self.cluster.stop()
        finally:
            shutil.rmtree(self.tmp, ignore_errors=True)

    def local_reference(self):
        out = self.tmp / "local"
        t0 = time.monotonic()
        r = self.cluster.client(*SWEEP, "--out", out, "--bin-dir", BIN, "--workers", 2, "--domain-base", 90,
                                "--no-rawlogs", "--json")
        log(f"local reference sweep: {time.monotonic() - t0:.1f} s")
        self.assertEqual(r.returncode, 0, r.stderr[-3000:])
        return out, json.loads(r.stdout)

    def dask_args(self, out):
        return list(SWEEP) + ["--out", out, "--scheduler", self.cluster.address, "--domain-base", 92,
                              "--domain-slots", 2, "--json"]

    def assert_same_study(self, local, dist):
        self.assertEqual(table(dist), table(local))
        self.assertEqual(len(table(local)), 1)
        for c in ("sa", "mft"):
            self.assertTrue(table(local)[0][f"{c}_imax_Ns"], table(local))
        lruns, lkeys, _ = runs_of(local)
        druns, dkeys, drecs = runs_of(dist)
        self.assertEqual(len(dkeys), len(set(dkeys)), f"a run is twice in results.jsonl: {sorted(dkeys)}")
        self.assertEqual(sorted(druns), sorted(lruns), "missing or extra runs")
        for k in lruns:
            self.assertEqual(druns[k], lruns[k], f"run {k}: a different outcome or signature on the workers")
        cells = [r for r in lines(Path(dist) / "results.jsonl") if r["kind"] == "cell"]
        self.assertEqual(sorted(c["controller"] for c in cells), ["mft", "sa"])
        return drecs


class SweepOnDask(DaskTestBase):
    tag = "dxa"

    def test_same_table_as_local_and_build_check(self):
        local, _ = self.local_reference()
        out = self.tmp / "dask"
        t0 = time.monotonic()
        r = self.cluster.client(*self.dask_args(out))
        wall = time.monotonic() - t0
        self.assertEqual(r.returncode, 0, r.stderr[-3000:] + self.worker_logs())
        summary = json.loads(r.stdout)
        log(f"dask sweep (with the boundary rawlogs): {wall:.1f} s; progress {summary['progress']}")
        recs = self.assert_same_study(local, out)
        per_worker = summary["progress"]["per_worker"]
        self.assertEqual(set(per_worker), {"w1", "w2"}, per_worker)  # both workers ran some
        self.assertEqual(sum(per_worker.values()), summary["progress"]["runs_done"])
        self.assertEqual(sum(1 for x in recs if x["worker"] in ("w1", "w2")), len(recs))
        self.assertGreater(summary["progress"]["runs_per_min"], 0)
        self.assertEqual(summary["executor"]["backend"], "dask")
        # the domains the two workers took on this (shared) machine: within the pool, never one at a time twice
        self.assertTrue({x["domain"] for x in recs} <= {92, 93}, {x["domain"] for x in recs})
        cells = [x for x in lines(out / "results.jsonl") if x["kind"] == "cell"]
        for c in cells:  # the boundary rawlogs, recorded on a worker and written here, reproduced their runs
            self.assertEqual(set(c["rawlogs"]), {"recovered", "failed"}, c)
            for p in c["rawlogs"].values():
                self.assertTrue(Path(p).stat().st_size > 10000, p)
                self.assertTrue(str(p).startswith(str(out)), p)
            self.assertTrue(c["deterministic"], c)
        self.assertEqual(processes_mentioning(str(self.cluster.scratch)), [])

        # a worker of another build is refused with a clear error, before any run
        fake = self.tmp / "other-build"
        for rel in ("tools/mft-experiment", "python", "services"):
            shutil.copytree(REPO / rel, fake / rel, ignore=shutil.ignore_patterns("__pycache__"))
        shutil.copytree(REPO / "config", fake / "config")
        (fake / "config" / "wbc.yaml").write_text((REPO / "config" / "wbc.yaml").read_text() + "\n# changed\n")
        self.cluster.kill("w2", signal.SIGTERM)
        self.cluster.start_worker("w2", tool=fake / "tools" / "mft-experiment" / "mft-experiment")
        self.cluster.wait_log("w2", "Registered to", 60)
        r = self.cluster.client(*self.dask_args(self.tmp / "refused"), timeout=300)
        self.assertEqual(r.returncode, 2, r.stderr[-2000:])
        err = r.stderr.strip().splitlines()[-1]
        log(f"the refusal: {err}")
        self.assertIn("refuse", err)
        self.assertIn("its build differs", err)
        self.assertIn("config/ sha256", err)
        self.assertIn("commit", err)
        self.assertNotIn("Traceback", r.stderr)

    def test_run_failing_everywhere_is_an_error_with_logs(self):
        """A run that fails on every worker: tried on each, then one error line naming the run and its logs."""
        broken = self.tmp / "broken-bin"
        broken.mkdir()
        for p in BIN.iterdir():
            (broken / p.name).symlink_to(p)
        (broken / "mft-wbc").unlink()
        (broken / "mft-wbc").write_text("#!/bin/sh\necho 'mft-wbc: broken on purpose by the test' >&2\nexit 3\n")
        (broken / "mft-wbc").chmod(0o755)
        for w in ("w1", "w2"):
            self.cluster.kill(w, signal.SIGTERM)
            self.cluster.start_worker(w, bin_dir=broken)
        for w in ("w1", "w2"):
            self.cluster.wait_log(w, "Registered to", 60)
        out = self.tmp / "failing"
        t0 = time.monotonic()
        r = self.cluster.client(*self.dask_args(out), "--no-rawlogs", timeout=300)
        log(f"failing study: {time.monotonic() - t0:.1f} s, exit {r.returncode}")
        self.assertEqual(r.returncode, 2, r.stderr[-3000:])
        self.assertNotIn("Traceback", r.stderr)
        err = r.stderr.strip().splitlines()[-1]
        log(f"the error: {err}")
        self.assertRegex(err, r"error: run runs/h0\.44-\w+-forward/6\.000 failed on w[12], w[12], w[12]: ", err)
        self.assertIn("w1", err.split(":")[2])
        self.assertIn("w2", err.split(":")[2])
        logs = Path(err.rsplit("logs in ", 1)[1].rstrip(")"))
        text = logs.read_text()
        self.assertEqual(text.count("=== attempt"), 3, text[:2000])
        self.assertIn("broken on purpose", text)
        self.assertEqual([x for x in lines(out / "results.jsonl") if x["kind"] == "run"], [])

    def worker_logs(self):
        return "".join(f"\n--- {n}.log ---\n" + (self.tmp / f"{n}.log").read_text()[-1500:] for n in ("w1", "w2"))


class WorkerKilled(DaskTestBase):
    tag = "dxk"

    def test_killed_worker_loses_only_its_run(self):
        local, _ = self.local_reference()
        out = self.tmp / "dask"
        t0 = time.monotonic()
        p = self.cluster.client(*self.dask_args(out), "--no-rawlogs", wait=False)
        victim = self.cluster.procs["w1"].pid
        results = out / "results.jsonl"
        deadline = time.monotonic() + 300
        while True:  # at least 3 runs on file and w1 in the middle of a stack run
            busy = [(c, cmd) for c, cmd in children(victim) if "mft-supervisor" in cmd] if pid_alive(victim) else []
            done = sum(1 for x in lines(results) if x["kind"] == "run") if results.exists() else 0
            if done >= 3 and busy:
                break
            if p.poll() is not None or time.monotonic() > deadline:
                p.kill()
                self.fail(f"w1 was never busy after 3 runs within 300 s (client exit {p.poll()}, {done} runs)")
            time.sleep(0.05)
        self.cluster.kill("w1")  # SIGKILL, mid-run
        sup_pid, sup_cmd = busy[0]
        m = re.search(r"runs_h([\d.]+)-(\w+)-(\w+)_([\d.]+)\.", sup_cmd)
        self.assertIsNotNone(m, sup_cmd)
        lost = (m.group(2), round(float(m.group(4)), 3))
        log(f"killed w1 (pid {victim}) while it ran {lost} (supervisor {sup_pid}), {done} runs on file, "
            f"{time.monotonic() - t0:.1f} s into the sweep")
        deadline = time.monotonic() + 30  # its stack goes with it (PR_SET_PDEATHSIG)
        while pid_alive(sup_pid) and time.monotonic() < deadline:
            time.sleep(0.1)
        self.assertFalse(pid_alive(sup_pid), "the killed worker's stack is still running")
        stdout, stderr = p.communicate(timeout=900)
        self.assertEqual(p.returncode, 0, stderr[-3000:])
        summary = json.loads(stdout)
        log(f"dask sweep with a worker killed: {time.monotonic() - t0:.1f} s; per worker "
            f"{summary['progress']['per_worker']}")
        recs = self.assert_same_study(local, out)
        by_key = {(x["controller"], round(x["impulse_Ns"], 3)): x for x in recs}
        self.assertIn(lost, by_key, "the run of the killed worker is missing")
        self.assertEqual(by_key[lost]["worker"], "w2", "the killed worker's run was not run again on w2")
        self.assertGreater(summary["progress"]["per_worker"].get("w2", 0), 0)
        self.assertEqual(processes_mentioning(str(self.cluster.scratch)), [])


if __name__ == "__main__":
    unittest.main(verbosity=2)
