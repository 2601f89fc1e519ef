#!/usr/bin/env python3
"""fault-matrix: runs the stack's fault matrix (docs/results/faults.md) and writes a Markdown table and JSON.

Every row starts a fresh realtime stack (services/mft-supervisor up, recording with mft-record), lets it
settle, applies one fault, watches, stops the stack and reads every service's summary:
  - for each service (sim, estimator, planner, wbc, record): kill -9, SIGSTOP 50 ms, SIGSTOP 2 s, restart
    (SIGTERM: a clean exit the supervisor answers with a restart);
  - for the recorder: disk full (its output on a small tmpfs mounted here, unmounted after) and a read-only
    target (a tmpfs remounted read-only);
  - for inputs: NaN, inf and out-of-range values injected on every topic by mft-inject (1 kHz topics: every
    real sample re-published corrupted with the next tick, so it is the newest; event topics at 20 Hz).
Each row reports the detection (who noticed, how long after the fault), what the stack did (damping, fall,
restart, refusal counters) and what was lost.

  scripts/fault-matrix.py [--bin-dir DIR] [--domain 200] [--out DIR] [--only REGEX] [--json]
"""
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "python"))
from mftstack.scripts import run_script, script_parser  # noqa: E402
from mftstack.paths import REPO, SUPERVISOR  # noqa: E402
from mftstack.testing import child_processes, pid_alive  # noqa: E402
from mftstack import topics as topic_registry  # noqa: E402

SERVICES = ["mft-sim", "mft-estimator", "mft-planner", "mft-wbc", "mft-record"]
# The topics the matrix corrupts, and which of them are events (idl/topics.yaml: faults, qos event).
REGISTRY = topic_registry.load()
TOPICS = REGISTRY.names(faults=True)
EVENT_TOPICS = set(REGISTRY.names(faults=True, qos="event"))
WATCHDOG_MS = 3.0


def log(msg, quiet=False):
    if not quiet:
        print(f"fault-matrix: {msg}", file=sys.stderr, flush=True)


def children(ppid, name):
    """Pids of the live children of `ppid` running `name` (the supervisor's restarted service)."""
    return [pid for pid, comm, state, _ in child_processes(ppid) if state != "Z" and name.startswith(comm)]


def read_json(path):
    try:
        return json.loads(Path(path).read_text())
    except (OSError, ValueError):
        return None


class Row:
    def __init__(self, target, fault, kind):
        self.target, self.fault, self.kind = target, fault, kind
        self.detection = ""
        self.detection_ms = None
        self.did = ""
        self.lost = ""
        self.fell = None
        self.ok = True      # no promise of the design broken
        self.data = {}

    def as_dict(self):
        return {"target": self.target, "fault": self.fault, "detection": self.detection,
                "detection_ms": self.detection_ms, "stack_did": self.did, "lost": self.lost, "fell": self.fell,
                "promises_kept": self.ok, "data": self.data}


