"""Service processes: start in order, readiness, restart with back-off, PR_SET_PDEATHSIG, logs, stop.

Stack builds every service's command line (the service contract, with the host's DDS profile of a stack
file, docs/guide/distributed.md) and supervises the processes; Service is one child with its log and summary."""
import json
import os
import re
import signal
import subprocess
import threading
import time
from pathlib import Path

from .ddsxml import DISCOVERY_SERVER, write_host_profiles
from .errors import Interrupted, SupervisorError, log, os_problem
from .paths import DEFAULT_RUNS
from .registry import set_pdeathsig

# Start order: the simulator owns the clock, so it starts last, once every consumer listens.
CORE_SERVICES = ["mft-estimator", "mft-planner", "mft-wbc"]
READY_TIMEOUT_S = 30.0
STOP_GRACE_S = 5.0
RESTART_BACKOFF_S = (0.1, 0.2, 0.5, 1.0, 2.0)
ALL_SERVICES = CORE_SERVICES + ["mft-sim", "mft-record"]
# Lockstep recording: the simulator never runs more than this many ticks ahead of what mft-record has received,
# so a starved recorder slows the run down instead of losing samples. 200 ticks are ~1400 datagrams; the kernel
# charges each small datagram ~2-3 kB of the recorder's 4 MB (x2) receive buffer, so they fit with room for
# the services' re-sends. The recorder keeps up on an idle machine: the window rarely binds there.
RECORDER_WINDOW_TICKS = 200
# Fast DDS 2.9.1's secure handshake between two participants sometimes never completes (measured: 1 of 3
# secured realtime starts, "SensorData readers 0" after 30 s; a new participant authenticates at once). A
# secured simulator gives up connecting after this long and `run` starts the stack once more.
SECURE_START_TIMEOUT_S = 10
SECURE_RUN_ATTEMPTS = 2
DISCOVERY_SERVER_READY = "### Server is running ###"




def chain_cpu_for(chain_cpu, mode, domain, multi_host):
    """The CPU the control chain is pinned to, or None: --chain-cpu N, "none" (no pinning) or "auto" (the
    default when the option is not given).

    A tick is a relay (sim -> estimator -> planner -> wbc -> sim) in which one process runs at a time: on one
    core every hand-off is a local wake-up, while a wake-up on another, idle, vCPU costs tens of us on a VM
    (docs/results/loop-benchmark.md). "auto" pins the chain of a single-host stack to one of the CPUs this process may
    use, chosen by its DDS domain, so that the stacks of mft-experiment's local workers (consecutive domains)
    each get their own core; multi-host stacks (--stack) are not pinned by "auto". Measured
    (docs/results/loop-benchmark.md): in lockstep the pinned chain ran a tick in ~0.7x the time of the unpinned one;
    in realtime (with the priorities rising along the chain) the sensor-to-command p50 fell ~3x and its p99
    ~1.7x on a 2-vCPU VM."""
    if chain_cpu is None:
        chain_cpu = "auto"
    if chain_cpu == "none":
        return None
    allowed = sorted(os.sched_getaffinity(0))
    if chain_cpu == "auto":
        if multi_host:
            return None
        return allowed[domain % len(allowed)]
    try:
        cpu = int(chain_cpu)
    except (TypeError, ValueError):
        raise SupervisorError(f"--chain-cpu {chain_cpu}: expected a CPU number, auto or none")
    if cpu not in allowed:
        raise SupervisorError(f"--chain-cpu {chain_cpu}: this process may run on CPUs {allowed} only")
    return cpu


CHAIN_SEGMENT_BYTES = 3_300_000  # a little more than the chain channel's segment (ChainChannel::segmentBytes)
CHAIN_SEGMENT = re.compile(r"^mft-chain-d\d+-(\d+)-\d+$")


def remove_orphan_segments(shm_dir="/dev/shm"):
    """Removes chain segments whose supervisor (the pid in the name) is gone: a supervisor killed with SIGKILL
    cannot remove its own. Returns the names removed."""
    removed = []
    try:
        names = os.listdir(shm_dir)
    except OSError:
        return removed
    for name in names:
        m = CHAIN_SEGMENT.match(name)
        if not m or _pid_alive(int(m.group(1))):
            continue
        try:
            os.unlink(os.path.join(shm_dir, name))
            removed.append(name)
        except OSError:
            pass
    return removed


