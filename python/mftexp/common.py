"""Shared pieces: errors, paths, binaries, process handling and progress lines."""
import json
import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

from mftstack.paths import DEFAULT_BIN, DEFAULT_CONFIG, REPO, SUPERVISOR  # noqa: F401 (the tools' one place)
from mftstack.registry import ProcessRegistry

SERVICES = ["mft-sim", "mft-estimator", "mft-planner", "mft-wbc"]

# The paper's Table II (section IV-B): I_max [N s] per reference height, SA-WBC and MFT-WBC.
PAPER_TABLE2 = {
    0.38: {"sa": 10.4, "mft": 10.7, "increase_pct": 2.9},
    0.40: {"sa": 9.7, "mft": 10.6, "increase_pct": 9.3},
    0.42: {"sa": 9.1, "mft": 10.6, "increase_pct": 16.5},
    0.44: {"sa": 7.0, "mft": 9.5, "increase_pct": 35.6},
    0.46: {"sa": 4.5, "mft": 6.6, "increase_pct": 44.4},
}
CONTROLLER_NAMES = {"mft": "MFT-WBC", "sa": "SA-WBC", "none": "no MFT, no SA"}


class ExperimentError(Exception):
    """A problem reported as one clear line (exit status 2), never a traceback."""


class Interrupted(Exception):
    """Ctrl-C or SIGTERM: what finished is kept, the runs in flight are stopped."""


def bounded(convert, lo, hi, message):
    """An argparse type: `convert` (int or float) of the text, within [lo, hi]; else `message` (formatted with
    the value as {v} and the text as {t}) as the argument's error."""
    noun = "an integer" if convert is int else "a number"

    def parse(text):
        import argparse
        try:
            v = convert(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"not {noun}: {text!r}")
        if not lo <= v <= hi:
            raise argparse.ArgumentTypeError(message.format(v=v, t=repr(text)))
        return v
    return parse


def log(msg):
    print(f"mft-experiment: {msg}", file=sys.stderr, flush=True)


def fmt_duration(s):
    s = int(round(max(0.0, s)))
    return f"{s // 60}:{s % 60:02d}" if s < 3600 else f"{s // 3600}:{s % 3600 // 60:02d}:{s % 60:02d}"


def check_setup(bin_dir, config_dir, need=("mft-sim", "mft-estimator", "mft-planner", "mft-wbc")):
    bin_dir, config_dir = Path(bin_dir), Path(config_dir)
    if not SUPERVISOR.is_file():
        raise ExperimentError(f"the supervisor {SUPERVISOR} is missing")
    if not bin_dir.is_dir():
        raise ExperimentError(f"binary folder {bin_dir} does not exist (build first: cmake --build build/release)")
    for name in need:
        p = bin_dir / name
        if not (p.is_file() and os.access(p, os.X_OK)):
            raise ExperimentError(f"{p} is missing or not executable (build first: cmake --build build/release)")
    if not (config_dir / "robot.yaml").is_file():
        raise ExperimentError(f"configuration folder {config_dir} has no robot.yaml")


SNAPSHOT = ("mft-sim", "mft-estimator", "mft-planner", "mft-wbc", "mft-record", "mft-export", "mft-closedloop",
            "mft-participants", "mft-space")  # mft-participants: the supervisor's domain probe; mft-space: eq. (10)


