#!/usr/bin/env python3
"""A stand-in for any mft-<service> executable that follows the supervisor's service contract, so the
supervisor's own logic (readiness, restart with back-off, failure handling, clean stop, no orphans) is tested
without DDS. Behaviour per service comes from FAKE_SERVICES, e.g. "mft-wbc:crash_after=0.3:crash_times=1".
The pids it ran as are appended to $FAKE_PID_LOG."""
import json
import os
import signal
import sys
import time
from pathlib import Path

name = Path(sys.argv[0]).name
args = sys.argv[1:]


def opt(key, default=None):
    return args[args.index(key) + 1] if key in args else default


if name == "mft-participants":
    # The supervisor's domain probe: the participants listed in $FAKE_PARTICIPANTS (a JSON list) answer.
    print(json.dumps({"domain": int(opt("--domain")), "participants": json.loads(os.environ.get("FAKE_PARTICIPANTS", "[]"))}))
    sys.exit(0)

if "--check-config" in args:
    # FAKE_CHECK_CONFIG="mft-wbc=message": that service refuses its configuration with the message.
    for spec in filter(None, os.environ.get("FAKE_CHECK_CONFIG", "").split(",")):
        service, message = spec.split("=", 1)
        if service == name:
            print(f"{name}: {message}\nTry '{name} --help'.", file=sys.stderr)
            sys.exit(2)
    with open(os.environ["FAKE_PID_LOG"] + ".checks", "a") as f:
        f.write(f"{name} {os.getpid()}\n")
    time.sleep(float(os.environ.get("FAKE_CHECK_SLOW", "0")))  # a slow validation (Ctrl-C during it)
    print(f"{name}: configuration ok")
    sys.exit(0)

if "--check-scenario" in args:
    path = Path(opt("--check-scenario"))
    text = path.read_text()
    fields = dict(l.split(":", 1) for l in text.splitlines() if ":" in l and not l.startswith((" ", "#")))
    print(json.dumps({"name": fields["name"].strip(), "duration_s": float(fields["duration_s"].split("#")[0])}))
    sys.exit(0)

behaviour = {}
for spec in os.environ.get("FAKE_SERVICES", "").split(","):
    parts = spec.split(":")
    if parts[0] == name:
        behaviour = dict(p.split("=") for p in parts[1:])
with open(os.environ["FAKE_PID_LOG"], "a") as f:
    f.write(f"{name} {os.getpid()}\n")

# Crash count across restarts: a file per service in the run folder.
summary_path = Path(opt("--summary"))
crash_file = summary_path.with_suffix(".crashes")
crashes = int(crash_file.read_text()) if crash_file.exists() else 0

stop = False


def started_before(service):
    """How many times SERVICE has been started so far, this start included ($FAKE_PID_LOG)."""
    return sum(1 for l in Path(os.environ["FAKE_PID_LOG"]).read_text().splitlines() if l.split()[0] == service)


def on_term(*_):
    global stop
    stop = True


signal.signal(signal.SIGTERM, signal.SIG_IGN if "ignore_term" in behaviour else on_term)  # a service hung at stop
signal.signal(signal.SIGINT, on_term)
# stuck_start=N: the first N starts (counted in $FAKE_PID_LOG) end as a secured simulator does whose chain never
# answered tick 0 (a DDS Security handshake stuck further down the chain).
if started_before(name) <= int(behaviour.get("stuck_start", "0")):
    print(f"{name}: timeout: no JointCommand for tick 0 within 10 s (is mft-wbc running?)", file=sys.stderr, flush=True)
    sys.exit(3)
if "fail_start" in behaviour:  # exits before it is ready, with this message
    print(f"{name}: {behaviour['fail_start']}", flush=True)
    sys.exit(3)
time.sleep(float(behaviour.get("ready_after", "0")))  # a slow start (Ctrl-C at spawn)
print(f"READY {name}", flush=True)
t0 = time.monotonic()
run_for = float(behaviour.get("run_for", "1e9"))
crash_after = float(behaviour.get("crash_after", "1e9"))
crash_times = int(behaviour.get("crash_times", "1000"))
# until_started=SERVICE/N: end (before run_for) once SERVICE has been started N times, so that a run lasts as
# long as the restarts it tests take, not a fixed time that a loaded machine may not give them.
until_service, _, until_count = behaviour.get("until_started", "/0").partition("/")


def started(service):
    try:
        return sum(1 for l in Path(os.environ["FAKE_PID_LOG"]).read_text().splitlines() if l.split()[0] == service)
    except OSError:
        return 0


while not stop:
    t = time.monotonic() - t0
    if t > crash_after and crashes < crash_times:
        crash_file.write_text(str(crashes + 1))
        os._exit(3)
    if t > run_for or (until_service and started(until_service) >= int(until_count)):
        break
    time.sleep(0.01)
summary = {"service": name, "ran_s": time.monotonic() - t0}
if name == "mft-sim":
    summary.update({"fell": False, "sim_time_s": 1.0, "ticks": 1000, "deadline_misses": 0})
if name == "mft-wbc":
    summary.update({"solve_time_us": {"mean": 5.0, "p99": 9.0, "max": 20.0}, "safety_events": 0})
try:
    summary_path.write_text(json.dumps(summary))
except OSError as e:  # as the real services do (ServiceContext::writeSummary): the summary on stdout instead
    print(f"{name}: cannot write the summary {summary_path}: {e.strerror}", file=sys.stderr)
    print("SUMMARY " + json.dumps(summary), flush=True)