class Matrix:
    def __init__(self, args):
        self.args = args
        self.bin = Path(args.bin_dir).resolve()
        self.out = Path(args.out).resolve()
        self.out.mkdir(parents=True, exist_ok=True)
        self.runs = self.out / "runs"
        self.env = dict(os.environ, MFT_RUNS_DIR=str(self.runs))
        self.scenario = REPO / "config" / "scenarios" / f"{args.scenario}.yaml"
        self.domain = args.domain
        self.mounts = []

    # --------------------------------------------------------------------------------------- stack control
    def sup(self, *a, timeout=120):
        return subprocess.run([sys.executable, str(SUPERVISOR)] + [str(x) for x in a], env=self.env,
                              capture_output=True, text=True, timeout=timeout)

    def up(self, record):
        cmd = ["up", self.scenario, "--domain", self.domain, "--mode", "realtime", "--bin-dir", self.bin]
        if record:
            cmd += ["--record", record]
        return self.sup(*cmd)

    def status(self):
        p = self.sup("status", "--domain", self.domain, "--json", timeout=30)
        try:
            return json.loads(p.stdout)
        except ValueError:
            return None

    def down(self):
        self.sup("down", "--domain", self.domain, timeout=90)

    def mount_tmpfs(self, size_kb):
        d = Path(tempfile.mkdtemp(prefix="mft-fault-fs-"))
        r = subprocess.run(["mount", "-t", "tmpfs", "-o", f"size={size_kb}k,mode=0755", "tmpfs", str(d)],
                           capture_output=True, text=True)
        if r.returncode != 0:
            d.rmdir()
            raise RuntimeError(f"cannot mount a tmpfs ({r.stderr.strip()}): run as root")
        self.mounts.append(d)
        return d

    def unmount_all(self):
        for d in self.mounts:
            subprocess.run(["umount", str(d)], capture_output=True)
            try:
                d.rmdir()
            except OSError:
                pass
        self.mounts = []

    # ------------------------------------------------------------------------------------------- one row
    def run_row(self, row):
        rec_dir = Path(tempfile.mkdtemp(prefix="mft-fault-rec-"))
        record = rec_dir / "run.rawlog"
        try:
            if row.kind == "diskfull":
                record = self.mount_tmpfs(self.args.diskfull_kb) / "run.rawlog"
            elif row.kind == "readonly":
                d = self.mount_tmpfs(1024)
                subprocess.run(["mount", "-o", "remount,ro", str(d)], check=True, capture_output=True)
                record = d / "run.rawlog"
            t_up = time.monotonic()
            p = self.up(record)
            if p.returncode != 0:
                row.data["up_error"] = (p.stderr or p.stdout).strip()[-600:]
                if row.kind == "readonly":
                    msg = row.data["up_error"]
                    m = re.search(r"mft-record: ([^\n]*)", self.supervisor_log())
                    row.detection = "at start: mft-record refuses the target before READY"
                    row.detection_ms = round((time.monotonic() - t_up) * 1e3)
                    row.did = "the stack does not start: " + (m.group(1).strip() if m else msg.splitlines()[-1])[:160]
                    row.lost = "nothing (nothing ran)"
                    row.fell = False
                    return row
                raise RuntimeError(f"the stack did not come up: {row.data['up_error']}")
            time.sleep(self.args.settle)
            st = self.status()
            if not st:
                raise RuntimeError("no status")
            run_dir = Path(st["run_dir"])
            pids = {n: s["pid"] for n, s in st["services"].items()}
            fault = self.apply(row, pids, run_dir, record)
            time.sleep(self.args.observe)
            self.down()
            self.analyse(row, run_dir, record, fault)
        finally:
            if self.status():
                self.down()
            self.unmount_all()
            shutil.rmtree(rec_dir, ignore_errors=True)
        return row

    def supervisor_log(self):
        try:
            return (self.runs / f"supervisor-d{self.domain}.log").read_text(errors="replace")
        except OSError:
            return ""

    def ready_count(self, run_dir, svc):
        try:
            return (run_dir / f"{svc}.log").read_text(errors="replace").count(f"READY {svc}")
        except OSError:
            return 0

    def apply(self, row, pids, run_dir, record):
        """Applies the fault; returns what the analysis needs (times, restart timings, injector report)."""
        f = {"t": time.monotonic()}
        svc = row.target
        if row.kind in ("kill9", "restart"):
            pid = pids[svc]
            sup_pid = self.status()["supervisor_pid"]
            ready0 = self.ready_count(run_dir, svc)
            f["t"] = time.monotonic()
            os.kill(pid, signal.SIGKILL if row.kind == "kill9" else signal.SIGTERM)
            gone = back = ready = None
            deadline = f["t"] + 15
            while time.monotonic() < deadline and ready is None:
                if gone is None and not pid_alive(pid):
                    gone = time.monotonic()
                if back is None and any(c != pid for c in children(sup_pid, svc)):
                    back = time.monotonic()
                if self.ready_count(run_dir, svc) > ready0:
                    ready = time.monotonic()
                time.sleep(0.002)
            f.update(gone_s=gone and gone - f["t"], new_pid_s=back and back - f["t"], ready_s=ready and ready - f["t"])
        elif row.kind.startswith("stop"):
            pid = pids[svc]
            dur = 0.05 if row.kind == "stop50ms" else 2.0
            f["t"] = time.monotonic()
            os.kill(pid, signal.SIGSTOP)
            time.sleep(dur)
            os.kill(pid, signal.SIGCONT)
            f["stopped_s"] = time.monotonic() - f["t"]
        elif row.kind == "inject":
            topic = svc
            cmd = [str(self.bin / "mft-inject"), "--domain", str(self.domain), "--publish", topic,
                   "--value", row.data["value"], "--seconds", str(self.args.inject_s), "--json"]
            cmd += ["--rate", "20"] if topic in EVENT_TOPICS else ["--follow"]
            f["t"] = time.monotonic()
            p = subprocess.run(cmd, capture_output=True, text=True, timeout=self.args.inject_s + 30)
            try:
                f["inject"] = json.loads(p.stdout.strip().splitlines()[-1])
            except (ValueError, IndexError):
                f["inject"] = {"error": (p.stderr or "")[-300:]}
        elif row.kind == "diskfull":
            # The tmpfs fills by itself: when is it full, and when does the recorder's writer report it?
            f["t"] = time.monotonic()
            end = f["t"] + 20
            full = err = None
            while time.monotonic() < end and err is None:
                if full is None and os.statvfs(record.parent).f_bavail == 0:
                    full = time.monotonic()
                try:
                    if "writer stopped" in (run_dir / "mft-record.log").read_text(errors="replace"):
                        err = time.monotonic()
                except OSError:
                    pass
                time.sleep(0.002)
            f.update(full_s=full and full - f["t"], error_after_full_ms=(err - full) * 1e3 if full and err else None)
            time.sleep(1.0)
        return f

    # ------------------------------------------------------------------------------------------ analysis
    def analyse(self, row, run_dir, record, fault):
        sums = {n: read_json(run_dir / f"{n}.summary.json") or {} for n in SERVICES}
        sim, wbc, est, pln, rec = (sums[n] for n in SERVICES)
        row.fell = bool(sim.get("fell"))
        eps = sim.get("damping_episodes") or []
        # Damping episodes: [onset sim time s, ms after the deadline, duration ms]; the fault's is the longest.
        longest = max(eps, key=lambda e: e[2]) if eps else None
        damping_ms = sum(e[2] for e in eps)
        restarts = self.supervisor_log().count("restarting in")
        row.data.update(sim={k: sim.get(k) for k in ("fell", "fall_time_s", "fall_reason", "ticks", "deadline_misses",
                                                      "damping_ticks", "lost_commands", "watchdog_recoveries",
                                                      "commands_received", "commands_rejected", "disturbances_rejected",
                                                      "startup_ticks", "damping_episodes")},
                        refused={n: {k: sums[n].get(k) for k in ("refused_inputs", "refused_ticks", "new_clocks")}
                                 for n in ("mft-estimator", "mft-planner", "mft-wbc")},
                        wbc_safety=wbc.get("safety"), planner_rejected=pln.get("rejected_commands"),
                        reader_deadline_misses={"estimator": est.get("deadline_misses"), "planner": pln.get("deadline_misses"),
                                                "wbc": wbc.get("deadline_misses")},
                        supervisor_restarts=restarts, fault={k: v for k, v in fault.items() if k != "t"})
        recinfo = self.recording_info(record)
        row.data["recording"] = recinfo
        row.data["recorder_summary"] = {k: rec.get(k) for k in ("error", "objects")} if rec else None
        fell = f"FELL ({sim.get('fall_reason')})" if row.fell else "no fall"
        kind = row.kind
        if kind in ("kill9", "restart", "stop50ms", "stop2s"):
            svc = row.target
            parts = []
            if svc == "mft-sim" and kind.startswith("stop"):
                misses = sum(v or 0 for v in row.data["reader_deadline_misses"].values())
                row.detection = (f"deadline at the chain's readers ({misses} misses, 3 ms); on resume the sim's "
                                 f"watchdog sees the gap and damps")
                if longest and longest[2] >= 5:
                    parts.append(f"damping {longest[2]:.0f} ms after resuming")
            elif svc in ("mft-estimator", "mft-planner", "mft-wbc") and longest and longest[2] >= 5:
                row.detection_ms = round(WATCHDOG_MS + longest[1], 2)
                row.detection = f"sim watchdog: damping {row.detection_ms} ms after the last command"
                parts.append(f"damping {longest[2]:.0f} ms")
            if kind in ("kill9", "restart"):
                if fault.get("new_pid_s") is not None:
                    det = f"supervisor: restarted after {fault['new_pid_s'] * 1e3:.0f} ms"
                    if fault.get("ready_s") is not None:
                        det += f", READY after {fault['ready_s'] * 1e3:.0f} ms"
                    row.detection = (row.detection + "; " if row.detection else "") + det
                    if row.detection_ms is None:
                        row.detection_ms = round(fault["new_pid_s"] * 1e3)
                    parts.append("restart")
                else:
                    parts.append("NOT restarted")
                    row.ok = False
            if kind.startswith("stop") and not row.detection:
                if svc == "mft-record":
                    row.detection = "none needed (the stack does not wait for the recorder)"
                else:
                    misses = sum(v or 0 for v in row.data["reader_deadline_misses"].values())
                    row.detection = f"deadline: {misses} reader deadline misses (3 ms)"
            if svc == "mft-sim" and kind != "stop50ms":
                ncl = sum(1 for n in ("mft-estimator", "mft-planner", "mft-wbc") if sums[n].get("new_clocks"))
                if kind in ("kill9", "restart"):
                    parts.append(f"new clock followed by {ncl}/3 services; the world restarts from the initial pose")
            parts.append(fell)
            row.did = ", ".join(parts)
            row.lost = self.lost_text(row, recinfo, sim, svc, kind, fault)
        elif kind == "inject":
            inj = fault.get("inject", {})
            rej = sim.get("commands_rejected") or {}
            refused = {n.replace("mft-", ""): (sums[n].get("refused_inputs") or 0) + (sums[n].get("refused_ticks") or 0)
                       for n in ("mft-estimator", "mft-planner", "mft-wbc")}
            parts = [f"{inj.get('written', 0)} corrupted samples sent"]
            if sum(rej.values() if rej else [0]):
                parts.append(f"sim refused {sum(rej.values())} commands ({', '.join(k for k, v in rej.items() if v)})")
            if sim.get("disturbances_rejected"):
                parts.append(f"sim refused {sim['disturbances_rejected']} disturbances")
            if pln.get("rejected_commands"):
                parts.append(f"planner rejected {pln['rejected_commands']} commands")
            for n, c in refused.items():
                if c:
                    parts.append(f"{n} refused {c}")
            saf = wbc.get("safety") or {}
            if saf.get("damping_ticks") or saf.get("hold_ticks"):
                parts.append(f"WBC safety: hold {saf.get('hold_ticks')} / damping {saf.get('damping_ticks')} ticks")
            consumers = ", ".join(REGISTRY.topic(row.target).subscribers())
            refusals = sum(refused.values()) + sum(rej.values() if rej else [0]) + (sim.get("disturbances_rejected") or 0) \
                + (pln.get("rejected_commands") or 0)
            row.detection = ("input checks: refused on arrival (0 ms)" if refusals else
                             f"not refused (read by: {consumers})")
            row.detection_ms = 0.0 if refusals else None
            parts.append(f"damping {damping_ms:.0f} ms" if damping_ms >= 5 else "no damping")
            parts.append(fell)
            row.did = ", ".join(parts)
            row.lost = f"nothing refused reached the actuators; recorder wrote {recinfo.get('nonfinite', 0)} non-finite samples as received" \
                if row.target == "WbcDiagnostics" else "nothing" if not row.fell else "the robot's stance"
            # Promise: no NaN reaches a torque, no fall from a refused input.
            row.ok = not row.fell and not (saf.get("nonfinite_output") or 0)
        elif kind == "diskfull":
            err = (rec or {}).get("error") or ""
            det = fault.get("error_after_full_ms")
            row.detection = (f"recorder writer: '{err}', {det:.0f} ms after the disk was full" if err and det is not None
                             else f"recorder writer: '{err}'" if err else "recorder: no error reported")
            row.detection_ms = round(det, 1) if det is not None else None
            row.did = f"the recorder stops writing and keeps running (stack unaffected), {fell}"
            kept = recinfo.get("ticks", 0)
            flushed = (rec or {}).get("flushed_sim_s")
            row.lost = (f"everything after the disk filled ({(rec or {}).get('dropped_after_error')} samples counted); "
                        f"the file keeps {kept} ticks ({recinfo.get('status', '?')}), flushed until "
                        f"{flushed} s of sim time")
            row.data["kept_last_s"] = recinfo.get("last_s")
            # Promise: what was flushed stays readable, and the stack does not notice.
            row.ok = not row.fell and kept > 0 and bool(err) and (flushed is None or recinfo.get("last_s", 0) + 1e-3 >= flushed)
        if kind in ("kill9", "restart", "stop50ms", "stop2s") and row.target != "mft-record":
            # Promises: the sim damps within 5 ms after a missed command deadline; a crashed service is
            # restarted. A fall during a long blackout is physics, reported but not a broken promise.
            if row.detection_ms is not None and row.detection.startswith("sim watchdog") and row.detection_ms > WATCHDOG_MS + 5:
                row.ok = False
        if kind in ("kill9", "restart", "stop50ms", "stop2s") and row.target == "mft-record" and row.fell:
            row.ok = False  # the recorder must never disturb the robot

    def lost_text(self, row, recinfo, sim, svc, kind, fault):
        if svc == "mft-record":
            gaps = recinfo.get("gap_ticks")
            if kind == "stop50ms":
                return f"recording: {gaps} ticks missing" if gaps else "nothing (socket buffers held the 50 ms)"
            if kind == "stop2s":
                return f"recording: {gaps} ticks missing over {recinfo.get('pieces')} piece(s)" if gaps else \
                    "nothing (socket buffers held the 2 s)"
            return (f"recording: {gaps} ticks missing while it was down "
                    f"({recinfo.get('pieces')} pieces, {recinfo.get('ticks')} ticks kept)")
        lost = []
        d = sim.get("damping_ticks") or 0
        if d:
            lost.append(f"{d} control ticks under damping")
        if kind in ("kill9", "restart") and svc == "mft-sim":
            lost.append("the simulated world (a new one starts)")
        gaps = recinfo.get("gap_ticks")
        if gaps:
            lost.append(f"recording: {gaps} GroundTruth ticks missing")
        return "; ".join(lost) if lost else "nothing"

    def recording_info(self, record):
        """Ticks of GroundTruth readable in every piece of the recording, and the gaps between pieces."""
        pieces = sorted(Path(record).parent.glob(Path(record).stem + "*" + Path(record).suffix))
        info = {"pieces": len(pieces), "ticks": 0, "gap_ticks": 0, "file_bytes": 0}
        ranges = []
        for p in pieces:
            r = subprocess.run([str(self.bin / "mft-export"), str(p), "--info", "--json"], capture_output=True, text=True,
                               timeout=120)
            try:
                j = json.loads(r.stdout)
            except ValueError:
                info["status"] = f"unreadable: {(r.stderr or '').strip()[:120]}"
                continue
            gt = (j.get("labels") or {}).get("gt_q") or {}
            info["ticks"] += gt.get("count", 0)
            info["last_s"] = max(info.get("last_s", 0.0), gt.get("last_tick", 0) * 1e-3)
            info["gap_ticks"] += gt.get("tick_gaps", 0)
            info["file_bytes"] += j.get("file_bytes", 0)
            info["status"] = j.get("error") or j.get("status") or "readable"
            if gt.get("count"):
                ranges.append((gt["first_tick"], gt["last_tick"]))
        ranges.sort()
        for (a0, a1), (b0, b1) in zip(ranges, ranges[1:]):
            if b0 > a1 + 1:
                info["gap_ticks"] += b0 - a1 - 1
        return info