def snapshot_binaries(bin_dir, dest):
    """Copies the services (and the supervisor) into dest once, so that a rebuild of the shared build folder
    during a long experiment can neither break nor change it. Returns the folder to use as --bin-dir."""
    import shutil
    global SUPERVISOR
    dest = Path(dest)
    if (dest / "mft-sim").is_file():  # a snapshot of an earlier version: add what it lacks
        for name in SNAPSHOT:
            if not (dest / name).is_file() and (Path(bin_dir) / name).is_file():
                shutil.copy2(Path(bin_dir) / name, dest / name)
    else:
        _fresh_snapshot(bin_dir, dest)
    # The supervisor's package beside the copied launcher (it looks in ../python first), frozen like the rest.
    package = dest.parent / "python" / "mftstack"
    if not package.is_dir():
        tmp = package.with_name("mftstack.tmp")
        try:
            shutil.rmtree(tmp, ignore_errors=True)
            shutil.copytree(REPO / "python" / "mftstack", tmp, ignore=shutil.ignore_patterns("__pycache__"))
            tmp.rename(package)
        except OSError as e:
            shutil.rmtree(tmp, ignore_errors=True)
            raise ExperimentError(f"cannot copy the supervisor's package into {package}: {e.strerror or e}")
    SUPERVISOR = dest / "mft-supervisor"
    return dest


def _fresh_snapshot(bin_dir, dest):
    """Copies the executables into dest.tmp, then renames it to dest. On a write error (a full disk) the partial
    copy is removed and the error names the folder written, not the file read."""
    import shutil
    tmp = dest.with_name(dest.name + ".tmp")
    try:
        shutil.rmtree(tmp, ignore_errors=True)
        tmp.mkdir(parents=True)
        for name in SNAPSHOT:
            src = Path(bin_dir) / name
            if src.is_file():
                _copy_when_stable(src, tmp / name)
        shutil.copy2(SUPERVISOR, tmp / "mft-supervisor")
        tmp.rename(dest)
    except OSError as e:
        shutil.rmtree(tmp, ignore_errors=True)
        raise ExperimentError(f"cannot copy the executables into {dest}: {e.strerror or e}"
                              f"{' (disk full?)' if getattr(e, 'errno', None) == 28 else ''}")


def _copy_when_stable(src, dst):
    import shutil
    for _ in range(10):  # a file being relinked right now: wait until it is stable
        before = src.stat()
        shutil.copy2(src, dst)
        after = src.stat()
        if (before.st_mtime_ns, before.st_size) == (after.st_mtime_ns, after.st_size) and \
                after.st_mtime_ns < time.time_ns() - 2_000_000_000:
            return
        time.sleep(2.0)


# The supervisors this tool started (and only those), in mftstack's registry: stopped by pid on Ctrl-C or an error;
# a supervisor gets SIGTERM (and stops its stack) when this process dies.
REGISTRY = ProcessRegistry(interrupted=Interrupted, death_signal=signal.SIGTERM)


def where(e):
    """The innermost frame an exception came from, as 'file:line in function' (a one-line error that can be
    traced without MFT_EXPERIMENT_DEBUG; an error raised on a Dask worker carries the worker's frames)."""
    import traceback
    frames = traceback.extract_tb(e.__traceback__)
    if not frames:
        return "no traceback"
    f = frames[-1]
    return f"at {Path(f.filename).name}:{f.lineno} in {f.name}"


def run_workers(worker, count, errors, interrupted_msg=None):
    """Runs worker(i) for i in 0..count-1 on threads and waits for them. Ctrl-C stops every run in flight and
    raises Interrupted; the first error a worker appended to `errors` is raised as an ExperimentError."""
    threads = [threading.Thread(target=worker, args=(i,), daemon=True) for i in range(max(1, count))]
    for t in threads:
        t.start()
    try:
        while any(t.is_alive() for t in threads):
            for t in threads:
                t.join(timeout=0.2)
    except KeyboardInterrupt:
        if interrupted_msg:
            log(interrupted_msg)
        REGISTRY.stop_all()
        for t in threads:
            t.join(timeout=30)
        raise Interrupted()
    if errors:
        e = errors[0]
        if isinstance(e, ExperimentError):
            raise e
        if os.environ.get("MFT_EXPERIMENT_DEBUG"):
            import traceback
            traceback.print_exception(type(e), e, e.__traceback__)
        raise ExperimentError(f"a worker failed: {type(e).__name__}: {e} ({where(e)})")


