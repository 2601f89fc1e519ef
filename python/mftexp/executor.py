"""Where a study's stack runs happen: on this machine (LocalExecutor, the default: no daemon) or on Dask
distributed workers (DaskExecutor, --scheduler tcp://HOST:8786; docs/guide/cluster-studies.md).

A run is a task: a plain dict (RunTask) with the scenario, the profiles, the configuration files, the build it
was meant for and whether to record. `execute` is the one implementation of a run on both backends. A study
(Sweep) asks its executor for slots, one search thread per slot; a slot's run() blocks until that run's result:
  local: slot i owns DDS domain domain_base + i and runs the stack in its thread, as before this layer existed;
  dask:  a slot submits the task and waits for its future. The worker (mftexp.worker.run_task) takes a DDS
         domain no other run on its machine holds (a lock file per domain), checks its build against the
         client's, runs the stack in a scratch folder and returns the summary (and the rawlog when asked).
The client alone writes results.jsonl, so resuming and the table are the same on both backends."""
import hashlib
import logging
import os
import threading
import time
from pathlib import Path

from .common import REGISTRY, ExperimentError, Interrupted, log, write_yaml_scenario
from .execution import (BuildMismatch, RunFailed, build_identity, config_files, execute,  # noqa: F401 (the
                        files_sha256, identity_difference, run_task)                     # study's entry points)
LOCAL_ATTEMPTS = 3   # a run that fails is tried again on the same domain (local) ...
REMOTE_ATTEMPTS = 3  # ... or on another worker where there is one (dask)


class RunResult:
    """What a slot returns: the summary, the wall time of the run, where it ran."""

    def __init__(self, sim, wall, worker, domain, host=None):
        self.sim, self.wall, self.worker, self.domain, self.host = sim, wall, worker, domain, host


# ------------------------------------------------------------------------------------------- local backend
class LocalSlot:
    def __init__(self, executor, domain):
        self.executor, self.domain, self.name = executor, domain, f"local/domain-{domain}"

    def run(self, task, run_dir, record_path=None):
        sim, wall = execute(task, run_dir, self.domain, self.executor.bin_dir, self.executor.config_dir,
                            record_path, attempts=LOCAL_ATTEMPTS)
        return RunResult(sim, wall, self.name, self.domain)


class LocalExecutor:
    """Stacks on this machine, `workers` at a time, stack i on DDS domain domain_base + i."""
    kind = "local"

    def __init__(self, workers, domain_base, bin_dir, config_dir):
        self.workers, self.domain_base, self.bin_dir, self.config_dir = workers, domain_base, bin_dir, config_dir

    def describe(self):
        return f"{self.workers} stacks on domains {self.domain_base}..{self.domain_base + self.workers - 1}"

    def slots(self):
        return [LocalSlot(self, self.domain_base + i) for i in range(self.workers)]

    def info(self):
        return {"backend": "local", "workers": self.workers, "domain_base": self.domain_base}

    def cancel(self):
        pass

    def close(self):
        pass


# -------------------------------------------------------------------------------------------- dask backend
def _import_distributed():
    try:
        import distributed
    except ImportError:
        import sys
        raise ExperimentError(f"--scheduler needs Dask distributed for {sys.executable} (Debian: apt-get install "
                              f"python3-distributed; run with /usr/bin/python3)")
    return distributed


class _UnretrievedTimeouts(logging.Filter):
    """Drops asyncio's report of a timeout future nobody awaited. Dask's client leaves tornado connect timeouts
    unretrieved on a loaded machine; at exit asyncio prints 'Future exception was never retrieved ...
    TimeoutError: Timeout' after the study's last line (its error line included), which says nothing about the
    study and hid that line in a loaded test series."""

    def filter(self, record):
        exc = record.exc_info[1] if record.exc_info else None
        return not (isinstance(exc, TimeoutError) and record.getMessage().startswith("Future exception was never"))


def quiet_unretrieved_timeouts():
    """Once per process: asyncio's logger drops those reports (other unretrieved exceptions are still reported)."""
    log = logging.getLogger("asyncio")
    if not any(isinstance(f, _UnretrievedTimeouts) for f in log.filters):
        log.addFilter(_UnretrievedTimeouts())


def _probe_worker(identity):
    """Runs on every worker before a study (Client.run): its build difference from the client and its binaries."""
    from . import worker
    return worker.probe(identity)


