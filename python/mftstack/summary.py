"""The run's summary: built from the services' summaries, printed (text or JSON) and written to summary.json."""
import json
import sys
from pathlib import Path

from .processes import write_atomically


def write_summary_file(stack, summary):
    """summary.json of the run; returns what could not be written (the summary itself is printed anyway)."""
    path = stack.run_dir / "summary.json"
    try:
        write_atomically(path, json.dumps(summary, indent=2))
        return None
    except OSError as e:
        return f"{path}: {e.strerror or e}"


def report_unwritten(not_written):
    """A full disk never loses a result silently: name every file that could not be written."""
    for item in not_written:
        print(f"mft-supervisor: warning: could not write {item}", file=sys.stderr, flush=True)
    if not_written:
        print("mft-supervisor: the summary printed above is complete; the files named here are missing or cut short",
              file=sys.stderr, flush=True)


STALL_PROBE_PERIOD_NS = 1_000_000  # mft-sim --stall-probe-us 1000, as the supervisor starts it
READER_DEADLINE_NS = 3_000_000     # the control_reader profile's deadline (config/dds_profiles.xml)


def stalled_within(stalls, t0, t1):
    """Nanoseconds of [t0, t1] during which some CPU stood still: the union of the stall windows overlapping it."""
    hits = sorted((max(a, t0), min(b, t1)) for a, b in stalls if b > t0 and a < t1)
    total, end = 0, t0
    for a, b in hits:
        a = max(a, end)
        if b > a:
            total, end = total + b - a, b
    return total


def gaps_in_stalls(gaps, stalls):
    """How many of a reader's gaps over its deadline the machine explains, by the simulator's rule for its own misses
    (services/runtime/stall_probe.hpp): some CPU stood still for at least half the deadline during the gap (widened
    by one probe period on each side, as a stall is recorded from the first probe wake-up it delayed)."""
    return sum(1 for a, b in gaps
               if 2 * stalled_within(stalls, a - STALL_PROBE_PERIOD_NS, b + STALL_PROBE_PERIOD_NS) >= READER_DEADLINE_NS)


def deadline_misses_by_service(stack):
    """Every service's deadline misses: the simulator's watchdog (those in a CPU stall of the machine apart, with
    --stall-probe) and each chain reader's while its topic flowed; the readers' misses before the stream starts and
    after it ends (the stack starting and stopping) apart, as `outside_stream`; the gaps between samples over the
    deadline that the reader measured itself (`gaps_over_deadline`: the rest of `reader` is Fast DDS's timer firing
    early; services/runtime/deadline_counts.hpp), and with --stall-probe how many of those fell in a CPU stall of
    the machine (`gaps_during_cpu_stalls`; the others are the chain's)."""
    sim = stack.services["mft-sim"].summary() if "mft-sim" in stack.services else None
    stalls = ((sim or {}).get("cpu_stalls") or {}).get("windows_ns")
    out = {}
    for name, svc in stack.services.items():
        s = svc.summary() or {}
        prefix = "reader_" if name == "mft-sim" else ""
        if prefix + "deadline_misses" not in s:
            continue
        gaps = s.get(prefix + "gap_windows_ns") or []
        m = {"reader": s.get(prefix + "deadline_misses"), "outside_stream": s.get(prefix + "deadline_misses_outside_stream"),
             "gaps_over_deadline": s.get(prefix + "gaps_over_deadline"),
             "gaps_during_cpu_stalls": gaps_in_stalls(gaps, stalls) if stalls is not None else None}
        if name == "mft-sim":
            m = dict(watchdog=s.get("deadline_misses"), during_cpu_stalls=s.get("deadline_misses_during_cpu_stalls"), **m)
        out[name] = m
    return out


def rt_threads(stack):
    """Which threads of the chain ran SCHED_FIFO in realtime: "loop" (the 1 kHz threads only: the chain channel),
    "all" (every thread: a DDS chain, or --rt-threads all); None in lockstep or with --no-rt."""
    args = stack.args
    if args.mode != "realtime" or getattr(args, "no_rt", False):
        return None
    return (getattr(args, "rt_threads", None) or "loop") if getattr(stack, "chain_shm", None) else "all"