def write_report(path, report, png, t0, as_json):
    """Completes the report with its figure and wall time, writes it to `path` and prints it when `as_json`."""
    report["plot"] = str(png)
    report["wall_s"] = round(time.monotonic() - t0, 1)
    path.write_text(json.dumps(report, indent=1) + "\n")
    if as_json:
        print(json.dumps(report, indent=1))


def profile_options(profiles):
    """--profile NAME for each configuration profile (config/profiles/, docs/guide/profiles.md), in order."""
    return [a for name in (profiles or []) for a in ("--profile", name)]


# (domain, bin dir, config dir, profiles) of every successful run of this process. The supervisor's checks before
# a run (each service's --check-config and the busy-domain probe, which listens 1 s) cost about 1.2 s, as much as
# half of a push run; a worker owns its domain, so after one checked run the next ones on the same domain and
# configuration skip them (mft-supervisor run --checked-before). A stack started by someone else on that domain
# meanwhile is refused by its own supervisor's probe, which sees ours.
_CHECKED_SETUPS = set()
_CHECKED_LOCK = threading.Lock()


def run_scenario(scenario_path, run_dir, domain, bin_dir, config_dir, record=None, timeout_s=600.0, profiles=()):
    """One lockstep run through the supervisor. Returns (summary dict, wall seconds); raises ExperimentError
    when the stack itself failed (not when the robot fell) and Interrupted when stopping. `profiles` go to
    the supervisor (--profile), which applies them after the scenario's own."""
    argv = [sys.executable, str(SUPERVISOR), "run", str(scenario_path), "--domain", str(domain), "--json",
            "--bin-dir", str(bin_dir), "--config-dir", str(config_dir), "--run-dir", str(run_dir)]
    argv += profile_options(profiles)
    setup = (int(domain), str(bin_dir), str(config_dir), tuple(profiles or ()))
    with _CHECKED_LOCK:
        if setup in _CHECKED_SETUPS:
            argv.append("--checked-before")
    if record:
        argv += ["--record", str(record), "--overwrite"]  # a retried or resumed run replaces its own recording
    env = dict(os.environ, MFT_RUNS_DIR=str(Path(run_dir).parent))
    t0 = time.monotonic()
    p = REGISTRY.popen(argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
    try:
        out, err = p.communicate(timeout=timeout_s)
    except subprocess.TimeoutExpired:
        p.terminate()
        out, err = p.communicate()
        raise ExperimentError(f"run {scenario_path} did not end within {timeout_s:.0f} s (logs in {run_dir})")
    finally:
        REGISTRY.done(p)
    wall = time.monotonic() - t0
    if REGISTRY.stopping.is_set():
        raise Interrupted()
    try:
        summary = json.loads(out)
    except ValueError:
        last = (err.strip().splitlines() or ["no output"])[-1]
        raise ExperimentError(f"supervisor failed on {scenario_path} (status {p.returncode}): {last}")
    if not summary.get("ok"):
        raise ExperimentError(f"stack failed on {scenario_path}: {summary.get('error') or summary.get('failed')} "
                              f"(logs in {run_dir})")
    with _CHECKED_LOCK:
        _CHECKED_SETUPS.add(setup)
    sim = (summary.get("services") or {}).get("mft-sim") or {}
    if "verdict" not in (sim.get("recovery") or {}):
        raise ExperimentError("mft-sim's summary has no 'recovery' section: rebuild mft-sim "
                              "(cmake --build build/release --target mft-sim)")
    return summary, wall


def tool_reason(stderr):
    """The reason a tool printed: its last line other than the "Try 'TOOL --help'." hint after a usage error."""
    lines = [l for l in stderr.strip().splitlines() if l.strip() and not l.startswith("Try '")]
    return lines[-1] if lines else "no output"


def run_closedloop(scenario_path, bin_dir, config_dir, timeout_s=600.0, profiles=()):
    """One run of the in-process loop (mft-closedloop --scenario, same configs, profiles and recovery verdict as
    the stack). Returns (a dict shaped like mft-sim's summary: fell, fall_time_s, fall_reason, recovery, ...;
    wall seconds)."""
    argv = [str(Path(bin_dir) / "mft-closedloop"), "--scenario", str(scenario_path), "--config-dir", str(config_dir),
            "--json"] + profile_options(profiles)
    t0 = time.monotonic()
    p = REGISTRY.popen(argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        out, err = p.communicate(timeout=timeout_s)
    except subprocess.TimeoutExpired:
        p.kill()
        p.communicate()
        raise ExperimentError(f"mft-closedloop on {scenario_path} did not end within {timeout_s:.0f} s")
    finally:
        REGISTRY.done(p)
    if REGISTRY.stopping.is_set():
        raise Interrupted()
    if p.returncode not in (0, 1):
        raise ExperimentError(f"mft-closedloop failed on {scenario_path} (status {p.returncode}): {tool_reason(err)}")
    try:
        d = json.loads(out)
    except ValueError:
        raise ExperimentError(f"mft-closedloop printed no JSON for {scenario_path}")
    s = d["summary"]
    sim = {"fell": s["fell"], "fall_time_s": s["fall_time_s"] if s["fell"] else None,
           "fall_reason": s["fall_reason"] or None, "ticks": s["ticks"], "sim_time_s": s["sim_time_s"],
           "recovery": d["recovery"], "profiles": (d.get("scenario") or {}).get("profiles"),
           "max_base_x_m": s.get("max_base_x_m"), "first_body_contact": s.get("first_body_contact"),
           "mean_base_z_m": s.get("mean_base_z_m")}  # over the window from --stats-from (2 s) to the end or the fall
    return sim, time.monotonic() - t0


def write_yaml_scenario(path, s):
    """Writes a scenario dict in the flow style of config/scenarios (no yaml dependency needed)."""
    def v(x):
        if isinstance(x, bool):
            return "true" if x else "false"
        if isinstance(x, float):
            return repr(round(x, 6))
        if isinstance(x, int):
            return str(x)  # a plain number: a quoted one is text, which the strict loader refuses for a number
        if isinstance(x, str) and x.replace("_", "").replace("-", "").replace(".", "").isalnum():
            return x
        return json.dumps(str(x))  # a JSON string is a valid YAML double-quoted scalar
    lines = ["# generated by mft-experiment", "schema_version: 1"]
    for k in ("name", "description", "duration_s", "controller", "estimator", "terrain", "initial_base_height_m"):
        lines.append(f"{k}: {v(s[k])}")
    for section in ("fall", "recovery"):
        if section in s:
            lines.append(f"{section}:")
            for k, x in s[section].items():
                lines.append(f"  {k}: {v(x)}")
    lines.append("commands:")
    for c in s["commands"]:
        lines.append("  - {" + ", ".join(f"{k}: {v(x)}" for k, x in c.items()) + "}")
    if s.get("pushes"):
        lines.append("pushes:")
        for c in s["pushes"]:
            lines.append("  - {" + ", ".join(f"{k}: {v(x)}" for k, x in c.items()) + "}")
    Path(path).write_text("\n".join(lines) + "\n")


def check_scenario(bin_dir, config_dir, path, profiles=()):
    p = subprocess.run([str(Path(bin_dir) / "mft-sim"), "--check-scenario", str(path), "--config-dir", str(config_dir),
                        "--json"] + profile_options(profiles), capture_output=True, text=True, timeout=60)
    if p.returncode != 0:
        raise ExperimentError(f"generated scenario {path} is invalid: {(p.stderr or p.stdout).strip()}")


def export_csv(bin_dir, rawlog, out_dir, labels):
    p = subprocess.run([str(Path(bin_dir) / "mft-export"), str(rawlog), "--csv", str(out_dir), "--labels",
                        ",".join(labels)], capture_output=True, text=True, timeout=600)
    if p.returncode not in (0,):
        raise ExperimentError(f"mft-export failed on {rawlog}: {(p.stderr or p.stdout).strip()[-300:]}")


def load_yaml(path):
    try:
        import yaml
    except ImportError:
        raise ExperimentError("python3-yaml is missing (Debian: apt-get install python3-yaml)")
    try:
        return yaml.safe_load(Path(path).read_text())
    except (OSError, yaml.YAMLError) as e:
        raise ExperimentError(f"cannot read {path}: {e}")


def load_text():
    """The load average (1, 5, 15 min) as text for the reports."""
    try:
        return " ".join(Path("/proc/loadavg").read_text().split()[:3])
    except OSError:
        return "unknown"


def read_csv(path):
    """A numeric CSV of mft-export as {column: list of floats}."""
    import csv
    with open(path) as f:
        r = csv.reader(f)
        header = next(r)
        cols = {h: [] for h in header}
        for row in r:
            for h, x in zip(header, row):
                cols[h].append(float(x))
    return cols


class Progress:
    """Progress on stderr: runs done of the estimated total, runs per minute, the time left and how many runs
    each worker (a local domain or a Dask worker) did; snapshot() gives the same figures for --json."""

    def __init__(self, workers, quiet=False, every_s=60.0):
        self.workers = max(1, workers)
        self.quiet = quiet
        self.lock = threading.Lock()
        self.t0 = time.monotonic()
        self.walls = []
        self.runs_done = 0
        self.remaining = None
        self.per_worker = {}
        self.every_s = every_s  # a per-worker line at most this often
        self._last_workers_line = self.t0

    def _rate_and_eta(self, remaining):
        elapsed = time.monotonic() - self.t0
        rate = self.runs_done / (elapsed / 60.0) if elapsed > 0 and self.runs_done else None
        if rate and self.runs_done >= self.workers:  # the observed pace, once every worker finished about one run
            eta = remaining / rate * 60.0
        else:
            eta = remaining * (sum(self.walls) / len(self.walls)) / self.workers if self.walls else None
        return elapsed, rate, eta

    def run_finished(self, wall_s, text, remaining_runs, worker=None):
        with self.lock:
            self.walls.append(wall_s)
            self.runs_done += 1
            self.remaining = remaining_runs
            if worker:
                self.per_worker[worker] = self.per_worker.get(worker, 0) + 1
            elapsed, rate, eta = self._rate_and_eta(remaining_runs)
            if not self.quiet:
                total = self.runs_done + int(round(remaining_runs))
                print(f"[{fmt_duration(elapsed)} elapsed, ~{fmt_duration(eta or 0)} left, {self.runs_done}/~{total} runs, "
                      f"{rate or 0:.1f} runs/min] {text}", file=sys.stderr, flush=True)
                now = time.monotonic()
                if len(self.per_worker) > 1 and now - self._last_workers_line >= self.every_s:
                    self._last_workers_line = now
                    print(f"[{fmt_duration(elapsed)}] runs per worker: {self.workers_text()}", file=sys.stderr,
                          flush=True)

    def workers_text(self):
        return ", ".join(f"{w} {n}" for w, n in sorted(self.per_worker.items()))

    def snapshot(self):
        """{"runs_done", "runs_total_estimate", "runs_per_min", "eta_s", "elapsed_s", "per_worker"}."""
        with self.lock:
            remaining = self.remaining or 0.0
            elapsed, rate, eta = self._rate_and_eta(remaining)
            return {"runs_done": self.runs_done, "runs_total_estimate": self.runs_done + int(round(remaining)),
                    "runs_per_min": None if rate is None else round(rate, 2),
                    "eta_s": None if eta is None else round(eta, 1), "elapsed_s": round(elapsed, 1),
                    "per_worker": dict(sorted(self.per_worker.items()))}

    def note(self, text):
        if not self.quiet:
            with self.lock:
                print(f"[{fmt_duration(time.monotonic() - self.t0)}] {text}", file=sys.stderr, flush=True)


def pyplot():
    """matplotlib's pyplot (Agg), or a clear error."""
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        raise ExperimentError(f"matplotlib is missing for {sys.executable} (Debian: apt-get install python3-matplotlib; "
                              f"run with /usr/bin/python3)")
    return plt