class DaskSlot:
    def __init__(self, executor, index):
        self.executor, self.index, self.name = executor, index, f"dask/{index}"

    def run(self, task, run_dir, record_path=None):
        ex = self.executor
        run_dir = Path(run_dir)
        run_dir.mkdir(parents=True, exist_ok=True)
        write_yaml_scenario(run_dir / "scenario.yaml", task["scenario"])  # what ran, beside the client's results
        full = dict(task, build=ex.identity, config=ex.config, domain_base=ex.domain_base,
                    domain_slots=ex.domain_slots, study=ex.study)
        tried, failures, resubmits = [], [], 0
        while True:
            attempt = len(failures) + 1
            # after a failure: only on workers that have not tried it, while there are such workers
            untried = [w for w in ex.worker_addresses() if w not in tried] if failures else []
            where = {"workers": untried, "allow_other_workers": False} if untried else {}
            fut = ex.client.submit(_run_on_worker, full, key=f"mft-run-{ex.study}-{task['name']}-a{attempt}-{resubmits}",
                                   pure=False, **where)
            try:
                out = ex.wait(fut, restricted=untried)
            except _RestrictedWorkersGone:
                resubmits += 1
                continue
            except BuildMismatch as e:
                raise ExperimentError(str(e))
            except RunFailed as e:
                failures.append(e)
                tried.append(e.address)
            except ex.distributed.KilledWorker as e:  # the scheduler gave up: its workers died running it
                failures.append(RunFailed(f"the workers running it died ({e})", "killed", ""))
            else:
                if out.get("rawlog") is not None and record_path:
                    Path(record_path).parent.mkdir(parents=True, exist_ok=True)
                    tmp = Path(str(record_path) + ".part")
                    tmp.write_bytes(out["rawlog"])
                    tmp.rename(record_path)
                with ex.lock:
                    ex.per_host[out["worker"]] = out["host"]
                return RunResult(out["sim"], out["wall"], out["worker"], out["domain"], out["host"])
            if len(failures) >= REMOTE_ATTEMPTS:  # each attempt preferred a worker that had not tried it
                log_path = run_dir / "failures.log"
                log_path.write_text("".join(f"=== attempt {i + 1} on {f.worker}: {f.message}\n{f.logs}\n"
                                            for i, f in enumerate(failures)))
                raise ExperimentError(f"run {task['name']} failed on {', '.join(f.worker for f in failures)}: "
                                      f"{failures[-1].message} (logs in {log_path})")
            log(f"run {task['name']} failed on {failures[-1].worker}: {failures[-1].message}; "
                f"running it again elsewhere ({attempt} of {REMOTE_ATTEMPTS - 1})")


class _RestrictedWorkersGone(Exception):
    pass


def _run_on_worker(task):
    from . import worker
    return worker.run_task(task)


