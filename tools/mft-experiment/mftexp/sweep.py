"""push-sweep: the largest impulse each controller recovers from at each base height (the paper's Table II).

Search per cell (height, controller) on the grid I_k = start + k * step (the paper: 3 N s, 0.1 N s):
  bisect (default): run I_0; if it fails, I_max < start (checked: I_1, I_2 fail too). Otherwise bracket upward
  from I_0 in increments of 2, 4, 8 ... N s (capped at --max-impulse), then bisect to adjacent grid points
  lo (recovered) and hi = lo + 1 (failed). Monotonicity check around the boundary: I_lo-1, I_lo-2 must recover
  and I_hi+1, I_hi+2 must fail. If not, the cell falls back to the paper's linear rule in a window of 1 N s
  either side (from the window's start upward, I_max = the last recovered impulse before the first failure; from
  I_0 if the window's first point fails already) and reports the outcomes it saw ("non_monotone").
  linear: the paper's procedure literally: I_0, I_1, ... until the first failure.
Every finished run is one JSON line in results.jsonl (fsync'ed), so an interrupted sweep resumes without
re-running anything; lockstep runs are deterministic, so a cached outcome is the outcome. At the end of a cell
the boundary runs are re-run with --record (kept rawlogs) and must give identical summaries."""
import json
import math
import os
import threading
import time
from dataclasses import asdict
from pathlib import Path

from .common import (ExperimentError, Interrupted, Progress, REGISTRY, check_scenario, log, run_scenario, run_workers,
                     fmt_duration)
from . import push as pushmod

CELL_ORDER_NOTE = "cells run on --workers stacks in parallel, each on its own DDS domain"


def config_hash(config_dir):
    """What the runs depend on besides the scenario: every configuration file the services read."""
    import hashlib
    h = hashlib.sha1()
    root = Path(config_dir)
    for name in ("robot.yaml", "sim.yaml", "estimator.yaml", "planner.yaml", "wbc.yaml", "mft_space.yaml",
                 "terrain/flat.yaml"):
        p = root / name
        h.update(name.encode() + b"\0" + (p.read_bytes() if p.is_file() else b"missing") + b"\0")
    return h.hexdigest()[:12]


def ikey(i):
    return f"{i:.3f}"


def cell_name(h, c, direction):
    return f"h{h:.2f}-{c}-{direction}"


class ResultsFile:
    def __init__(self, path, header):
        self.path = Path(path)
        self.lock = threading.Lock()
        self.runs, self.cells, self.records = {}, {}, {}
        self.resumed = self.path.exists()
        if self.path.exists():
            self._load(header)
        else:
            self._append(header)

    def _load(self, header):
        lines = self.path.read_text().splitlines()
        good = []
        for n, line in enumerate(lines, 1):
            if not line.strip():
                continue
            try:
                d = json.loads(line)
            except ValueError:
                if n == len(lines):  # a line cut by a crash: drop it (its run is simply run again)
                    log(f"{self.path}: dropping an incomplete last line")
                    continue
                raise ExperimentError(f"{self.path}:{n}: not a JSON line; is this a results file of mft-experiment?")
            good.append(d)
        if not good or good[0].get("kind") != "sweep":
            raise ExperimentError(f"{self.path}: not a push-sweep results file (no 'sweep' header line)")
        old = good[0]
        if old.get("setup_key") != header["setup_key"] or old.get("grid") != header["grid"]:
            raise ExperimentError(
                f"{self.path} was made with other settings (setup {old.get('setup')}, grid {old.get('grid')}); "
                f"resume it with the same options or choose another --out")
        if old.get("config_hash") and old["config_hash"] != header["config_hash"]:
            raise ExperimentError(
                f"{self.path} was made with other settings: the configuration ({old.get('config_dir')}) has changed "
                f"since; its runs would not be comparable: choose another --out")
        for d in good[1:]:
            k = (d.get("height"), d.get("controller"), d.get("direction"))
            if d.get("kind") == "run":
                self.runs[k + (ikey(d["impulse_Ns"]),)] = d
            elif d.get("kind") == "cell":
                self.cells[k] = d
            elif d.get("kind") == "record":
                self.records[k + (d["label"],)] = d
        # rewrite without a cut last line, so appends start on a fresh line
        self.path.write_text("".join(json.dumps(d) + "\n" for d in good))

    def _append(self, d):
        with self.lock:
            with open(self.path, "a") as f:
                f.write(json.dumps(d) + "\n")
                f.flush()
                os.fsync(f.fileno())

    def add_run(self, d):
        self._append(d)
        with self.lock:
            self.runs[(d["height"], d["controller"], d["direction"], ikey(d["impulse_Ns"]))] = d

    def add_cell(self, d):
        self._append(d)
        with self.lock:
            self.cells[(d["height"], d["controller"], d["direction"])] = d

    def add_record(self, d):
        self._append(d)
        with self.lock:
            self.records[(d["height"], d["controller"], d["direction"], d["label"])] = d


