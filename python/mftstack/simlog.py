"""Waiting on a running realtime stack through its simulator's log (run folder/mft-sim.log), for the
multi-process tests: each wait is for the condition a test needs, bounded, and fails with what it saw.

mft-sim prints (services/sim/):
  "mft-sim: the chain answered tick 0: the clock starts"
  "mft-sim: t = 3.0 s, 1.00x real time, base z 0.4001 m"                    every 1000 ticks
  "mft-sim: a tick waited 3.2 ms for its command: actuators damping (t = 4.123 s)"
  "mft-sim: commands resumed after 201.0 ms of damping (t = 4.324 s)"
A sleep of fixed length is no such condition: on a loaded machine the stack may not have started its clock,
or not recovered, when it ends."""
import os
import re
import time
from pathlib import Path

CLOCK_STARTED = "the chain answered tick 0: the clock starts"
_EVENT = re.compile(r"^mft-sim: (?:t = (?P<progress>[0-9.]+) s, .*base z (?P<z>[-0-9.e]+) m"
                    r"|a tick waited .*actuators damping \(t = (?P<onset>[0-9.]+) s\)"
                    r"|commands resumed after .* \(t = (?P<resumed>[0-9.]+) s\))\s*$", re.M)


class SimLog:
    def __init__(self, path):
        self.path = Path(path)

    def text(self):
        try:
            return self.path.read_text(errors="replace")
        except OSError:
            return ""

    def events(self):
        """[(kind, sim time s, base z or None)] in log order; kind: progress, onset or resumed."""
        out = []
        for m in _EVENT.finditer(self.text()):
            if m.group("progress") is not None:
                out.append(("progress", float(m.group("progress")), float(m.group("z"))))
            elif m.group("onset") is not None:
                out.append(("onset", float(m.group("onset")), None))
            else:
                out.append(("resumed", float(m.group("resumed")), None))
        return out

    def sim_time(self):
        """The newest sim time the log shows (progress, onset or resume), 0 once the clock started, else None."""
        ev = self.events()
        if ev:
            return max(t for _, t, _ in ev)
        return 0.0 if CLOCK_STARTED in self.text() else None

    def wait_for(self, condition, timeout, what):
        """Polls condition() every 20 ms until it is true; fails the test with `what` and the log's tail."""
        deadline = time.monotonic() + timeout
        while True:
            value = condition()
            if value:
                return value
            if time.monotonic() > deadline:
                tail = "\n".join(self.text().splitlines()[-12:])
                raise AssertionError(f"{what}: not seen within {timeout:g} s in {self.path}; its last lines:\n{tail}")
            time.sleep(0.02)

    def wait_for_sim_time(self, t_s, timeout=60):
        """Until the simulator's clock has reached t_s (to the 1 s progress line at or after it)."""
        return self.wait_for(lambda: (self.sim_time() or 0.0) >= t_s - 1e-9 and self.sim_time(), timeout,
                             f"the simulator's clock at {t_s:g} s")

    def commands_flowing_since(self, after_s, seconds=1.0, base_z=None, z_tol=None):
        """The sim time at the end of the first stretch of at least `seconds` (between progress lines) after
        sim time after_s in which the actuators never damped (commands arrived in time on every tick), and,
        if base_z is given, the base height was within z_tol of it at the stretch's end; None if none yet."""
        damping, start = False, None
        for kind, t, z in self.events():
            if kind == "onset":
                damping, start = True, None
            elif kind == "resumed":
                damping = False
            elif not damping and t >= after_s - 1e-9:
                if start is not None and t - start >= seconds - 1e-6 and \
                        (base_z is None or abs(z - base_z) <= z_tol):
                    return t
                if start is None:
                    start = t
        return None

    def wait_for_commands_flowing(self, after_s, timeout, seconds=1.0, base_z=None, z_tol=None):
        what = f"{seconds:g} s of sim time without damping after t = {after_s:.3f} s"
        if base_z is not None:
            what += f", ending with the base within {z_tol * 100:g} cm of {base_z:g} m"
        return self.wait_for(lambda: self.commands_flowing_since(after_s, seconds, base_z, z_tol), timeout, what)


class fifo_priority:
    """Runs a block at SCHED_FIFO 85, above the realtime stack's 80, where permitted: a fault (a SIGSTOP, a cut)
    timed by a normal-priority sleep lasts longer than asked on a busy machine (tens of ms, once 1.2 s:
    docs/guide/distributed.md)."""

    def __init__(self, priority=85):
        self.priority = priority
        self.saved = None

    def __enter__(self):
        try:
            self.saved = (os.sched_getscheduler(0), os.sched_getparam(0))
            os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param(self.priority))
        except (OSError, AttributeError):
            self.saved = None
        return self

    def __exit__(self, *exc):
        if self.saved:
            try:
                os.sched_setscheduler(0, *self.saved)
            except OSError:
                pass


# CFS weight of nice -10 against nice 0 (the kernel's table: 9548 / 1024): ~9.3 times the share of CPU of a
# normal task. The test, the supervisor and the helpers it starts (Python processes, mft-inject, status, down)
# run at normal priority otherwise, and with the other core busy and ~12 compilers of other users runnable
# they got ~1/12 of a core each: `mft-supervisor status` took over 30 s, and 4 Python fake services did not
# start within 20 s. The services of a realtime stack run at SCHED_FIFO 80 themselves (--rt).
TEST_NICE = -10


def reserve_cpu_share():
    """Raises this test process (and all it starts, which inherit it) to nice TEST_NICE where permitted (root);
    returns the nice value in effect. Called once at the start of each multi-process test."""
    try:
        current = os.nice(0)
        if current > TEST_NICE:
            os.nice(TEST_NICE - current)
    except OSError:
        pass
    return os.nice(0)


# The test's own DDS participants (mft-inject: a listener that must keep up with 1 kHz topics, an attacker that
# must answer every tick) run at SCHED_FIFO 79: just below the stack's services (80, --rt), so they never delay
# the stack, and above every normal task, so that what they count does not depend on the machine's load
# (measured at load average 24 with a busy core and nice -10: a secured listener got 45 % of the ticks, with
# 300 ms gaps).
HELPER_FIFO_PRIORITY = 79
_helper_prefix = None


def helper_realtime_prefix():
    """["chrt", "-f", "79"] where SCHED_FIFO is permitted (root), else [] (then the counts depend on the load)."""
    global _helper_prefix
    if _helper_prefix is None:
        import subprocess
        cmd = ["chrt", "-f", str(HELPER_FIFO_PRIORITY)]
        try:
            ok = subprocess.run(cmd + ["true"], capture_output=True, timeout=30).returncode == 0
        except (OSError, subprocess.SubprocessError):
            ok = False
        _helper_prefix = cmd if ok else []
    return list(_helper_prefix)


def run_tests():
    """unittest.main for a multi-process test: reserves its CPU share, and prints each failure's traceback as
    it happens (CTest kills a test past its TIMEOUT before unittest prints them at the end)."""
    import unittest

    class ImmediateResult(unittest.TextTestResult):
        def addFailure(self, test, err):
            super().addFailure(test, err)
            self.stream.writeln(f"\nFAIL {test.id()}:\n{self.failures[-1][1]}")
            self.stream.flush()

        def addError(self, test, err):
            super().addError(test, err)
            self.stream.writeln(f"\nERROR {test.id()}:\n{self.errors[-1][1]}")
            self.stream.flush()

    reserve_cpu_share()
    unittest.main(verbosity=2, testRunner=unittest.TextTestRunner(resultclass=ImmediateResult, verbosity=2))