def build_rows(args):
    rows = []
    for svc in SERVICES:
        for kind, label in (("kill9", "kill -9"), ("stop50ms", "SIGSTOP 50 ms"), ("stop2s", "SIGSTOP 2 s"),
                            ("restart", "restart (SIGTERM)")):
            rows.append(Row(svc, label, kind))
    rows.append(Row("mft-record", "disk full (tmpfs)", "diskfull"))
    rows.append(Row("mft-record", "read-only target", "readonly"))
    for topic in TOPICS:
        for value in ("nan", "inf", "range"):
            r = Row(topic, {"nan": "NaN fields", "inf": "inf fields", "range": "out-of-range values (1e6, bad enums)"}[value],
                    "inject")
            r.data["value"] = value
            rows.append(r)
    if args.only:
        rx = re.compile(args.only)
        rows = [r for r in rows if rx.search(f"{r.target} {r.fault} {r.kind}")]
    return rows


def table_lines(report):
    """The matrix as markdown lines from its JSON report (docs/results/faults.md quotes them; test
    docs_results_pages renders them again from the file the page cites)."""
    meta = report["meta"]
    out = [f"Fault matrix: {meta['scenario']} in realtime, one fresh stack per row (recording on), "
           f"{meta['date']}, {meta['rows']} rows in {meta['wall_s']:.0f} s. Promises broken: {meta['broken']}.", "",
           "| target | fault | detection | what the stack did | what was lost | promise kept |",
           "|---|---|---|---|---|---|"]
    for r in report["rows"]:
        out.append(f"| {r['target']} | {r['fault']} | {r['detection']} | {r['stack_did']} | {r['lost']} "
                   f"| {'yes' if r['promises_kept'] else '**no**'} |")
    return out


