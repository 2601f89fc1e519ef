"""One run of a study, wherever it happens: the task as data, its execution (`execute`, the one implementation on
both backends), the errors a remote run reports and the build identity a worker is checked against. The local
executor and a Dask worker (mftexp.worker) both use it; neither imports the other through it."""
import hashlib
import subprocess
import threading
import time
from pathlib import Path

from .common import (REGISTRY, REPO, ExperimentError, check_scenario, log, run_closedloop, run_scenario,
                     write_yaml_scenario)

# The configuration files a run reads (services and supervisor), shipped with every Dask task (about 40 kB).
CONFIG_GLOBS = ("*.yaml", "*.xml", "terrain/*.yaml", "profiles/*.yaml")


class RunFailed(Exception):
    """A run that failed on a worker: the message, the worker and the tails of its logs."""

    def __init__(self, message, worker="", logs="", address=""):
        super().__init__(message, worker, logs, address)
        self.message, self.worker, self.logs, self.address = message, worker, logs, address

    def __str__(self):
        return self.message


class BuildMismatch(Exception):
    """A worker whose build (commit, configuration) is not the client's: it refuses to run."""

    def __init__(self, message, worker=""):
        super().__init__(message, worker)
        self.message, self.worker = message, worker

    def __str__(self):
        return self.message


# ------------------------------------------------------------------------------------------------ the build
def config_files(config_dir):
    """{relative path: text} of the configuration files a run reads, in a fixed order."""
    root = Path(config_dir)
    names = sorted({p for g in CONFIG_GLOBS for p in root.glob(g) if p.is_file()})
    return {str(p.relative_to(root)): p.read_text() for p in names}


def files_sha256(files):
    h = hashlib.sha256()
    for name in sorted(files):
        h.update(name.encode() + b"\0" + files[name].encode() + b"\0")
    return h.hexdigest()


def _git(*args):
    try:
        p = subprocess.run(["git", "-C", str(REPO)] + list(args), capture_output=True, text=True, timeout=30)
    except (OSError, subprocess.TimeoutExpired):
        return None
    return p.stdout if p.returncode == 0 else None


_IDENTITY = None


def build_identity():
    """What a worker must share with the client: the commit of this source tree, a digest of its uncommitted
    changes to the sources the stack is built and run from (none: a clean tree), and the sha256 of its own
    config/ (the files CONFIG_GLOBS names)."""
    global _IDENTITY
    if _IDENTITY is None:
        commit = (_git("rev-parse", "HEAD") or "").strip() or "unknown (not a git clone)"
        diff = _git("diff", "HEAD", "--", ".", ":(exclude)docs", ":(exclude)*.md", ":(exclude)tests")
        _IDENTITY = {"commit": commit,
                     "uncommitted": hashlib.sha256(diff.encode()).hexdigest()[:16] if diff else None,
                     "config_sha256": files_sha256(config_files(REPO / "config"))}
    return dict(_IDENTITY)


def identity_difference(mine, theirs):
    """One line saying how two build identities differ, or None when they match."""
    def short(commit):
        return commit[:12] if all(c in "0123456789abcdef" for c in commit) else commit
    parts = []
    if mine["commit"] != theirs["commit"]:
        parts.append(f"commit {short(mine['commit'])} (client {short(theirs['commit'])})")
    if mine["uncommitted"] != theirs["uncommitted"]:
        parts.append(f"uncommitted changes {mine['uncommitted'] or 'none'} (client {theirs['uncommitted'] or 'none'})")
    if mine["config_sha256"] != theirs["config_sha256"]:
        parts.append(f"config/ sha256 {mine['config_sha256'][:12]} (client {theirs['config_sha256'][:12]})")
    return "; ".join(parts) or None


# --------------------------------------------------------------------------------------------------- a run
def run_task(name, scenario, profiles, timeout_s, inprocess=False, record=False):
    """A run as data: `name` is unique in its study (cell/impulse[-rec]), `scenario` a scenario dict."""
    return {"name": name, "scenario": scenario, "profiles": list(profiles or []), "timeout_s": float(timeout_s),
            "inprocess": bool(inprocess), "record": bool(record)}


_CHECKED_SCENARIOS = set()
_CHECKED_LOCK = threading.Lock()


def execute(task, run_dir, domain, bin_dir, config_dir, record_path=None, attempts=1):
    """Runs one task: writes its scenario into run_dir, checks it once per (binaries, configuration, profiles)
    in this process, runs it (the stack on `domain`, or mft-closedloop) up to `attempts` times.
    Returns (mft-sim-like summary, wall seconds); raises ExperimentError when the stack itself failed."""
    run_dir = Path(run_dir)
    run_dir.mkdir(parents=True, exist_ok=True)
    scen = run_dir / "scenario.yaml"
    write_yaml_scenario(scen, task["scenario"])
    profiles = task["profiles"]
    key = (str(bin_dir), str(config_dir), tuple(profiles))
    with _CHECKED_LOCK:
        checked = key in _CHECKED_SCENARIOS
    if not checked:
        check_scenario(bin_dir, config_dir, scen, profiles=profiles)
        with _CHECKED_LOCK:
            _CHECKED_SCENARIOS.add(key)
    if task["inprocess"] and not record_path:
        return run_closedloop(scen, bin_dir, config_dir, timeout_s=task["timeout_s"], profiles=profiles)
    for attempt in range(1, attempts + 1):
        try:
            summary, wall = run_scenario(scen, run_dir, domain, bin_dir, config_dir, record=record_path,
                                         timeout_s=task["timeout_s"], profiles=profiles)
            sim = dict(summary["services"]["mft-sim"])
            sim.setdefault("profiles", summary.get("profiles"))  # what the stack reports it ran with
            return sim, wall
        except ExperimentError as e:
            if attempt == attempts or REGISTRY.stopping.is_set():
                raise
            log(f"{e}; retrying ({attempt} of {attempts - 1})")
            time.sleep(3.0 * attempt)
