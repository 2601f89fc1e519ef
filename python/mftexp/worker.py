"""The worker side of the Dask backend (mftexp.executor): runs in a dask-worker process on any machine that has
a clone and a build of this project, importable as mftexp (`mft-experiment worker SCHEDULER` sets that up).

Per run: refuse when this machine's build is not the client's; take a DDS domain that no other run on this
machine holds (one lock file per domain in the scratch folder, so several worker processes on one machine never
share a domain, and a killed one frees its domains with its file locks); write the configuration the client sent
into scratch/config-<sha256> once; run the stack in a scratch run folder; return the summary (and the rawlog
when asked) and delete the folder. A failed run raises RunFailed with the tails of its logs.
Environment: MFT_BIN_DIR (the services; default this clone's build/release/bin), MFT_EXPERIMENT_SCRATCH
(default TMPDIR/mft-experiment-worker)."""
import fcntl
import os
import shutil
import socket
import tempfile
import threading
import time
from contextlib import contextmanager
from pathlib import Path

from .common import DEFAULT_BIN, ExperimentError, check_setup
from .execution import BuildMismatch, RunFailed, build_identity, execute, files_sha256, identity_difference

DOMAIN_WAIT_S = 600.0  # every domain of the pool held by other runs on this machine: wait this long at most


def scratch_dir():
    d = Path(os.environ.get("MFT_EXPERIMENT_SCRATCH") or Path(tempfile.gettempdir()) / "mft-experiment-worker")
    d.mkdir(parents=True, exist_ok=True)
    return d


def bin_dir():
    return Path(os.environ.get("MFT_BIN_DIR") or DEFAULT_BIN)


def worker_name():
    try:
        from distributed import get_worker
        w = get_worker()
        return str(w.name) if w.name is not None and not str(w.name).isdigit() else w.address
    except (ImportError, ValueError):
        return f"{socket.gethostname()}/{os.getpid()}"


def worker_address():
    try:
        from distributed import get_worker
        return get_worker().address
    except (ImportError, ValueError):
        return ""


def probe(client_identity):
    """{"problem": None or one line, "host", "bin_dir"}: whether this worker can run the client's study."""
    problem = identity_difference(build_identity(), client_identity)
    if problem:
        problem = f"its build differs: {problem}"
    else:
        try:
            check_setup(bin_dir(), Path(__file__).resolve().parents[2] / "config")
        except ExperimentError as e:
            problem = str(e)
    return {"problem": problem, "host": socket.gethostname(), "bin_dir": str(bin_dir())}


