"""The child processes a tool started, and only those (the one process registry of the Python side): each started
in its own session and bound to its parent's life (PR_SET_PDEATHSIG); on Ctrl-C or an error stop_all() ends them
by pid, SIGTERM first (a supervisor stops its own children), SIGKILL after a grace time. The supervisor's service
processes (processes.Service) use the same parent-death binding; mft-experiment keeps its supervisors here."""
import ctypes
import os
import signal
import subprocess
import threading
import time

PR_SET_PDEATHSIG = 1


def set_pdeathsig(sig, ignore_errors=False):
    """In a child between fork and exec: the kernel sends `sig` to it when its parent dies, whatever killed it."""
    try:
        libc = ctypes.CDLL("libc.so.6", use_errno=True)
        libc.prctl(PR_SET_PDEATHSIG, sig)
    except OSError:
        if not ignore_errors:
            raise


class ProcessRegistry:
    """Processes started through popen() until done(); `interrupted` is raised by popen() once stop_all() began."""

    def __init__(self, interrupted=RuntimeError, death_signal=signal.SIGTERM):
        self._lock = threading.Lock()
        self._procs = set()
        self._interrupted = interrupted
        self._death_signal = death_signal
        self.stopping = threading.Event()

    def popen(self, argv, **kw):
        with self._lock:
            if self.stopping.is_set():
                raise self._interrupted()
            p = subprocess.Popen(argv, stdin=subprocess.DEVNULL, start_new_session=True,
                                 preexec_fn=lambda: set_pdeathsig(self._death_signal, ignore_errors=True), **kw)
            self._procs.add(p)
            return p

    def done(self, p):
        with self._lock:
            self._procs.discard(p)

    def stop_all(self, grace_s=15.0):
        self.stopping.set()
        with self._lock:
            procs = list(self._procs)
        for p in procs:
            if p.poll() is None:
                try:
                    os.kill(p.pid, signal.SIGTERM)  # a supervisor stops its own children
                except OSError:
                    pass
        deadline = time.monotonic() + grace_s
        for p in procs:
            try:
                p.wait(timeout=max(0.1, deadline - time.monotonic()))
            except subprocess.TimeoutExpired:
                try:
                    os.kill(p.pid, signal.SIGKILL)  # its children die with it (PR_SET_PDEATHSIG)
                except OSError:
                    pass
                p.wait()