def main():
    p = script_parser("fault-matrix", __doc__)
    p.add_argument("--domain", type=int, default=200, help="DDS domain id for the stacks (default 200)")
    p.add_argument("--scenario", default="step-in-place", help="scenario name in config/scenarios (default step-in-place)")
    p.add_argument("--out", default=None, help="output folder (default runs/fault-matrix-<time>)")
    p.add_argument("--only", help="regular expression on 'target fault kind' selecting rows")
    p.add_argument("--settle", type=float, default=2.0, help="seconds between READY and the fault")
    p.add_argument("--observe", type=float, default=2.5, help="seconds watched after the fault")
    p.add_argument("--inject-s", type=float, default=2.0, help="seconds of injection per input row")
    p.add_argument("--diskfull-kb", type=int, default=1536, help="size of the recorder's tmpfs for the disk-full row")
    p.add_argument("--json", action="store_true", help="print the JSON report on stdout")
    args = p.parse_args()
    if not (0 <= args.domain <= 232):
        p.error("--domain must be in 0..232")
    missing = [n for n in SERVICES + ["mft-inject", "mft-export"] if not os.access(Path(args.bin_dir) / n, os.X_OK)]
    if missing:
        p.error(f"missing executables in {args.bin_dir}: {', '.join(missing)}")
    if not (REPO / "config" / "scenarios" / f"{args.scenario}.yaml").is_file():
        p.error(f"no scenario {args.scenario}")
    args.out = args.out or str(REPO / "runs" / f"fault-matrix-{time.strftime('%Y%m%d-%H%M%S')}")
    m = Matrix(args)
    rows = build_rows(args)
    if not rows:
        p.error("--only selected no row")
    t0 = time.monotonic()
    for i, row in enumerate(rows, 1):
        log(f"[{i}/{len(rows)}] {row.target}: {row.fault}", args.json and False)
        try:
            m.run_row(row)
        except Exception as e:  # a row that could not run is reported, the matrix goes on
            row.ok = False
            row.did = f"row failed: {e}"[:300]
        log(f"    detection: {row.detection}; did: {row.did}; lost: {row.lost}; promise kept: {row.ok}")
    meta = {"scenario": args.scenario, "date": time.strftime("%Y-%m-%d %H:%M"), "rows": len(rows),
            "wall_s": time.monotonic() - t0, "broken": sum(not r.ok for r in rows), "domain": args.domain}
    report = {"meta": meta, "rows": [r.as_dict() for r in rows]}
    out = Path(args.out)
    (out / "fault-matrix.json").write_text(json.dumps(report, indent=2))
    (out / "fault-matrix.md").write_text("\n".join(table_lines(report)) + "\n")
    log(f"wrote {out / 'fault-matrix.md'} and {out / 'fault-matrix.json'}")
    if args.json:
        print(json.dumps(report, indent=2))
    else:
        print("\n".join(table_lines(report)))
    return 0 if meta["broken"] == 0 else 1


if __name__ == "__main__":
    run_script(main, "fault-matrix.py")
