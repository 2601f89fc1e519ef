"""The Dask client's unretrieved tornado timeouts are not reported after a study's last line; other unretrieved
exceptions still are (a loaded series found asyncio's 'TimeoutError: Timeout' printed after mft-experiment's error)."""
import subprocess
import sys
import unittest
from pathlib import Path

PYTHON_DIR = Path(__file__).resolve().parents[2] / "python"

# An asyncio future per exception, failed and dropped unretrieved, as tornado's with_timeout leaves its timeouts.
PROGRAM = """
import asyncio, gc, sys
sys.path.insert(0, {python_dir!r})
from mftexp import executor
if {quiet}:
    executor.quiet_unretrieved_timeouts()
    executor.quiet_unretrieved_timeouts()  # twice: still one filter

async def drop(exc):
    fut = asyncio.get_running_loop().create_future()
    fut.set_exception(exc)
    del fut
    gc.collect()

async def main():
    await drop(TimeoutError("Timeout"))
    await drop(ValueError("a real error"))
asyncio.run(main())
import logging
print(sum(type(f).__name__ == "_UnretrievedTimeouts" for f in logging.getLogger("asyncio").filters))
"""


def run(quiet):
    code = PROGRAM.format(python_dir=str(PYTHON_DIR), quiet=quiet)
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)


class UnretrievedTimeouts(unittest.TestCase):
    def test_without_the_filter_both_are_reported(self):
        r = run(False)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("TimeoutError: Timeout", r.stderr)
        self.assertIn("ValueError: a real error", r.stderr)

    def test_the_filter_drops_only_the_timeout(self):
        r = run(True)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertNotIn("TimeoutError", r.stderr)
        self.assertIn("ValueError: a real error", r.stderr)
        self.assertEqual(r.stdout.strip(), "1")


if __name__ == "__main__":
    unittest.main(verbosity=2)