def _pid_alive(pid):
    """True while pid runs; a zombie (killed, not yet reaped by its parent) counts as gone."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:
        return True
    return not _is_zombie(pid)


def _is_zombie(pid):
    try:
        return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0] == "Z"
    except (OSError, IndexError):
        return False


def shm_problem(shm_dir="/dev/shm"):
    """Why the chain's segment cannot go in /dev/shm, or None."""
    if not os.access(shm_dir, os.W_OK):
        return f"{shm_dir} is not writable"
    try:
        st = os.statvfs(shm_dir)
    except OSError as e:
        return f"{shm_dir}: {e.strerror}"
    free = st.f_bavail * st.f_frsize
    if free < CHAIN_SEGMENT_BYTES:
        return f"{shm_dir} has {free / 1e6:.1f} MB free, the chain's segment needs {CHAIN_SEGMENT_BYTES / 1e6:.1f} MB"
    return None


def chain_shm_name(args, multi_host):
    """The shared-memory segment of this stack's chain channel, or None: --chain-transport, by default shm in both
    modes; never with --secure (it would bypass access control) or --stack (several hosts). By default a /dev/shm
    that is not writable or too full for the segment means DDS (some containers), with a note; an explicit
    --chain-transport shm is then an error."""
    explicit = getattr(args, "chain_transport", None)
    if (explicit or "shm") != "shm" or multi_host or getattr(args, "secure", None):
        return None
    for name in remove_orphan_segments():
        log(f"removed /dev/shm/{name}: its supervisor is gone")
    problem = shm_problem()
    if problem and explicit:
        raise SupervisorError(f"--chain-transport shm: {problem}")
    if problem:
        log(f"chain transport: dds ({problem})")
        return None
    return f"/mft-chain-d{args.domain}-{os.getpid()}-{time.monotonic_ns() % 1000000}"


# --rt-priorities chain (the default for a chain pinned on the shared-memory channel, rt_priorities_for): SCHED_FIFO
# priorities rising along the chain from the estimator to the simulator, which consumes the chain's end product
# (the command). With the chain on one core each hand-off (estimator -> planner -> wbc) preempts the writer at
# once, and the WBC's command preempts the WBC itself: the simulator has it before the writers' post-write work
# runs. "flat" runs them all at 80. Measured (docs/results/loop-benchmark.md, "The realtime tail, measure by
# measure"): with the simulator lowest instead (sim 76 ... wbc 79) the command waited for the estimator's and the
# planner's remaining work, p50 +50-100 us.
RT_CHAIN_PRIORITIES = {"mft-estimator": 76, "mft-planner": 77, "mft-wbc": 78, "mft-sim": 79}


def rt_priorities_for(args, pinned_shm_chain):
    """--rt-priorities as given, else "chain" for a chain pinned to one core on the shared-memory channel (where it
    was measured to pay: docs/results/loop-benchmark.md), else "flat". Measured on a 2-vCPU VM: a secured standing
    stack (its chain on secured DDS) fell in 4 of 9 runs of 20-90 s with the chain's priorities and in none of 7
    flat; a three-host stack (DDS, unpinned) with the chain's priorities fell in its realtime test in a clean-clone
    CI run and in loaded series, where it had passed 20 of 20 flat (docs/guide/testing.md)."""
    given = getattr(args, "rt_priorities", None)
    if given:
        return given
    return "chain" if pinned_shm_chain else "flat"


def realtime_options(name, args, priorities):
    """The options of service `name` for the realtime knobs: --rt-priority with priorities "chain" (from
    rt_priorities_for), the chain services' --rt-threads, mft-sim's --spin-us with --sim-spin-us; nothing in
    lockstep or without --rt."""
    if args.mode != "realtime" or getattr(args, "no_rt", False):
        return []
    extra = []
    if priorities == "chain" and name in RT_CHAIN_PRIORITIES:
        extra += ["--rt-priority", str(RT_CHAIN_PRIORITIES[name])]
    if name in RT_CHAIN_PRIORITIES:
        extra += ["--rt-threads", getattr(args, "rt_threads", None) or "loop"]  # applies on the chain channel only
    if name == "mft-sim" and getattr(args, "sim_spin_us", 0):
        extra += ["--spin-us", str(args.sim_spin_us)]
    return extra