class DaskExecutor:
    """Runs on the workers of a Dask distributed scheduler. `in_flight`: searches (one run each) at once;
    None: the workers' threads at the start."""
    kind = "dask"

    def __init__(self, address, domain_base, domain_slots, config_dir, in_flight=None, connect_timeout_s=30.0,
                 worker_wait_s=120.0):
        self.distributed = _import_distributed()
        self.address, self.domain_base, self.domain_slots = address, domain_base, domain_slots
        self.identity = build_identity()
        files = config_files(config_dir)
        self.config = {"files": files, "sha256": files_sha256(files)}
        self.study = hashlib.sha1(f"{os.getpid()}-{time.time()}".encode()).hexdigest()[:10]
        self.lock = threading.Lock()
        self.per_host = {}
        self.worker_wait_s = worker_wait_s
        self._futures = set()
        self._closed_info = None
        self._info_lock = threading.Lock()
        self._workers_cache = None
        quiet_unretrieved_timeouts()
        try:
            self.client = self.distributed.Client(address, timeout=connect_timeout_s, set_as_default=False)
        except (OSError, TimeoutError) as e:
            raise ExperimentError(f"no Dask scheduler answers at {address} within {connect_timeout_s:.0f} s ({e}); "
                                  f"start one with dask-scheduler (docs/guide/cluster-studies.md)")
        try:
            self.client.wait_for_workers(1, timeout=worker_wait_s)
        except (TimeoutError, self.distributed.TimeoutError, OSError):
            self.close()
            raise ExperimentError(f"no Dask worker joined {address} within {worker_wait_s:.0f} s")
        self.check_workers()
        threads = sum(w.get("nthreads", 1) for w in self.workers_info().values())
        self.in_flight = in_flight or max(2, threads)

    def check_workers(self):
        """Every connected worker must run this build and have its binaries: else a clear error naming it."""
        try:
            answers = self.client.run(_probe_worker, self.identity)
        except Exception as e:  # noqa: a worker that cannot import mftexp raises ModuleNotFoundError here
            raise ExperimentError(f"a Dask worker could not check its build: {type(e).__name__}: {e} (start workers "
                                  f"with 'mft-experiment worker {self.address}' or PYTHONPATH=REPO/python)")
        bad = [f"{addr}: {a['problem']}" for addr, a in sorted(answers.items()) if a.get("problem")]
        if bad:
            raise ExperimentError("Dask worker(s) refuse this study: " + " | ".join(bad))

    def workers_info(self, max_age_s=1.0):
        """{address: info} of the connected workers. One search thread at a time asks the scheduler, at most
        every max_age_s (Client.scheduler_info updates shared state of the client)."""
        with self._info_lock:
            now = time.monotonic()
            if self._workers_cache is None or now - self._workers_cache[0] > max_age_s:
                self._workers_cache = (now, dict(self.client.scheduler_info()["workers"]))
            return self._workers_cache[1]

    def worker_addresses(self):
        return sorted(self.workers_info())

    def wait(self, fut, restricted=None):
        """The future's result; Interrupted when stopping; an error when no worker was connected for too long;
        _RestrictedWorkersGone when the future may only run on `restricted` workers and all of those left."""
        with self.lock:
            self._futures.add(fut)
        no_worker_since = None
        try:
            while True:
                if REGISTRY.stopping.is_set():
                    fut.cancel()
                    raise Interrupted()
                try:
                    return fut.result(timeout=0.5)
                except (TimeoutError, self.distributed.TimeoutError):  # one class from Python 3.11 on
                    pass
                connected = self.workers_info()
                if restricted and not set(restricted) & set(connected):
                    fut.cancel()
                    raise _RestrictedWorkersGone()
                if not connected:
                    no_worker_since = no_worker_since or time.monotonic()
                    if time.monotonic() - no_worker_since > self.worker_wait_s:
                        fut.cancel()
                        raise ExperimentError(f"no Dask worker connected to {self.address} for "
                                              f"{self.worker_wait_s:.0f} s")
                else:
                    no_worker_since = None
        finally:
            with self.lock:
                self._futures.discard(fut)

    def describe(self):
        workers = self.workers_info()
        threads = sum(w.get("nthreads", 1) for w in workers.values())
        return (f"Dask scheduler {self.address}: {len(workers)} workers, {threads} threads, {self.in_flight} runs in "
                f"flight, build {self.identity['commit'][:12]}")

    def slots(self):
        return [DaskSlot(self, i) for i in range(self.in_flight)]

    def info(self):
        if self._closed_info is not None:
            return dict(self._closed_info)
        workers = self.workers_info()
        return {"backend": "dask", "scheduler": self.address, "workers_now": len(workers),
                "threads_now": sum(w.get("nthreads", 1) for w in workers.values()), "in_flight": self.in_flight,
                "build": self.identity, "hosts": dict(self.per_host)}

    def cancel(self):
        with self.lock:
            futs = list(self._futures)
        for f in futs:
            f.cancel()

    def close(self):
        if self._closed_info is not None:
            return
        try:
            self._closed_info = self.info()
        except Exception:  # noqa: a scheduler already gone
            self._closed_info = {"backend": "dask", "scheduler": self.address, "build": self.identity,
                                 "hosts": dict(self.per_host)}
        try:
            self.client.close(timeout=10)
        except Exception:  # noqa: closing a client whose scheduler is gone
            pass


def make_executor(args, config_dir):
    if getattr(args, "scheduler", None):
        return DaskExecutor(args.scheduler, args.domain_base, args.domain_slots, config_dir,
                            in_flight=args.in_flight, worker_wait_s=args.worker_wait)
    return LocalExecutor(args.workers, args.domain_base, args.bin_dir, config_dir)