class Sweep:
    def __init__(self, args, setup):
        self.args = args
        self.setup = setup
        self.out = Path(args.out)
        self.out.mkdir(parents=True, exist_ok=True)
        self.grid = {"start_Ns": args.start, "step_Ns": args.step, "max_Ns": args.max_impulse, "search": args.search}
        header = {"kind": "sweep", "version": 1, "setup_key": setup.key(), "setup": asdict(setup), "grid": self.grid,
                  "config_hash": config_hash(args.config_dir), "config_dir": str(args.config_dir),
                  "created": time.strftime("%Y-%m-%d %H:%M:%S")}
        self.results = ResultsFile(self.out / "results.jsonl", header)
        self.kmax = int(math.floor((args.max_impulse - args.start) / args.step + 1e-9))
        self.cells = [(h, c, setup.direction) for h in args.heights for c in args.controllers]
        self.progress = Progress(args.workers, quiet=args.quiet)
        self.lock = threading.Lock()
        self.cell_runs = {c: 0 for c in self.cells}  # runs done (cost units) per cell, this session and before
        for k in self.results.runs:
            if k[:3] in self.cell_runs:
                self.cell_runs[k[:3]] += 1
        self.new_runs = 0
        self.checked_scenario = False

    # ------------------------------------------------------------------------------------------ estimates
    def expected_cost(self):
        done = [c for c in self.cells if c in self.results.cells]
        if done:
            return sum(self.cell_runs[c] + 2 * (2 if self.args.keep_rawlogs else 0) for c in done) / len(done)
        if self.args.search == "linear":
            return (8.0 - self.args.start) / self.args.step + 1 + (4 if self.args.keep_rawlogs else 0)
        return 1 + 4 + math.ceil(math.log2(max(2.0, 8.0 / self.args.step))) + 4 + (4 if self.args.keep_rawlogs else 0)

    def remaining_runs(self):
        e = self.expected_cost()
        with self.lock:
            return sum(max(1.0, e - self.cell_runs[c]) for c in self.cells if c not in self.results.cells)

    # ------------------------------------------------------------------------------------------------ runs
    def impulse(self, k):
        return round(self.args.start + k * self.args.step, 6)

    def run_dir(self, cell, impulse, suffix=""):
        return self.out / "runs" / cell_name(*cell) / f"{ikey(impulse)}{suffix}"

    def run_one(self, cell, impulse, domain, record=None):
        h, c, direction = cell
        rd = self.run_dir(cell, impulse, "-rec" if record else "")
        rd.mkdir(parents=True, exist_ok=True)
        scen = rd / "scenario.yaml"
        pushmod.write_scenario(scen, self.setup, h, c, impulse)
        if not self.checked_scenario:
            check_scenario(self.args.bin_dir, self.args.config_dir, scen, profiles=self.setup.profiles)
            self.checked_scenario = True
        for attempt in (1, 2, 3):
            try:
                summary, wall = run_scenario(scen, rd, domain, self.args.bin_dir, self.args.config_dir, record=record,
                                             timeout_s=self.setup.duration_s * 30 + 120, profiles=self.setup.profiles)
                break
            except ExperimentError as e:
                if attempt == 3 or REGISTRY.stopping.is_set():
                    raise
                log(f"{e}; retrying ({attempt} of 2)")
                time.sleep(3.0 * attempt)
        sim = summary["services"]["mft-sim"]
        recovered, reason = pushmod.judge(sim, self.setup.criteria)
        if recovered is None:
            raise ExperimentError(f"{cell_name(*cell)} I={impulse}: {reason} (logs in {rd})")
        rec = sim["recovery"]
        return {"height": h, "controller": c, "direction": direction, "impulse_Ns": impulse, "recovered": recovered,
                "reason": reason, "fell": sim.get("fell"), "fall_reason": sim.get("fall_reason"),
                "fall_time_s": sim.get("fall_time_s"), "push_time_s": rec.get("push_time_s"),
                "pre": rec.get("pre"), "after": rec.get("after"), "tail": rec.get("tail"),
                "sim_time_s": sim.get("sim_time_s"), "wall_s": round(wall, 3), "domain": domain,
                "run_dir": str(rd), "signature": pushmod.signature(sim), "setup_key": self.setup.key(),
                "finished_at": time.strftime("%H:%M:%S")}, wall

    def recovered(self, cell, k, domain):
        imp = self.impulse(k)
        key = cell + (ikey(imp),)
        d = self.results.runs.get(key)
        if d is None:
            d, wall = self.run_one(cell, imp, domain)
            d = dict({"kind": "run"}, **d)
            self.results.add_run(d)
            with self.lock:
                self.cell_runs[cell] += 1
                self.new_runs += 1
            self.progress.run_finished(
                wall, f"{cell_name(*cell)} I = {imp:.2f} N s: {'recovered' if d['recovered'] else d['reason']} "
                      f"({wall:.1f} s, domain {domain})", self.remaining_runs())
        return d["recovered"]

    # ---------------------------------------------------------------------------------------------- search
    def search_cell(self, cell, domain):
        t0 = time.monotonic()
        rec = lambda k: self.recovered(cell, k, domain)
        kmax = self.kmax
        info = {"monotone": None, "checks": [], "non_monotone_scan": None}
        lo = hi = None
        if self.args.search == "linear":
            k = 0
            while k <= kmax and rec(k):
                k += 1
            lo, hi = (k - 1 if k > 0 else None), (k if k <= kmax else None)
            info["monotone"] = "not checked (linear scan)"
        elif not rec(0):
            lo, hi = None, 0
        else:
            lo, inc = 0, max(1, int(round(2.0 / self.args.step)))
            while True:
                k = min(lo + inc, kmax)
                if k == lo:
                    break
                if rec(k):
                    lo = k
                    inc *= 2
                else:
                    hi = k
                    break
            if hi is not None:
                while hi - lo > 1:
                    mid = (lo + hi) // 2
                    if rec(mid):
                        lo = mid
                    else:
                        hi = mid
        if self.args.search == "bisect":
            checks = []
            if lo is not None:
                checks += [(k, True) for k in (lo - 1, lo - 2) if k >= 0]
            if hi is not None:
                checks += [(k, False) for k in (hi + 1, hi + 2) if k <= kmax]
            ok = True
            for k, want in checks:
                got = rec(k)
                info["checks"].append({"impulse_Ns": self.impulse(k), "expected": want, "recovered": got})
                ok = ok and got == want
            info["monotone"] = ok
            if not ok:
                w = max(1, int(round(1.0 / self.args.step)))
                a = max(0, (lo if lo is not None else 0) - w)
                if a > 0 and not rec(a):
                    a = 0  # the window starts in a failure: the paper's scan from I_0
                scan = []
                first_fail = None
                for k in range(a, kmax + 1):  # the paper's rule: up to the first failure
                    r = rec(k)
                    scan.append({"impulse_Ns": self.impulse(k), "recovered": r})
                    if not r and first_fail is None:
                        first_fail = k
                        break
                info["non_monotone_scan"] = scan
                hi = first_fail
                lo = kmax if first_fail is None else (first_fail - 1 if first_fail > 0 else None)
                log(f"{cell_name(*cell)}: recovery is not monotone around the boundary; linear rule in the window "
                    f"gives I_max = {self.impulse(lo) if lo is not None else '< start'}")
        status = "ok" if lo is not None and hi is not None else ("below_start" if lo is None else "at_max")
        cell_rec = {"kind": "cell", "height": cell[0], "controller": cell[1], "direction": cell[2],
                    "setup_key": self.setup.key(), "status": status,
                    "i_max_Ns": self.impulse(lo) if lo is not None else None,
                    "recovered_Ns": self.impulse(lo) if lo is not None else None,
                    "failed_Ns": self.impulse(hi) if hi is not None else None,
                    "runs": self.cell_runs[cell], **info}
        # kept rawlogs: the boundary runs again with --record; lockstep: the same outcome, bit for bit
        rawlogs, deterministic = {}, True
        if self.args.keep_rawlogs:
            for label, k in (("recovered", lo), ("failed", hi)):
                if k is None:
                    continue
                imp = self.impulse(k)
                prev = self.results.records.get(cell + (label,))
                path = self.out / "rawlogs" / cell_name(*cell) / f"{label}-{imp:.2f}Ns.rawlog"
                if prev and Path(prev["rawlog"]).exists() and prev["impulse_Ns"] == imp:
                    rawlogs[label] = prev["rawlog"]
                    deterministic = deterministic and prev["identical"]
                    continue
                path.parent.mkdir(parents=True, exist_ok=True)
                d, wall = self.run_one(cell, imp, domain, record=path)
                first = self.results.runs[cell + (ikey(imp),)]
                same = d["signature"] == first["signature"]
                deterministic = deterministic and same
                self.results.add_record({"kind": "record", "height": cell[0], "controller": cell[1],
                                         "direction": cell[2], "label": label, "impulse_Ns": imp, "rawlog": str(path),
                                         "recovered": d["recovered"], "identical": same, "wall_s": round(wall, 3)})
                with self.lock:
                    self.cell_runs[cell] += 2
                self.progress.run_finished(wall, f"{cell_name(*cell)} I = {imp:.2f} N s recorded to {path.name}: "
                                                 f"{'identical' if same else 'DIFFERENT'} outcome", self.remaining_runs())
                rawlogs[label] = str(path)
                if not same:
                    log(f"{cell_name(*cell)} I = {imp:.2f}: the recorded run differs from the first run "
                        f"(lockstep should be deterministic)")
        cell_rec["rawlogs"] = rawlogs
        cell_rec["deterministic"] = deterministic if rawlogs else None
        cell_rec["wall_s"] = round(time.monotonic() - t0, 1)
        self.results.add_cell(cell_rec)
        shown = {"ok": f"I_max = {cell_rec['i_max_Ns']:.2f} N s" if lo is not None else "",
                 "below_start": f"I_max < {self.args.start} N s",
                 "at_max": f"I_max >= {self.args.max_impulse} N s (no failure found)"}[status]
        self.progress.note(f"cell {cell_name(*cell)} done: {shown}, monotone {info['monotone']}")
        return cell_rec

    # ------------------------------------------------------------------------------------------------- all
    def run(self):
        todo = [c for c in self.cells if c not in self.results.cells]
        if self.results.resumed:
            log(f"resuming {self.out / 'results.jsonl'}: {len(self.cells) - len(todo)} of {len(self.cells)} cells "
                f"done, {len(self.results.runs)} runs on file")
        queue = list(todo)
        qlock = threading.Lock()
        errors = []

        def worker(i):
            domain = self.args.domain_base + i
            while not REGISTRY.stopping.is_set():
                with qlock:
                    if not queue:
                        return
                    cell = queue.pop(0)
                try:
                    self.search_cell(cell, domain)
                except Interrupted:
                    return
                except BaseException as e:  # noqa: the main thread reports it
                    errors.append(e)
                    REGISTRY.stop_all()
                    return

        t0 = time.monotonic()
        run_workers(worker, self.args.workers, errors,
                    "interrupted: stopping the runs in flight (finished runs are kept in results.jsonl)")
        return time.monotonic() - t0