@contextmanager
def domain_slot(base, count):
    """A DDS domain in base..base+count-1 that no other run on this machine holds while inside."""
    locks = scratch_dir() / "domains"
    locks.mkdir(exist_ok=True)
    deadline = time.monotonic() + DOMAIN_WAIT_S
    while True:
        for d in range(base, min(232, base + count - 1) + 1):
            f = open(locks / f"{d}.lock", "w")
            try:
                fcntl.flock(f, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except OSError:
                f.close()
                continue
            try:
                yield d
            finally:
                fcntl.flock(f, fcntl.LOCK_UN)
                f.close()
            return
        if time.monotonic() > deadline:
            raise ExperimentError(f"every DDS domain {base}..{base + count - 1} on {socket.gethostname()} stayed held "
                                  f"by other runs for {DOMAIN_WAIT_S:.0f} s (more worker threads than --domain-slots?)")
        time.sleep(0.2)


_CONFIG_LOCK = threading.Lock()


def materialize_config(config):
    """The client's configuration files as a folder of this machine (written once per content)."""
    files, sha = config["files"], config["sha256"]
    if files_sha256(files) != sha:
        raise ExperimentError("the configuration sent with the task does not match its sha256")
    dest = scratch_dir() / f"config-{sha[:16]}"
    with _CONFIG_LOCK:
        if not dest.is_dir():
            tmp = Path(tempfile.mkdtemp(prefix=f"config-{sha[:16]}.", dir=scratch_dir()))
            for rel, text in files.items():
                (tmp / rel).parent.mkdir(parents=True, exist_ok=True)
                (tmp / rel).write_text(text)
            try:
                tmp.rename(dest)
            except OSError:  # another worker process on this machine was first: its copy is the same content
                shutil.rmtree(tmp, ignore_errors=True)
    return dest


def log_tails(run_dir, limit=4000):
    """The ends of the log files a failed run left, as one text."""
    out = []
    for p in sorted(Path(run_dir).rglob("*")):
        if p.is_file() and p.suffix in (".log", ".txt", ".json", ".err", ".out") and p.stat().st_size:
            text = p.read_text(errors="replace")
            out.append(f"--- {p.name} ---\n{text[-limit:]}")
    return "\n".join(out) or "(no log files)"


# What a Dask nanny puts into its worker's environment for numpy (distributed.nanny.pre-spawn-environ): not
# passed on to the stacks, which run with the environment of the user who started the worker.
NANNY_ENVIRON = ("MALLOC_TRIM_THRESHOLD_", "OMP_NUM_THREADS", "MKL_NUM_THREADS", "OPENBLAS_NUM_THREADS")


def _drop_nanny_environ():
    try:
        import dask
        spawned = dask.config.get("distributed.nanny.pre-spawn-environ", {}) or {}
    except ImportError:
        return
    for k in NANNY_ENVIRON:
        if k in spawned and os.environ.get(k) == str(spawned[k]):
            os.environ.pop(k, None)


def run_task(task):
    """One run of a study on this worker (see the module's doc). Returns {"sim", "wall", "worker", "domain",
    "host", "rawlog" (bytes or None)}."""
    name = worker_name()
    _drop_nanny_environ()
    problem = identity_difference(build_identity(), task["build"])
    if problem:
        raise BuildMismatch(f"Dask worker {name} on {socket.gethostname()} refuses: its build differs from the "
                            f"client's: {problem} (check out and build the client's commit there)", name)
    try:
        check_setup(bin_dir(), Path(__file__).resolve().parents[2] / "config",
                    need=("mft-sim", "mft-estimator", "mft-planner", "mft-wbc") +
                         (("mft-record",) if task["record"] else ()) +
                         (("mft-closedloop",) if task["inprocess"] else ()))
        config_dir = materialize_config(task["config"])
    except ExperimentError as e:
        raise RunFailed(f"{e} (on {socket.gethostname()})", name, "", worker_address())
    safe = task["name"].replace("/", "_")
    run_dir = Path(tempfile.mkdtemp(prefix=f"{safe}.", dir=scratch_dir() / _study_dir(task["study"])))
    record_path = run_dir / "run.rawlog" if task["record"] else None
    try:
        with domain_slot(task["domain_base"], task["domain_slots"]) as domain:
            sim, wall = execute(task, run_dir / "run", domain, bin_dir(), config_dir, record_path, attempts=1)
        rawlog = record_path.read_bytes() if record_path else None
    except ExperimentError as e:
        raise RunFailed(f"{e} (on {socket.gethostname()}, kept in {run_dir})", name, log_tails(run_dir),
                        worker_address())
    except Exception as e:  # noqa: a bug or a broken build on this machine: reported with its traceback
        import traceback
        raise RunFailed(f"{type(e).__name__}: {e} (on {socket.gethostname()}, kept in {run_dir})", name,
                        traceback.format_exc() + "\n" + log_tails(run_dir), worker_address())
    shutil.rmtree(run_dir, ignore_errors=True)
    return {"sim": sim, "wall": wall, "worker": name, "domain": domain, "host": socket.gethostname(),
            "rawlog": rawlog}


def _study_dir(study):
    d = scratch_dir() / f"study-{study}"
    d.mkdir(exist_ok=True)
    return d.name