def cpu_placement(chain_cpu, names, recorder_elsewhere=True):
    """The chain (sim, estimator, planner, wbc) on CPU `chain_cpu` (None: no pinning); the recorder on the other
    CPUs when `recorder_elsewhere` (an explicit --chain-cpu N), else free. "auto" leaves it free: the lockstep
    recorder's threads are SCHED_IDLE, and confined to a core that something else keeps busy (another stack's
    chain in mft-experiment, another job) it starved until the simulator's recorder window timed out (measured:
    rawlog_integration's starved-recorder run on a loaded machine); free, it also takes the chain's core
    whenever the chain waits for it."""
    if chain_cpu is None:
        return {}
    allowed = sorted(os.sched_getaffinity(0))
    others = [c for c in allowed if c != chain_cpu] or [chain_cpu]
    return {n: {chain_cpu} if n in CORE_SERVICES + ["mft-sim"] else set(others)
            for n in names if n in CORE_SERVICES + ["mft-sim"] or recorder_elsewhere}


class Service:
    """One child process: its log file, readiness and exit status."""

    def __init__(self, name, argv, run_dir, ready_line=None, summary=True, host=None, cpus=None):
        self.name = name
        self.argv = argv
        self.cpus = cpus  # CPU affinity set in the child before exec (None: inherit)
        self.run_dir = run_dir
        self.host = host  # the stack file's host (None: this machine, as before)
        self.ready_line = ready_line or f"READY {name}"
        self.log_path = run_dir / f"{name}.log"
        self.summary_path = run_dir / f"{name}.summary.json" if summary else None
        self.proc = None
        self.ready = threading.Event()
        self.restarts = 0
        self.started_at = 0.0
        self._reader = None
        self.stdout_summary = None
        self.log_lost = None  # why the log file could not be written (full disk, ...)

    def start(self):
        self.ready.clear()
        logf = open_service_log(self)
        extra = ["--summary", str(self.summary_path)] if self.summary_path else []
        cpus = self.cpus
        # The recorder gets SIGTERM, so that it closes its file (gzip end, sidecar status) when the supervisor
        # is killed; the others SIGKILL.
        death_signal = signal.SIGTERM if self.name == "mft-record" else signal.SIGKILL

        def before_exec():
            set_pdeathsig(death_signal)  # bound to the supervisor's life, whatever killed it
            if cpus:
                os.sched_setaffinity(0, cpus)

        self.proc = subprocess.Popen(self.argv + extra, stdout=subprocess.PIPE,
                                     stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL, preexec_fn=before_exec)
        self.started_at = time.monotonic()
        self._reader = threading.Thread(target=self._pump, args=(self.proc, logf), daemon=True)
        self._reader.start()

    def _pump(self, proc, logf):
        ready_line = self.ready_line.encode()
        for line in proc.stdout:
            logf.write(line)  # a LossyLog: a full disk loses log lines, never the pipe (the child would block)
            if line.strip() == ready_line:
                self.ready.set()
            elif line.startswith(b"SUMMARY {"):  # a service that could not write its summary file prints it
                self.stdout_summary = line[len(b"SUMMARY "):].decode(errors="replace")
        logf.close()

    def alive(self):
        return self.proc is not None and self.proc.poll() is None

    def signal(self, sig):
        if self.alive():
            try:
                self.proc.send_signal(sig)
            except ProcessLookupError:
                pass

    def wait(self, timeout):
        if self.proc is None:
            return None
        try:
            return self.proc.wait(timeout=timeout)
        except subprocess.TimeoutExpired:
            return None

    def summary(self):
        if self.summary_path is None:
            return None
        try:
            return json.loads(self.summary_path.read_text())
        except (OSError, ValueError):
            pass
        if self._reader is not None and self.proc is not None and self.proc.poll() is not None:
            # The service has exited: its last output line (a SUMMARY it could not write to a file) may still be in
            # the pipe. Seen once under load: a full disk's summary read as missing.
            self._reader.join(timeout=2.0)
        try:
            return json.loads(self.stdout_summary) if self.stdout_summary else None
        except ValueError:
            return None


