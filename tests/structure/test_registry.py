#!/usr/bin/env python3
"""One process registry on the Python side (python/mftstack/registry.py): no other module binds children to their
parent's life or keeps its own registry, and the registry stops what it started."""
import re
import subprocess
import sys
import time
import unittest
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "python"))
from mftstack.registry import ProcessRegistry  # noqa: E402

PYTHON_DIRS = [ROOT / "python", ROOT / "tools", ROOT / "services", ROOT / "scripts"]


class Registry(unittest.TestCase):
    def test_one_registry(self):
        owners = {"prctl": set(), "class ProcessRegistry": set()}
        for d in PYTHON_DIRS:
            for path in d.rglob("*.py"):
                text = path.read_text(errors="replace")
                for what in owners:
                    if re.search(re.escape(what) + r"\b", text):
                        owners[what].add(str(path.relative_to(ROOT)))
        for what, files in owners.items():
            self.assertEqual(files, {"python/mftstack/registry.py"}, what)

    def test_stop_all_ends_what_it_started(self):
        class Stopped(Exception):
            pass
        reg = ProcessRegistry(interrupted=Stopped)
        p = reg.popen(["sleep", "30"])
        t0 = time.monotonic()
        reg.stop_all(grace_s=5.0)
        self.assertIsNotNone(p.poll())
        self.assertLess(time.monotonic() - t0, 5.0)
        with self.assertRaises(Stopped):
            reg.popen(["true"])


if __name__ == "__main__":
    sys.exit(unittest.main())
