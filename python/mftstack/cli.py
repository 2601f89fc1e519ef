"""mft-supervisor: starts, watches and stops an mft-wbc stack (sim, estimator, planner, wbc, recorder).

Every service is a separate process on one DDS domain. The supervisor validates everything before it starts
anything, waits for each service's "READY <name>" line, restarts a crashed service with back-off (realtime
mode), stops everything cleanly, and never leaves an orphan: every child gets PR_SET_PDEATHSIG, so even a
`kill -9` of the supervisor takes its children with it.

Service contract (every mft-<service> executable):
  --domain N --scenario FILE --mode lockstep|realtime --config-dir DIR --summary FILE [--forever]
  prints "READY <service>" on stdout once its DDS endpoints are matched; writes a JSON summary at exit;
  exits 0 on SIGINT/SIGTERM. mft-sim ends the run at the scenario's duration (unless --forever) and
  `mft-sim --check-scenario FILE --json` validates a scenario and prints it as JSON.
  `--profiles FILE` replaces the DDS profile file (default: dds_profiles.xml of --config-dir).
  `--check-config` (with the same options) loads every configuration file the service reads and the DDS profile
  file, prints "<service>: configuration ok" and exits 0, or prints the error and exits 2, starting nothing.

Before it starts anything the supervisor validates the scenario, runs every service's --check-config, refuses
an existing --record file (unless --overwrite) and refuses a DDS domain on which participants already answer
(`mft-participants`, from each host of a stack file). docs/results/faults.md "Bad input and misuse" lists every case.
  `--profile NAME` (repeatable) applies the configuration profile config/profiles/NAME.yaml after the
  scenario's own `profiles` (docs/guide/profiles.md); the supervisor passes its --profile options to every service.

Multi-host (`--stack FILE`, docs/guide/distributed.md): a stack file names hosts (an address, optionally a network
namespace), places each service on one, and chooses discovery by initial peers or a Fast DDS discovery server.
The supervisor writes one DDS profile per host into the run folder (the project's profile bound to the host's
address, with every host's address as initial peer or the server as discovery server), starts each service
on its host (`ip netns exec NS` where the host names a namespace) and, for `discovery: server`, supervises
`fast-discovery-server` on its host like any other child. Without `--stack` nothing changes.
"""
import argparse
import json
import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

from .checks import (DOMAIN_CHECKED_ENV, check_before_start, check_common, check_domain_range, check_record_target,
                     load_scenario)
from .errors import Interrupted, SupervisorError, error_text, log
from .paths import DEFAULT_BIN, DEFAULT_CONFIG, DEFAULT_RUNS
from .processes import (ANSI_ESCAPE, READY_TIMEOUT_S, SECURE_RUN_ATTEMPTS, SECURE_START_TIMEOUT_S, STOP_GRACE_S, Stack,
                        pid_alive, process_start_time, read_json, tail, watch_process, write_atomically)
from .summary import build_summary, print_summary, report_unwritten, write_summary_file

# On Ctrl-C the children get this long to stop before SIGKILL (an interrupted start must end promptly).
INTERRUPT_GRACE_S = 0.8