class Stack:
    def __init__(self, args, scenario):
        self.args = args
        self.scenario = scenario
        self.services = {}
        stamp = time.strftime("%Y%m%d-%H%M%S")
        self.run_dir = Path(args.run_dir) if args.run_dir else DEFAULT_RUNS / f"{scenario['name']}-{stamp}-d{args.domain}"
        make_run_dir(self.run_dir)
        common = ["--domain", str(args.domain), "--scenario", str(Path(args.scenario).resolve()), "--mode", args.mode,
                  "--config-dir", str(args.config_dir)]
        for name in getattr(args, "profile", None) or []:
            common += ["--profile", name]  # each service applies the scenario's profiles, then these
        if getattr(args, "secure", None):
            common += ["--secure", str(Path(args.secure).resolve())]  # each service takes its own identity
        if args.mode == "realtime" and not args.no_rt:
            common.append("--rt")  # SCHED_FIFO keeps the 1 kHz tail short under load (docs/reference/dds.md#scheduling-and-latency)
        names = list(CORE_SERVICES)
        if args.record:
            names.append("mft-record")
        names.append("mft-sim")
        # Every service announces the whole stack (all hosts) in DDS discovery: mft-cmd then waits for each reader
        # of a request by name, the recorder included, even before it has discovered that reader's participant.
        common += ["--stack-services", ",".join(names)]
        self.stack = getattr(args, "stack_file", None)
        self.only_host = getattr(args, "host", None)
        if self.only_host:
            names = [n for n in names if self.stack.placement[n] == self.only_host]
        profiles = write_host_profiles(self.stack, Path(args.config_dir), self.run_dir) if self.stack else {}
        if self.stack and self.stack.runs_server(self.only_host):
            host = self.stack.server_host
            argv = self.stack.launcher(host) + [self.stack.server_exe, "-x", str(profiles[DISCOVERY_SERVER])]
            self.services[DISCOVERY_SERVER] = Service(DISCOVERY_SERVER, argv, self.run_dir, summary=False,
                                                      ready_line=DISCOVERY_SERVER_READY, host=host)
        self.chain_shm = chain_shm_name(args, bool(self.stack))
        self.chain_cpu = chain_cpu_for(getattr(args, "chain_cpu", None), args.mode, args.domain, bool(self.stack))
        explicit = getattr(args, "chain_cpu", None) not in (None, "auto", "none")
        placement = cpu_placement(self.chain_cpu, names, recorder_elsewhere=explicit)
        self.rt_priorities = rt_priorities_for(args, bool(self.chain_shm) and self.chain_cpu is not None)
        for name in names:
            argv = [str(Path(args.bin_dir) / name)] + common
            host = None
            if self.stack:
                host = self.stack.placement[name]
                argv = self.stack.launcher(host) + argv + ["--profiles", str(profiles[host])]
            if self.chain_shm and (name != "mft-record" or args.mode == "lockstep"):
                # the four chain services, and in lockstep the recorder (its window keeps it inside the rings)
                argv += ["--chain-shm", self.chain_shm]
            argv += realtime_options(name, args, self.rt_priorities)
            if name == "mft-record":
                argv += ["--output", str(Path(args.record).resolve())] + (["--overwrite"] if args.overwrite else [])
            if name == "mft-sim" and getattr(args, "record", None) and args.mode == "lockstep" and RECORDER_WINDOW_TICKS:
                argv += ["--recorder-window", str(RECORDER_WINDOW_TICKS)]
            if name == "mft-sim" and getattr(args, "stall_probe", False) and args.mode == "realtime":
                argv += ["--stall-probe-us", "1000"]  # tells the machine's stalls from the chain's misses
            if name == "mft-sim" and getattr(args, "forever", False):
                argv += ["--forever", "--continue-after-fall"]  # a long-running stack outlives a fall
            if name == "mft-sim" and getattr(args, "secure", None):
                argv += ["--start-timeout", str(SECURE_START_TIMEOUT_S)]  # a stuck handshake: fail fast, retry
            self.services[name] = Service(name, argv, self.run_dir, host=host, cpus=placement.get(name))
        self.failed = []
        self.events = []
        self.stop_flag = None   # a threading.Event set by SIGINT/SIGTERM: start_all and watch give up at once
        self.on_restart = None  # called after a service was restarted (up keeps its state file current)

    def start_all(self, quiet):
        t0 = time.monotonic()
        if DISCOVERY_SERVER in self.services:  # clients find nothing without it
            self.services[DISCOVERY_SERVER].start()
            self._wait_ready([self.services[DISCOVERY_SERVER]])
        for svc in self.services.values():
            if svc.name in ("mft-sim", DISCOVERY_SERVER):
                continue
            self._check_interrupted()
            svc.start()
        self._wait_ready([s for n, s in self.services.items() if n not in ("mft-sim", DISCOVERY_SERVER)])
        if "mft-sim" in self.services:  # not with --host on a host without the simulator
            self._check_interrupted()
            self.services["mft-sim"].start()
            self._wait_ready([self.services["mft-sim"]])
        self.ready_s = time.monotonic() - t0
        log(f"all {len(self.services)} services ready in {self.ready_s:.2f} s (run folder {self.run_dir})", quiet)

    def _check_interrupted(self):
        if self.stop_flag is not None and self.stop_flag.is_set():
            raise Interrupted("interrupted while starting the stack")

    def _wait_ready(self, services):
        deadline = time.monotonic() + READY_TIMEOUT_S
        for svc in services:
            while not svc.ready.wait(0.05):
                self._check_interrupted()
                if not svc.alive():
                    raise SupervisorError(f"{svc.name} exited with status {svc.proc.returncode} before it was ready; "
                                          f"see {svc.log_path}:\n{tail(svc.log_path, 15)}")
                if time.monotonic() > deadline:
                    raise SupervisorError(f"{svc.name} not ready after {READY_TIMEOUT_S:.0f} s; see {svc.log_path}")

    def watch(self, quiet, until_sim_exits=True, stop_flag=None):
        """Runs until the sim ends (or stop_flag is set); restarts crashed services in realtime mode."""
        sim = self.services.get("mft-sim")  # absent with --host on a host without the simulator (up only)
        timeout = float(self.scenario["duration_s"]) * 20.0 + 60.0 if until_sim_exits else None
        t_end = time.monotonic() + timeout if timeout else None
        while True:
            if stop_flag is not None and stop_flag.is_set():
                return
            if until_sim_exits and not sim.alive():
                return
            for svc in self.services.values():
                if svc.alive() or svc.name == "mft-sim" and until_sim_exits:
                    continue
                code = svc.proc.returncode
                self.events.append({"service": svc.name, "event": "exited", "status": code, "time": time.time()})
                if self.args.mode == "realtime" and svc.restarts < len(RESTART_BACKOFF_S):
                    delay = RESTART_BACKOFF_S[svc.restarts]
                    log(f"{svc.name} exited with status {code}; restarting in {delay:.1f} s", quiet)
                    time.sleep(delay)
                    svc.restarts += 1
                    svc.start()
                    self.events.append({"service": svc.name, "event": "restarted", "time": time.time()})
                    if self.on_restart is not None:
                        self.on_restart()
                else:
                    self.failed.append(svc.name)
                    raise SupervisorError(f"{svc.name} exited with status {code} (mode {self.args.mode}); "
                                          f"see {svc.log_path}:\n{tail(svc.log_path, 15)}")
            if t_end and time.monotonic() > t_end:
                raise SupervisorError(f"the run did not end within {timeout:.0f} s; stopping it")
            time.sleep(0.02)

    def stop_all(self, grace_s=STOP_GRACE_S):
        # Stop the clock first and wait for it, then the rest, the discovery server last; SIGKILL after a grace
        # period. The simulator goes first and alone: a controller that ended before it would leave the robot to
        # the watchdog's damping for the simulator's last ticks, and on a loaded machine those were enough to
        # sag a standing robot by 1.6 cm before the summary took its final height.
        if "mft-sim" in self.services:
            self.stop_one("mft-sim", time.monotonic() + grace_s)
        deadline = time.monotonic() + grace_s
        rest = [n for n in self.services if n not in ("mft-sim", DISCOVERY_SERVER)]
        for name in rest:
            self.services[name].signal(signal.SIGTERM)
        for name in rest:
            self.stop_one(name, deadline, signalled=True)
        if DISCOVERY_SERVER in self.services:
            self.stop_one(DISCOVERY_SERVER, deadline)

        if self.chain_shm:  # mft-sim unlinks it once the chain is attached; this covers a stack that never got there
            try:
                os.unlink("/dev/shm" + self.chain_shm)
            except OSError:
                pass

    def stop_one(self, name, deadline, signalled=False):
        svc = self.services[name]
        if not signalled:
            svc.signal(signal.SIGTERM)
        if svc.wait(max(0.0, deadline - time.monotonic())) is None and svc.alive():
            svc.signal(signal.SIGKILL)
            svc.wait(2.0)
            self.events.append({"service": name, "event": "killed after grace period", "time": time.time()})

    def pids(self):
        return {n: s.proc.pid for n, s in self.services.items() if s.proc is not None}

    def hosts(self):
        return {n: s.host for n, s in self.services.items()} if self.stack else None


