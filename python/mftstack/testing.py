"""The one helper the multi-process tests run stacks with (docs/guide/testing.md "Running a stack in a test").

StackRunner starts services/mft-supervisor the way a user does, in a temporary folder with a runs folder of its
own (MFT_RUNS_DIR: state files and logs never meet another test's), and close() ends whatever it started,
even after a failure: every `up` stack through the supervisor's `down` (by the pids in its state file), every
supervisor process by its pid (SIGTERM, then SIGKILL; its services die with it, PR_SET_PDEATHSIG)."""
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
import unittest
from pathlib import Path

from .paths import DEFAULT_BIN as BIN
from .paths import DEFAULT_CONFIG as CONFIG
from .paths import REPO, SCENARIOS, SUPERVISOR

__all__ = ["BIN", "CONFIG", "REPO", "SCENARIOS", "SUPERVISOR", "StackRunner", "StackTestCase", "StackUpTestCase", "mft_cmd",
           "child_processes", "pid_alive", "processes_mentioning"]


def mft_cmd(domain, *args, timeout=60):
    """Runs mft-cmd --json on `domain`; returns (exit code, parsed JSON or None, stderr, wall seconds)."""
    t0 = time.monotonic()
    p = subprocess.run([str(BIN / "mft-cmd"), "--domain", str(domain), "--json"] + [str(a) for a in args],
                       capture_output=True, text=True, timeout=timeout)
    try:
        result = json.loads(p.stdout)
    except ValueError:
        result = None
    return p.returncode, result, p.stderr, time.monotonic() - t0


def child_processes(ppid):
    """[(pid, comm, state, command line)] of the children of ppid, from /proc (those that vanish while being read
    are left out)."""
    out = []
    for d in Path("/proc").iterdir():
        if not d.name.isdigit():
            continue
        try:
            stat = (d / "stat").read_text()
            fields = stat[stat.rindex(")") + 2:].split()
            if int(fields[1]) == ppid:
                cmd = (d / "cmdline").read_bytes().replace(b"\0", b" ").decode(errors="replace")
                out.append((int(d.name), stat[stat.index("(") + 1:stat.rindex(")")], fields[0], cmd))
        except (OSError, ValueError, IndexError):
            continue
    return out


def processes_mentioning(text):
    """[(pid, command line)] of the processes whose command line mentions text (a test's own folders): what a
    test left running."""
    found = []
    for p in Path("/proc").iterdir():
        if not p.name.isdigit() or int(p.name) == os.getpid():
            continue
        try:
            cmd = (p / "cmdline").read_bytes().replace(b"\0", b" ").decode(errors="replace")
        except OSError:
            continue
        if text in cmd:
            found.append((int(p.name), cmd[:200]))
    return found


def pid_alive(pid):
    """True while process pid runs; a zombie counts as dead (its parent has not reaped it yet)."""
    try:
        os.kill(pid, 0)
        return Path(f"/proc/{pid}/stat").read_text().split()[2] != "Z"
    except (OSError, IndexError):
        return False


