#!/usr/bin/env python3
"""mft-experiment skips the supervisor's checks before a run (service configs, the 1 s busy-domain probe) only
when the same worker domain already ran a successful checked run with the same executables, configuration and
profiles (mftexp.common.run_scenario, `mft-supervisor run --checked-before`). A stand-in supervisor records the
arguments it was given; no stack runs."""
import json
import os
import sys
import tempfile
import unittest
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "python"))
from mftexp import common  # noqa: E402

FAKE_SUPERVISOR = r'''
import json, os, sys
with open(os.environ["FAKE_ARGV_LOG"], "a") as f:
    f.write(json.dumps(sys.argv[1:]) + "\n")
ok = os.environ.get("FAKE_OK", "1") == "1"
print(json.dumps({"ok": ok, "error": None if ok else "mft-sim exited with status 1",
                  "services": {"mft-sim": {"recovery": {"verdict": True}}}}))
'''


class CheckedBeforeTest(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory(prefix="mft-test-run-checks-")
        self.dir = Path(self.tmp.name)
        (self.dir / "supervisor.py").write_text(FAKE_SUPERVISOR)
        self.argv_log = self.dir / "argv.jsonl"
        self.saved = (common.SUPERVISOR, dict(os.environ))
        common.SUPERVISOR = self.dir / "supervisor.py"
        os.environ["FAKE_ARGV_LOG"] = str(self.argv_log)
        common._CHECKED_SETUPS.clear()

    def tearDown(self):
        common.SUPERVISOR = self.saved[0]
        os.environ.clear()
        os.environ.update(self.saved[1])
        common._CHECKED_SETUPS.clear()
        self.tmp.cleanup()

    def run_once(self, domain=90, profiles=(), ok=True):
        os.environ["FAKE_OK"] = "1" if ok else "0"
        try:
            common.run_scenario(self.dir / "s.yaml", self.dir / "run", domain, self.dir / "bin", self.dir / "cfg",
                                profiles=profiles)
        except common.ExperimentError:
            self.assertFalse(ok, "a successful fake run raised")
        return json.loads(self.argv_log.read_text().splitlines()[-1])

    def test_only_after_a_successful_run_of_the_same_setup(self):
        self.assertNotIn("--checked-before", self.run_once())
        self.assertIn("--checked-before", self.run_once())
        self.assertIn("--checked-before", self.run_once())

    def test_another_domain_or_profile_set_is_checked_again(self):
        self.run_once(domain=90)
        self.assertNotIn("--checked-before", self.run_once(domain=91))
        self.assertNotIn("--checked-before", self.run_once(domain=90, profiles=("slack-1e5",)))
        self.assertIn("--checked-before", self.run_once(domain=90, profiles=("slack-1e5",)))
        self.assertNotIn("--checked-before", self.run_once(domain=90, profiles=("slack-1e5", "actuator-sea")))

    def test_a_failed_run_does_not_count_as_checked(self):
        self.assertNotIn("--checked-before", self.run_once(ok=False))
        self.assertNotIn("--checked-before", self.run_once(ok=True))
        self.assertIn("--checked-before", self.run_once(ok=True))


class WorkerFailureTest(unittest.TestCase):
    """A worker thread's unexpected exception reaches the user as one line that says where it was raised."""

    def test_the_error_names_its_file_line_and_function(self):
        errors = []

        def worker(_):
            try:
                None.get("x")  # the AttributeError of an unexplained CI failure, raised here on purpose
            except AttributeError as e:
                errors.append(e)
        with self.assertRaises(common.ExperimentError) as ctx:
            common.run_workers(worker, 2, errors)
        msg = str(ctx.exception)
        self.assertIn("a worker failed: AttributeError", msg)
        self.assertRegex(msg, r"at test_run_checks\.py:\d+ in worker\)$")


if __name__ == "__main__":
    unittest.main(verbosity=2)