ANSI_ESCAPE = re.compile(r"\x1b\[[0-9;]*[A-Za-z]")


def tail(path, n):
    """The last n lines of a service log, without Fast DDS's colour codes (docs/reference/dds.md#log-output)."""
    try:
        lines = Path(path).read_text(errors="replace").splitlines()
    except OSError:
        return ""
    return "\n".join("    " + ANSI_ESCAPE.sub("", l) for l in lines[-n:])


def make_run_dir(path):
    """The run folder must be a directory this process can write: refused before anything starts otherwise
    (an existing file, /proc, a read-only file system, no permission)."""
    path = Path(path)
    if path.exists() and not path.is_dir():
        raise SupervisorError(f"run folder {path} exists and is not a directory (--run-dir)")
    try:
        path.mkdir(parents=True, exist_ok=True)
        probe = path / f".mft-supervisor-{os.getpid()}"
        probe.write_bytes(b"")
        probe.unlink()
    except OSError as e:
        raise SupervisorError(f"cannot write the run folder {path}: {e.strerror or e} (--run-dir)")


class LossyLog:
    """A service log that survives a full disk: a failed write is remembered (and reported in the summary),
    the child's output keeps being drained so that it never blocks on a full pipe."""

    def __init__(self, svc):
        self.svc = svc
        self.f = None
        try:
            self.f = open(svc.log_path, "ab", buffering=0)
        except OSError as e:
            svc.log_lost = os_problem(e)

    def write(self, data):
        if self.f is None:
            return
        try:
            self.f.write(data)
        except OSError as e:
            self.svc.log_lost = self.svc.log_lost or os_problem(e)

    def close(self):
        if self.f is not None:
            try:
                self.f.close()
            except OSError as e:
                self.svc.log_lost = self.svc.log_lost or os_problem(e)