class StackRunner:
    """mft-supervisor for a test: `run`, `up`, `status`, `down`, with the built executables (--bin-dir, and
    --config-dir when given) added to `run` and `up`, and cleanup by close()."""

    def __init__(self, prefix="mft-test-", bin_dir=BIN, config_dir=None):
        self.path = Path(tempfile.mkdtemp(prefix=prefix))
        self.env = dict(os.environ, MFT_RUNS_DIR=str(self.path / "runs"))
        self.bin_dir, self.config_dir = bin_dir, config_dir
        self.procs = []
        self.up_domains = []  # domain, or (domain, host) for `up --host`

    def command(self, *args):
        cmd = [sys.executable, str(SUPERVISOR)] + [str(a) for a in args]
        if args[0] in ("run", "up"):
            cmd += ["--bin-dir", str(self.bin_dir)]
            cmd += ["--config-dir", str(self.config_dir)] if self.config_dir else []
        if args[0] == "up":  # a test killed by CTest's timeout leaves no stack behind
            cmd += ["--watch-pid", str(os.getpid())]
        return cmd

    def start(self, *args, env=None):
        """The supervisor in the background (stdout, stderr: pipes of text); ended by close() if still running."""
        p = subprocess.Popen(self.command(*args), env=env or self.env, stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, text=True)
        self.procs.append(p)
        return p

    def supervisor(self, *args, env=None, timeout=240):
        """The supervisor to its end: (exit status, stdout, stderr)."""
        p = self.start(*args, env=env)
        out, err = p.communicate(timeout=timeout)
        return p.returncode, out, err

    def run_json(self, scenario, domain, *extra, run_dir=None, timeout=240, env=None):
        """`run SCENARIO --domain D --json` (scenario: a file name in config/scenarios or a path), in run_dir
        (default <tmp>/run-<domain>-<n>); returns (exit status, summary, stderr)."""
        return self.finish(self.start_run(scenario, domain, *extra, run_dir=run_dir, env=env), timeout)

    def start_run(self, scenario, domain, *extra, run_dir=None, env=None):
        run_dir = run_dir or self.path / f"run-{domain}-{len(self.procs)}"
        p = self.start("run", SCENARIOS / scenario, "--domain", domain, "--json", "--run-dir", run_dir, *extra, env=env)
        p.run_dir = Path(run_dir)
        return p

    @staticmethod
    def finish(p, timeout=240):
        """Waits for a `run --json` started by start_run; (exit status, summary, stderr)."""
        out, err = p.communicate(timeout=timeout)
        try:
            return p.returncode, json.loads(out), err
        except ValueError:
            raise AssertionError(f"no JSON summary (exit {p.returncode}): {err[-3000:]}")

    def up(self, scenario, domain, *extra, host=None, timeout=120):
        """`up` in the background, taken down by close(); returns its status (`status --json`)."""
        self.up_domains.append((domain, host) if host else domain)
        where = ["--host", host] if host else []
        code, out, err = self.supervisor("up", SCENARIOS / scenario, "--domain", domain, *where, *extra,
                                         timeout=timeout)
        if code != 0:
            log = self.path / "runs" / (f"supervisor-d{domain}-{host}.log" if host else f"supervisor-d{domain}.log")
            raise AssertionError(f"mft-supervisor up failed (exit {code}): {err[-3000:]}"
                                 + (f"\n{log}:\n{log.read_text(errors='replace')[-3000:]}" if log.exists() else ""))
        return self.status(domain, host)

    def status(self, domain, host=None):
        code, out, err = self.supervisor("status", "--domain", domain, *(["--host", host] if host else []),
                                         "--json", timeout=30)
        try:
            return json.loads(out)
        except ValueError:
            raise AssertionError(f"mft-supervisor status printed no JSON (exit {code}): {err[-2000:]}")

    def down(self, domain, status=None, names=("mft-sim", "mft-wbc", "mft-estimator", "mft-planner"), host=None,
             timeout=90):
        """`down`; returns {service: its summary} of `names` from the run folder of `status` (those written)."""
        code, out, err = self.supervisor("down", "--domain", domain, *(["--host", host] if host else []),
                                         timeout=timeout)
        self.up_domains.remove((domain, host) if host else domain)
        if code != 0:
            raise AssertionError(f"mft-supervisor down failed (exit {code}): {err[-2000:]}")
        if status is None:
            return {}
        run_dir = Path(status["run_dir"])
        return {n: json.loads((run_dir / f"{n}.summary.json").read_text()) for n in names
                if (run_dir / f"{n}.summary.json").exists()}

    def down_all(self):
        """`down` of every stack still up (a test that failed before its own `down`), whatever it answers."""
        for d in self.up_domains:
            host = ["--host", d[1]] if isinstance(d, tuple) else []
            subprocess.run(self.command("down", "--domain", d[0] if host else d, *host), env=self.env,
                           capture_output=True, timeout=90)
        self.up_domains = []

    def close(self):
        self.down_all()
        self.stop_processes()
        shutil.rmtree(self.path, ignore_errors=True)

    def stop_processes(self):
        """Ends every process in self.procs still running (the supervisor stops its children first)."""
        for p in self.procs:
            if p.poll() is None:
                p.terminate()  # the supervisor stops its children (and they die with it: PDEATHSIG)
                try:
                    p.wait(timeout=30)
                except subprocess.TimeoutExpired:
                    p.kill()
                    p.wait()

    def wait_for_text(self, path, text, timeout=60):
        """Until `text` is in file `path` (a service log); fails with what was waited for."""
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if Path(path).exists() and text in Path(path).read_text(errors="replace"):
                return
            time.sleep(0.02)
        raise AssertionError(f"'{text}' not in {path} within {timeout} s")


class StackTestCase(unittest.TestCase):
    """A test case with a StackRunner per test: self.stacks, self.tmp its folder; closed after tearDown
    whatever happened (a tearDown that needs it closed earlier calls self.stacks.close(): it may run twice)."""

    tmp_prefix = "mft-test-"

    def setUp(self):
        self.stacks = StackRunner(prefix=self.tmp_prefix)
        self.tmp = self.stacks.path
        self.addCleanup(self.stacks.close)


class StackUpTestCase(unittest.TestCase):
    """One stack `up` for all tests of the class (class attributes: stack_scenario, stack_domain, stack_args, and
    tmp_prefix), taken down after the last. A failed `up` fails every test with its message instead of erroring
    the class; cls.stacks, cls.run_dir (when stack_run_dir) and cls.status are set for the tests."""

    tmp_prefix = "mft-test-"
    stack_scenario = "step-in-place.yaml"
    stack_domain = None
    stack_args = ("--mode", "realtime")
    stack_run_dir = False  # True: the run folder is <tmp>/run (cls.run_dir)

    @classmethod
    def setUpClass(cls):
        cls.stacks = StackRunner(prefix=cls.tmp_prefix)
        cls.run_dir = cls.stacks.path / "run" if cls.stack_run_dir else None
        cls.status, cls.up_error = None, None
        try:
            cls.status = cls.stacks.up(cls.stack_scenario, cls.stack_domain, *cls.stack_up_args(),
                                       *(["--run-dir", cls.run_dir] if cls.run_dir else []), timeout=180)
        except AssertionError as e:
            cls.up_error = str(e)

    @classmethod
    def stack_up_args(cls):
        """The options of `up` after scenario and domain (stack_args; a class may add paths under cls.stacks)."""
        return cls.stack_args

    @classmethod
    def tearDownClass(cls):
        cls.stacks.close()

    def setUp(self):
        if self.up_error:
            self.fail(self.up_error)