def spin_us(text):
    """--sim-spin-us: whole microseconds, 0..900 (mft-sim's own range)."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected whole microseconds, got '{text}'")
    if not 0 <= value <= 900:
        raise argparse.ArgumentTypeError(f"expected 0..900 us, got {value}")
    return value

def this_run_lines(path, offset, n):
    """The last n lines a detached `up` wrote to its appended log, from `offset` on (not earlier stacks')."""
    try:
        with open(path, "rb") as f:
            f.seek(offset)
            lines = f.read().decode(errors="replace").splitlines()
    except OSError:
        return ""
    return "\n".join("    " + ANSI_ESCAPE.sub("", l) for l in lines[-n:])


def stop_on_signals():
    """A threading.Event that SIGTERM and SIGINT set: the stack is stopped in order instead of the process dying."""
    stop = threading.Event()
    signal.signal(signal.SIGTERM, lambda *_: stop.set())
    signal.signal(signal.SIGINT, lambda *_: stop.set())
    return stop


def cmd_run(args):
    check_common(args)
    scenario = load_scenario(args)
    if args.checked_before:
        check_record_target(args)
    else:
        check_before_start(args)
    error = None
    stop = stop_on_signals()
    stack = Stack(args, scenario)
    stack.stop_flag = stop
    t0 = time.monotonic()
    attempts = SECURE_RUN_ATTEMPTS if getattr(args, "secure", None) else 1
    for attempt in range(1, attempts + 1):
        error = None
        try:
            stack.start_all(args.json)
            log(f"running {scenario['name']} for {scenario['duration_s']} s of simulated time ({args.mode})", args.json)
            stack.watch(args.json, until_sim_exits=True, stop_flag=stop)
            if stop.is_set():
                error = "interrupted"
            else:
                code = stack.services["mft-sim"].proc.returncode
                if code != 0:
                    error = f"mft-sim exited with status {code}; see {stack.services['mft-sim'].log_path}"
        except Interrupted:
            error = "interrupted"
        except SupervisorError as e:
            error = str(e)
        finally:
            stack.stop_all(INTERRUPT_GRACE_S if stop.is_set() else STOP_GRACE_S)
        if not (error and attempt < attempts and secure_handshake_stuck(stack)) or stop.is_set():
            break
        print(f"mft-supervisor: the secured chain did not connect (Fast DDS secure handshake; see "
              f"{stack.services['mft-sim'].log_path}): starting the stack again, attempt {attempt + 1} of {attempts}",
              file=sys.stderr, flush=True)
        stack = Stack(args, scenario)
        stack.stop_flag = stop
    wall = time.monotonic() - t0
    stop_failures = []
    for name, svc in stack.services.items():
        if svc.proc is not None and svc.proc.returncode not in (0, None, -signal.SIGTERM) and name not in stack.failed:
            stack.failed.append(name)
            killed = any(e["service"] == name and e["event"] == "killed after grace period" for e in stack.events)
            stop_failures.append(f"{name} exited with status {svc.proc.returncode}"
                                 + (f" (killed: it had not stopped {STOP_GRACE_S:.0f} s after SIGTERM)" if killed else "")
                                 + f"; see {svc.log_path}")
    if stop_failures and error is None:  # a service that failed only at the stop says how, not just its name
        error = "; ".join(stop_failures)
    summary = build_summary(stack, wall, error)
    summary["failed"] = stack.failed
    summary["ok"] = error is None and not stack.failed
    not_written = [f"{s.log_path}: {s.log_lost}" for s in stack.services.values() if s.log_lost]
    summary["not_written"] = not_written
    # The result first, on stdout, whatever the disk says; then the file.
    if args.json:
        print(json.dumps(summary, indent=2), flush=True)
    else:
        print_summary(summary)
        sys.stdout.flush()
    problem = write_summary_file(stack, summary)
    report_unwritten(not_written + ([problem] if problem else []))
    if stop.is_set():
        print("mft-supervisor: interrupted: every service stopped", file=sys.stderr, flush=True)
        return 130
    if not summary["ok"]:  # a failed run says so on stderr too, whatever the summary format
        print(f"mft-supervisor: run failed: {error or ', '.join(stack.failed) + ' failed'}", file=sys.stderr, flush=True)
    return 0 if summary["ok"] else 1


def wait_for_secured_chain(sim_log, supervisor):
    """A secured stack is up once its chain answered: a stuck handshake makes the simulator give up after
    SECURE_START_TIMEOUT_S and the supervisor restarts it, which authenticates afresh."""
    deadline = time.monotonic() + SECURE_START_TIMEOUT_S * 3 + 5
    while time.monotonic() < deadline and supervisor.poll() is None:
        try:
            if "the chain answered tick 0" in sim_log.read_text(errors="replace"):
                return
        except OSError:
            pass
        time.sleep(0.1)
    print(f"mft-supervisor: warning: the secured chain has not answered yet (see {sim_log})", file=sys.stderr, flush=True)


def secure_handshake_stuck(stack):
    """The simulator gave up because its secured chain never matched (not a crash, not a fall): either its own
    endpoints never matched, or they did and tick 0 never came back (a hop further down the chain, e.g.
    estimator -> planner, is stuck in its handshake; seen once in a 20-run series with a busy core)."""
    sim = stack.services.get("mft-sim")
    if sim is None or sim.proc is None or sim.proc.returncode != 3:
        return False
    try:
        tail_text = Path(sim.log_path).read_text(errors="replace")[-4000:]
    except OSError:
        return False
    return "did not connect" in tail_text or "no JointCommand for tick 0 within" in tail_text


def state_file(domain, host=None):
    # One supervisor per host of a stack file (--host) may share a machine and a domain: one state file each.
    return DEFAULT_RUNS / (f"stack-d{domain}-{host}.json" if host else f"stack-d{domain}.json")


def cmd_up(args):
    check_common(args)
    scenario = load_scenario(args)
    sf = state_file(args.domain, args.host)
    on = f" (host {args.host})" if args.host else ""
    if sf.exists():
        st = read_json(sf)
        if pid_alive(st.get("supervisor_pid")):
            raise SupervisorError(f"a stack is already up on domain {args.domain}{on} (supervisor pid {st['supervisor_pid']})")
    if args.watch_pid is not None and process_start_time(args.watch_pid) is None:
        raise SupervisorError(f"--watch-pid {args.watch_pid}: no such process")
    check_before_start(args)
    if not args.foreground:
        # Detach: re-run this command in the foreground in a new session, logging to the runs folder.
        DEFAULT_RUNS.mkdir(parents=True, exist_ok=True)
        argv = [sys.executable, str(Path(sys.argv[0]).resolve())] + sys.argv[1:] + ["--foreground"]  # the launcher
        sup_log = DEFAULT_RUNS / (f"supervisor-d{args.domain}-{args.host}.log" if args.host else f"supervisor-d{args.domain}.log")
        out = open(sup_log, "ab")
        log_start = out.seek(0, os.SEEK_END)  # the log is appended to: a failure shows this run's lines only
        child = subprocess.Popen(argv, stdout=out, stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL,
                                 start_new_session=True, env=dict(os.environ, **{DOMAIN_CHECKED_ENV: str(args.domain)}))
        deadline = time.monotonic() + READY_TIMEOUT_S * 2
        while time.monotonic() < deadline:
            st = read_json(sf)
            if st.get("supervisor_pid") == child.pid:
                if getattr(args, "secure", None) and "mft-sim" in st.get("services", {}):
                    wait_for_secured_chain(Path(st["run_dir"]) / "mft-sim.log", child)
                hopt = f" --host {args.host}" if args.host else ""
                print(f"stack up on domain {args.domain}{on} (supervisor pid {child.pid}); "
                      f"'mft-supervisor status --domain {args.domain}{hopt}' to watch, 'down' to stop")
                return 0
            if child.poll() is not None:
                raise SupervisorError(f"the stack failed to start; see {sup_log}:\n{this_run_lines(sup_log, log_start, 15)}")
            time.sleep(0.1)
        raise SupervisorError("the stack did not come up in time")
    args.forever = True
    stop = stop_on_signals()
    if args.watch_pid is not None:
        watch_process(args.watch_pid, stop, f"the stack on domain {args.domain}{on}")
    stack = Stack(args, scenario)
    stack.stop_flag = stop
    started = time.time()
    # The state file names the pid of every service; a restarted service gets a new one (status reads it).
    stack.on_restart = lambda: write_state_file(sf, args, scenario, stack, started)
    try:
        stack.start_all(False)
        write_state_file(sf, args, scenario, stack, started)
        stack.watch(False, until_sim_exits=False, stop_flag=stop)
    finally:
        stack.stop_all(INTERRUPT_GRACE_S if stop.is_set() else STOP_GRACE_S)
        if read_json(sf).get("supervisor_pid") == os.getpid():
            sf.unlink()
    return 0


def write_state_file(sf, args, scenario, stack, started):
    write_atomically(sf, json.dumps({"supervisor_pid": os.getpid(), "domain": args.domain, "mode": args.mode,
                                     "scenario": scenario["name"], "profiles": scenario.get("profiles", []), "run_dir": str(stack.run_dir),
                                     "services": stack.pids(), "hosts": stack.hosts(),
                                     "stack": str(stack.stack.path) if stack.stack else None,
                                     "started": started}))


def read_state(domain, host=None):
    sf = state_file(domain, host)
    if not sf.exists():
        raise SupervisorError(f"no stack is up on domain {domain}" + (f" for host {host}" if host else ""))
    return json.loads(sf.read_text())


def cmd_status(args):
    check_domain_range(args.domain)
    st = read_state(args.domain, args.host)
    hosts = st.get("hosts") or {}
    services = {n: {"pid": p, "alive": pid_alive(p), **({"host": hosts.get(n)} if hosts else {})}
                for n, p in st["services"].items()}
    out = {"domain": args.domain, "supervisor_pid": st["supervisor_pid"], "supervisor_alive": pid_alive(st["supervisor_pid"]),
           "scenario": st["scenario"], "mode": st["mode"], "run_dir": st["run_dir"], "services": services,
           "uptime_s": round(time.time() - st["started"], 1), "stack": st.get("stack"),
           "live_changes": live_changes(Path(st["run_dir"])), "warnings": run_dir_warnings(Path(st["run_dir"]))}
    if args.json:
        print(json.dumps(out, indent=2))
    else:
        print(f"domain {args.domain}: {st['scenario']} ({st['mode']}), supervisor pid {st['supervisor_pid']} "
              f"{'alive' if out['supervisor_alive'] else 'DEAD'}, up {out['uptime_s']} s, run folder {st['run_dir']}")
        if st.get("stack"):
            print(f"  stack file {st['stack']}")
        for n, s in services.items():
            where = f"  on {s['host']}" if s.get("host") else ""
            print(f"  {n:{16 if hosts else 14}s} pid {s['pid']:<8d} {'running' if s['alive'] else 'not running'}{where}")
        for n, changes in out["live_changes"].items():
            for c in changes:
                print(f"  live change    {n}: {c['key']} = {c['value']} (was {c['previous']}) from tick {c['tick']} "
                      f"(t = {c['time_s']:.3f} s), seq {c['seq']}")
        for w in out["warnings"]:
            print(f"  warning: {w}")
    return 0 if out["supervisor_alive"] else 1


RUN_DIR_FULL_BYTES = 64 * 1024  # less free than this: a service's next log line or tuning file may not fit


def run_dir_warnings(run_dir):
    """What status cannot vouch for: on a full disk the services cannot write their live-change lists
    (*.tuning.json) or logs, so an empty list would read as "no live changes"."""
    try:
        st = os.statvfs(run_dir)
    except OSError as e:
        return [f"cannot inspect the run folder {run_dir}: {e.strerror}"]
    free = st.f_bavail * st.f_frsize
    if free < RUN_DIR_FULL_BYTES:
        return [f"the run folder's disk is full ({free // 1024} kB free): live changes, logs and summaries written "
                "since may be missing"]
    return []


def live_changes(run_dir):
    """The changes mft-cmd --set made while the stack runs, per service, oldest first: mft-wbc and mft-planner
    list them in <run_dir>/<service>.tuning.json, rewritten (whole) by a thread of the service after each change
    (docs/guide/live-tuning.md). A service that takes none has an empty list; one without the file is not listed."""
    out = {}
    for path in sorted(Path(run_dir).glob("*.tuning.json")):
        try:
            data = json.loads(path.read_text())
        except (OSError, ValueError):
            continue  # being replaced: the next status reads it whole
        out[data.get("service", path.name[:-len(".tuning.json")])] = data.get("applied", [])
    return out


def cmd_down(args):
    check_domain_range(args.domain)
    if not state_file(args.domain, args.host).exists():
        # Not an error: after `down` nothing runs on the domain, which is what was asked.
        print(f"no stack is up on domain {args.domain}" + (f" for host {args.host}" if args.host else "") +
              ": nothing to stop")
        return 0
    st = read_state(args.domain, args.host)
    pid = st["supervisor_pid"]
    if pid_alive(pid):
        os.kill(pid, signal.SIGTERM)
        deadline = time.monotonic() + STOP_GRACE_S * 3
        while pid_alive(pid) and time.monotonic() < deadline:
            time.sleep(0.05)
    leftovers = [n for n, p in st["services"].items() if pid_alive(p)]
    sf = state_file(args.domain, args.host)
    if sf.exists():
        sf.unlink()
    if leftovers:
        raise SupervisorError(f"still running after down: {', '.join(leftovers)}")
    print(f"stack on domain {args.domain} stopped")
    return 0


def positive_count(text):
    """An argparse type: an integer >= 1."""
    try:
        n = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a whole number >= 1, got {text!r}")
    if n < 1:
        raise argparse.ArgumentTypeError(f"expected a whole number >= 1, got {n}")
    return n


def cmd_logs(args):
    check_domain_range(args.domain)
    st = read_state(args.domain, args.host)
    run_dir = Path(st["run_dir"])
    if args.service and args.service not in st["services"]:  # a name, never a path out of the run folder
        raise SupervisorError(f"no service {args.service!r} in the stack on domain {args.domain} "
                              f"(services: {', '.join(st['services'])})")
    names = [args.service] if args.service else list(st["services"])
    for n in names:
        path = run_dir / f"{n}.log"
        if not path.exists():
            raise SupervisorError(f"no log for {n} in {run_dir}")
        print(f"==> {path} <==")
        print(tail(path, args.lines).replace("    ", "", 1) if args.lines else path.read_text(errors="replace"))
    return 0


def stack_options(sp):
    """The options of a command that starts a stack (run, up)."""
    sp.add_argument("scenario", help="scenario file (config/scenarios/*.yaml)")
    sp.add_argument("--domain", type=int, default=0, help="DDS domain id, 0..232 (default 0)")
    sp.add_argument("--mode", default="lockstep", help="lockstep (deterministic, as fast as possible) or realtime")
    sp.add_argument("--record", metavar="FILE", help="record every topic to this MRPT rawlog (an existing "
                    "recording is refused)")
    sp.add_argument("--overwrite", action="store_true", help="with --record: replace an existing recording")
    sp.add_argument("--bin-dir", default=str(DEFAULT_BIN), help=f"where the service executables are (default {DEFAULT_BIN})")
    sp.add_argument("--config-dir", default=str(DEFAULT_CONFIG), help=f"configuration folder (default {DEFAULT_CONFIG})")
    sp.add_argument("--profile", action="append", metavar="NAME",
                    help="configuration profile config/profiles/NAME.yaml, after the scenario's (repeatable, "
                         "applied in order; docs/guide/profiles.md)")
    sp.add_argument("--run-dir", help="folder for logs and summaries (default runs/<scenario>-<time>-d<domain>)")
    sp.add_argument("--no-rt", action="store_true", help="realtime mode: do not ask for SCHED_FIFO")
    sp.add_argument("--stall-probe", action="store_true", help="realtime: run the simulator's CPU stall probe "
                    "(one SCHED_FIFO thread per CPU, 1 ms): the summary then says which deadline misses fell in "
                    "a stall of the machine (costs ~30 us of p50 latency on a 2-vCPU VM)")
    sp.add_argument("--rt-priorities", choices=["chain", "flat"], help="realtime: SCHED_FIFO "
                    "priorities rising along the chain to the simulator (chain: estimator 76, planner 77, wbc 78, "
                    "sim 79; with the chain on one core each hand-off is a same-core preemption; the default for a "
                    "chain pinned to one core on the shared-memory channel) or 80 for all (flat: the default "
                    "otherwise, e.g. with --secure or --stack); docs/results/loop-benchmark.md")
    sp.add_argument("--rt-threads", choices=["loop", "all"], default="loop", help="realtime, the chain on the "
                    "shared-memory channel: loop (the default) gives the chain's priorities only to its 1 kHz threads, "
                    "on the chain's core, and runs each service's other threads (DDS's own) at SCHED_FIFO 1 on the "
                    "other CPUs; all: every thread at the service's priority on the chain's core (as a DDS chain "
                    "always runs); docs/results/loop-benchmark.md")
    sp.add_argument("--sim-spin-us", type=spin_us, default=0, metavar="US", help="realtime: the simulator wakes this "
                    "long before each 1 kHz deadline and polls the clock to it (0..900; default 0: sleeps to it)")
    sp.add_argument("--chain-cpu", metavar="N|auto|none", help="pin the control chain (sim, estimator, planner, "
                    "wbc) to CPU N and the recorder to the other CPUs: every hand-off of a tick stays on one core "
                    "(lockstep: faster, and recording costs less; realtime: a shorter and steadier sensor-to-command "
                    "latency; docs/results/loop-benchmark.md); auto (the default): on the CPU the stack's domain picks "
                    "(domain modulo the CPUs allowed), --stack unpinned; none: no pinning")
    sp.add_argument("--chain-transport", choices=["shm", "dds"],
                    help="how the chain's topics go from service to service: shm (a shared-memory segment per "
                    "stack, a hop about one thread wake-up; DDS still carries every topic to every reader outside "
                    "the chain, and the chain still hears DDS writers from outside the stack, such as mft-inject) "
                    "or dds (DDS alone). Default: shm. --secure and --stack always use DDS "
                    "(docs/results/loop-benchmark.md)")
    sp.add_argument("--secure", metavar="DIR", help="DDS Security: authenticate, access-control and encrypt with the "
                    "identities in DIR (scripts/make-security.sh; docs/guide/security.md)")
    sp.add_argument("--stack", metavar="FILE", help="multi-host: place each service on a host of this stack file "
                    "(config/stacks/*.yaml; docs/guide/distributed.md); default: every service here on 127.0.0.1")
    sp.add_argument("--host", metavar="NAME", help="with --stack: start only the services placed on this host (one "
                    "supervisor per machine; 'run' on the simulator's host, 'up' on the others)")


def build_parser():
    p = argparse.ArgumentParser(prog="mft-supervisor", description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = p.add_subparsers(dest="command", required=True)
    sp = sub.add_parser("run", help="run a scenario to its end and print a summary")
    stack_options(sp)
    sp.add_argument("--json", action="store_true", help="print the summary as JSON")
    sp.add_argument("--checked-before", action="store_true", help="skip the service configuration checks and the "
                    "busy-domain probe (about 1.2 s a run): only for a caller that owns the domain and ran a checked "
                    "run with the same configuration and profiles on it moments ago (mft-experiment's workers); the "
                    "scenario and the --record target are still checked")
    sp.set_defaults(func=cmd_run)
    sp = sub.add_parser("up", help="start a long-running stack in the background")
    stack_options(sp)
    sp.add_argument("--foreground", action="store_true", help="stay in the foreground")
    sp.add_argument("--watch-pid", type=int, metavar="PID", help="take the stack down when process PID ends (a test "
                    "passes its own pid, so a test killed by a timeout leaves no stack behind)")
    sp.set_defaults(func=cmd_up)
    for name, func, hlp in (("status", cmd_status, "show the stack of a domain (exit 2 when none is up)"),
                            ("down", cmd_down, "stop the stack of a domain (exit 0 when none is up: nothing runs "
                                               "there afterwards either way)")):
        sp = sub.add_parser(name, help=hlp, description=hlp)
        sp.add_argument("--domain", type=int, default=0)
        sp.add_argument("--host", metavar="NAME", help="the stack of this host (started with up --host NAME)")
        sp.add_argument("--json", action="store_true")
        sp.set_defaults(func=func)
    sp = sub.add_parser("logs", help="print the logs of a running stack")
    sp.add_argument("service", nargs="?", help="one service (default: all)")
    sp.add_argument("--domain", type=int, default=0)
    sp.add_argument("--lines", type=positive_count, default=0, help="only the last N lines (N >= 1)")
    sp.add_argument("--host", metavar="NAME", help="the stack of this host (started with up --host NAME)")
    sp.set_defaults(func=cmd_logs)

    return p


def main(argv=None):
    p = build_parser()
    args = p.parse_args(argv)
    if hasattr(args, "record") and getattr(args, "record", None) is None:
        args.record = None
    try:
        return args.func(args)
    except Interrupted as e:
        print(f"mft-supervisor: {e}: every service stopped", file=sys.stderr)
        return 130
    except KeyboardInterrupt:
        print("mft-supervisor: interrupted before anything started", file=sys.stderr)
        return 130
    except (SupervisorError, UnicodeDecodeError, OSError) as e:
        print(f"mft-supervisor: error: {error_text(e)}", file=sys.stderr)
        return 2