def open_service_log(svc):
    logf = LossyLog(svc)
    logf.write(f"--- start {time.strftime('%H:%M:%S')}: {' '.join(svc.argv)}\n".encode())
    return logf


def write_atomically(path, text):
    # Readers (status, down, a waiting `up`) never see a half-written file.
    tmp = path.with_suffix(path.suffix + ".tmp")
    tmp.write_text(text)
    os.replace(tmp, path)


def read_json(path):
    try:
        return json.loads(path.read_text())
    except (OSError, ValueError):
        return {}


def process_start_time(pid):
    """The start time of a live process (clock ticks since boot, /proc/PID/stat field 22), or None when it has
    ended or is a zombie: with the pid it identifies one process, so a reused pid is not mistaken for it."""
    try:
        fields = Path(f"/proc/{int(pid)}/stat").read_text().rsplit(")", 1)[1].split()
    except (OSError, ValueError, IndexError):
        return None
    return None if fields[0] in ("Z", "X") else int(fields[19])


def watch_process(pid, stop, what):
    """Sets `stop` when process pid ends (polled every 0.2 s by a daemon thread). Raises SupervisorError when it
    is not running now."""
    started = process_start_time(pid)
    if started is None:
        raise SupervisorError(f"--watch-pid {pid}: no such process")

    def poll():
        while not stop.wait(0.2):
            if process_start_time(pid) != started:
                log(f"the watched process {pid} has ended: stopping {what}")
                stop.set()
    threading.Thread(target=poll, daemon=True).start()


def pid_alive(pid):
    if not pid:
        return False
    try:
        os.kill(int(pid), 0)
        return not _is_zombie(int(pid))
    except (ProcessLookupError, PermissionError, ValueError):
        return False