def build_summary(stack, wall_s, error):
    sim = stack.services["mft-sim"].summary() or {}
    wbc = (stack.services["mft-wbc"].summary() if "mft-wbc" in stack.services else None) or {}
    out = {
        "scenario": stack.scenario["name"], "mode": stack.args.mode, "domain": stack.args.domain,
        "profiles": stack.scenario.get("profiles", []),
        "run_dir": str(stack.run_dir), "ok": error is None and not stack.failed, "error": error,
        "secure": bool(getattr(stack.args, "secure", None)), "chain_cpu": getattr(stack, "chain_cpu", None),
        "chain_transport": "shm" if getattr(stack, "chain_shm", None) else "dds",
        "rt_priorities": getattr(stack, "rt_priorities", None) if stack.args.mode == "realtime" else None,
        "rt_threads": rt_threads(stack),
        "stack": dict(stack.stack.describe(), services=stack.hosts(), only_host=stack.only_host) if stack.stack else None,
        "fell": sim.get("fell"), "sim_time_s": sim.get("sim_time_s"), "wall_time_s": round(wall_s, 3),
        "ticks": sim.get("ticks"), "real_time_factor": None,
        "deadline_misses": sim.get("deadline_misses", 0) + wbc.get("deadline_misses", 0),
        "deadline_misses_by_service": deadline_misses_by_service(stack),
        "restarts": sum(s.restarts for s in stack.services.values()),
        "wbc_solve_us": wbc.get("solve_time_us"), "wbc_tick_us": wbc.get("tick_time_us"),
        "wbc_safety_events": wbc.get("safety_events"),
        "sensor_to_command_latency_us": sim.get("latency_us") if stack.args.mode == "realtime" else None,
        "base_height_error_m": sim.get("base_height_error_m"), "pitch_error_rad": sim.get("pitch_error_rad"),
        "services": {n: s.summary() for n, s in stack.services.items()}, "events": stack.events,
    }
    if sim.get("sim_time_s") and wall_s > 0:
        out["real_time_factor"] = round(sim["sim_time_s"] / wall_s, 2)
    if stack.args.record:
        out["record"] = str(Path(stack.args.record).resolve())
    return out


def print_summary(s):
    def stats(d, unit):
        if not d:
            return "n/a"
        return f"mean {d.get('mean', float('nan')):.1f} {unit}, p99 {d.get('p99', float('nan')):.1f} {unit}, " \
               f"max {d.get('max', float('nan')):.1f} {unit}"
    print(f"scenario   {s['scenario']} ({s['mode']}, domain {s['domain']})")
    print(f"profiles   {', '.join(s.get('profiles') or []) or 'none (the paper setup)'}")
    print(f"result     {'FELL' if s['fell'] else 'no fall' if s['fell'] is not None else 'unknown'}"
          f"{'' if s['ok'] else '  [FAILED: ' + str(s['error'] or ', '.join(s.get('failed', []))) + ']'}")
    sim_t = s["sim_time_s"]
    print(f"time       sim {sim_t if sim_t is not None else 'n/a'} s, wall {s['wall_time_s']} s"
          f"{', ' + str(s['real_time_factor']) + 'x real time' if s['real_time_factor'] else ''}, ticks {s['ticks']}")
    print(f"health     deadline misses {s['deadline_misses']}, restarts {s['restarts']}, "
          f"WBC safety events {s['wbc_safety_events']}")
    if s.get("sensor_to_command_latency_us"):
        print(f"latency    sensor -> command {stats(s['sensor_to_command_latency_us'], 'us')}")
    print(f"wbc solve  {stats(s['wbc_solve_us'], 'us')}")
    print(f"wbc tick   {stats(s['wbc_tick_us'], 'us')}")
    bh, pe = s["base_height_error_m"], s["pitch_error_rad"]
    if bh:
        print(f"base z err rms {bh.get('rms', 0) * 1000:.1f} mm, max {bh.get('max', 0) * 1000:.1f} mm")
    if pe:
        print(f"pitch err  rms {pe.get('rms', 0):.4f} rad, max {pe.get('max', 0):.4f} rad")
    if s.get("stack"):
        st = s["stack"]
        where = ", ".join(f"{n} on {h}" for n, h in st["services"].items())
        print(f"stack      {st['file']} ({st['discovery']}): {where}")
    if s.get("record"):
        print(f"recording  {s['record']}")
    print(f"run folder {s['run_dir']}")
