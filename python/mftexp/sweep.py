"""push-sweep: the largest impulse each controller recovers from at each base height (the paper's Table II).

I_max follows the paper: on the grid I_k = start + k * step (3 N s, 0.1 N s), the largest impulse before the
first failure. "Failure" is the project's one recovery criterion (--recovery-rule, default: back to stepping in
place; chain/push_recovery.hpp). Search per cell (height, controller):
  linear (default): the paper's procedure literally: I_0, I_1, ... until the first failure; exact by definition.
    Then --above N s more on the same grid, to report recoveries above the first failure where they exist.
  coarse: a linear scan on the coarse grid (--coarse, 0.5 N s) until its first failure, then the fine grid
    between the last coarse recovery and that failure, linear again. It equals "linear" unless a failure hides
    between two recovered coarse points (not run); cheaper by about coarse/step. --above as for linear.
  bisect: bracket and bisect to a recovered/failed pair one step apart, check two steps either side, and fall
    back to a linear scan over 1 N s below the boundary when they disagree. Not equivalent to the paper's rule
    where recovery is not monotone further below; kept for quick looks.
Every finished run is one JSON line in results.jsonl (fsync'ed), so an interrupted sweep resumes without
re-running anything; lockstep runs are deterministic, so a cached outcome is the outcome. With --rawlogs the two
runs at each cell's boundary are re-run with --record (kept rawlogs) and must give identical summaries."""
import hashlib
import json
import math
import os
import threading
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path

from .common import ExperimentError, Interrupted, Progress, REGISTRY, load_text, log, run_workers
from . import push as pushmod
from .executor import make_executor, run_task


def config_hash(config_dir):
    """What the runs depend on besides the scenario: every configuration file the services read, and profiles."""
    h = hashlib.sha1()
    root = Path(config_dir)
    names = ["robot.yaml", "sim.yaml", "estimator.yaml", "planner.yaml", "wbc.yaml", "mft_space.yaml",
             "terrain/flat.yaml"] + sorted(str(p.relative_to(root)) for p in root.glob("profiles/*.yaml"))
    for name in names:
        p = root / name
        h.update(name.encode() + b"\0" + (p.read_bytes() if p.is_file() else b"missing") + b"\0")
    return h.hexdigest()[:12]


def ikey(i):
    return f"{i:.3f}"


@dataclass
class Variant:
    """One setup of an experiment: the configuration profiles on top of the defaults, and the recovery rule."""
    name: str = "default"
    profiles: list = field(default_factory=list)
    rule: str = "stepping"
    label: str = "the defaults (the paper's setup)"


def cell_name(cell):
    v, h, c, direction = cell
    return (f"{v}-" if v != "default" else "") + f"h{h:.2f}-{c}-{direction}"


class ResultsFile:
    def __init__(self, path, header, kind="sweep"):
        self.path = Path(path)
        self.kind = kind
        self.lock = threading.Lock()
        self.runs, self.cells, self.records, self.extra = {}, {}, {}, {}
        self.resumed = self.path.exists()
        if self.path.exists():
            self._load(header)
        else:
            self._append(header)

    @staticmethod
    def cell_of(d):
        return (d.get("variant", "default"), d.get("height"), d.get("controller"), d.get("direction"))

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
        if not good or good[0].get("kind") != self.kind:
            raise ExperimentError(f"{self.path}: not a {self.kind} results file of mft-experiment (no '{self.kind}' "
                                  f"header line)")
        old = good[0]
        if old.get("setup_key") != header["setup_key"] or old.get("grid") != header["grid"] or \
                old.get("variants") != header.get("variants"):
            raise ExperimentError(
                f"{self.path} was made with other settings (setup {old.get('setup')}, grid {old.get('grid')}); "
                f"resume it with the same options or choose another --out")
        if old.get("config_hash") and old["config_hash"] != header["config_hash"]:
            raise ExperimentError(
                f"{self.path} was made with other settings: the configuration ({old.get('config_dir')}) has changed "
                f"since; its runs would not be comparable: choose another --out")
        for d in good[1:]:
            k = self.cell_of(d)
            if d.get("kind") == "run":
                self.runs[k + (ikey(d["impulse_Ns"]),)] = d
            elif d.get("kind") == "cell":
                self.cells[k] = d
            elif d.get("kind") == "record":
                self.records[k + (d["label"],)] = d
            elif d.get("kind"):
                self.extra.setdefault(d["kind"], {})[d.get("key")] = d
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
            self.runs[self.cell_of(d) + (ikey(d["impulse_Ns"]),)] = d

    def add_cell(self, d):
        self._append(d)
        with self.lock:
            self.cells[self.cell_of(d)] = d

    def add_record(self, d):
        self._append(d)
        with self.lock:
            self.records[self.cell_of(d) + (d["label"],)] = d

    def add_extra(self, d):
        self._append(d)
        with self.lock:
            self.extra.setdefault(d["kind"], {})[d.get("key")] = d


def imax_search(kmax, search, coarse_k=5, above_k=10):
    """The paper's I_max on the grid k = 0..kmax as a generator: it yields the k whose outcome it needs next and is
    sent back recovered (bool); it returns (lo, first_fail, info): lo = the last k before the first failure (None:
    the first point failed), first_fail = the first failed k (None: none up to kmax), info = how it was found and
    the recoveries above the first failure. A generator, so that a scheduler can replay it on the outcomes known so
    far and see which run it needs next, and which it would need if the runs in flight recover (Sweep.run)."""
    info = {"monotone": None, "checks": [], "non_monotone_scan": None}
    if search in ("linear", "coarse"):
        return (yield from _scan_search(kmax, search, coarse_k, above_k, info))
    lo, hi = yield from _bisect(kmax, coarse_k)
    lo, hi = yield from _check_monotone(kmax, coarse_k, lo, hi, info)
    if hi is not None:
        above = []
        for k in (hi + 1, hi + 2):
            if k <= kmax:
                above.append((k, (yield k)))
        info["above"] = above
    return lo, hi, info


def _scan_search(kmax, search, coarse_k, above_k, info):
    """linear: every grid point from 0; coarse: every coarse_k-th, then the fine grid below the first failure."""
    step = 1 if search == "linear" else max(1, coarse_k)
    k, last_ok, fail = 0, None, None
    while k <= kmax:
        if (yield k):
            last_ok = k
            k += step
        else:
            fail = k
            break
    if step > 1 and fail is not None:  # the fine grid between the last coarse recovery and the coarse failure
        a = 0 if last_ok is None else last_ok + 1
        for j in range(a, fail):
            if not (yield j):
                fail = j
                break
    elif step > 1 and fail is None and last_ok is not None and last_ok < kmax:
        for j in range(last_ok + 1, kmax + 1):
            if not (yield j):
                fail = j
                break
    info["monotone"] = f"not assumed ({search} scan)"
    lo = None if fail == 0 else (kmax if fail is None else fail - 1)
    if fail is not None:  # what lies above the first failure, on the same grid
        above = []
        for j in range(fail + 1, min(kmax, fail + above_k) + 1, step):
            above.append((j, (yield j)))
        info["above"] = above
    return lo, fail, info


def _bisect(kmax, coarse_k):
    """Doubling steps from 0 until a failure, then bisection: (last recovered k or None, first failed k or None)."""
    lo = hi = None
    if not (yield 0):
        return None, 0
    lo, inc = 0, 2 * coarse_k
    while True:
        k = min(lo + inc, kmax)
        if k == lo:
            break
        if (yield k):
            lo = k
            inc *= 2
        else:
            hi = k
            break
    if hi is not None:
        while hi - lo > 1:
            mid = (lo + hi) // 2
            if (yield mid):
                lo = mid
            else:
                hi = mid
    return lo, hi


def _check_monotone(kmax, coarse_k, lo, hi, info):
    """Two points either side of the bisection's boundary; where one disagrees, the paper's scan from below the
    boundary (or from I_0) up to the first failure decides. Returns the (lo, hi) in force."""
    checks = []
    if lo is not None:
        checks += [(k, True) for k in (lo - 1, lo - 2) if k >= 0]
    if hi is not None:
        checks += [(k, False) for k in (hi + 1, hi + 2) if k <= kmax]
    ok = True
    for k, want in checks:
        got = yield k
        info["checks"].append({"k": k, "expected": want, "recovered": got})
        ok = ok and got == want
    info["monotone"] = ok
    if ok:
        return lo, hi
    w = 2 * coarse_k
    a = max(0, (lo if lo is not None else 0) - w)
    if a > 0 and not (yield a):
        a = 0  # the window starts in a failure: the paper's scan from I_0
    scan, first_fail = [], None
    for k in range(a, kmax + 1):
        r = yield k
        scan.append({"k": k, "recovered": r})
        if not r:
            first_fail = k
            break
    info["non_monotone_scan"] = scan
    hi = first_fail
    lo = kmax if first_fail is None else (first_fail - 1 if first_fail > 0 else None)
    return lo, hi


def find_imax(rec, kmax, search, coarse_k=5, above_k=10):
    """imax_search driven by rec(k) -> recovered, one run after the other: (lo, first_fail, info)."""
    search_steps = imax_search(kmax, search, coarse_k, above_k)
    try:
        k = next(search_steps)
        while True:
            k = search_steps.send(bool(rec(k)))
    except StopIteration as done:
        return done.value


def replay_search(kmax, search, coarse_k, above_k, known, assume_recovered=()):
    """Replays imax_search on `known` ({k: recovered}), taking the ks in `assume_recovered` as recovered.
    Returns (asked, need, result): asked = the ks it asked, in order, up to `need`, the first k it asked whose
    outcome is neither known nor assumed (None once the search has ended, with `result` its return value)."""
    search_steps = imax_search(kmax, search, coarse_k, above_k)
    asked = []
    try:
        k = next(search_steps)
        while True:
            if k in known:
                r = known[k]
            elif k in assume_recovered:
                r = True
            else:
                return asked, k, None
            asked.append(k)
            k = search_steps.send(bool(r))
    except StopIteration as done:
        return asked, None, done.value


class CellState:
    """A cell being searched: the runs finished ahead of its search, the runs in flight, and once the search has
    ended its record (cell line) and the recorded re-runs of its boundary."""

    def __init__(self, t0):
        self.t0 = t0
        self.phase = "search"  # search | record
        self.ahead = {}         # k -> run line: finished, not yet reached by the search
        self.in_flight = set()  # ks being run now
        self.failed_ahead = set()  # ks whose run ahead failed: run again only when the search asks for them
        self.cell_rec = None
        self.record_todo, self.record_labels, self.records_done, self.record_running = [], [], {}, 0
        self.rawlogs, self.deterministic = {}, True


class Job:
    """What a slot does next: kind run (k of a cell; ahead: not yet asked for by its search), record (a recorded
    re-run of a boundary impulse) or extra (a callable fn(slot))."""

    def __init__(self, kind, cell=None, st=None, k=None, ahead=False, label=None, impulse=None, fn=None):
        self.kind, self.cell, self.st, self.k, self.ahead = kind, cell, st, k, ahead
        self.label, self.impulse, self.fn = label, impulse, fn


class _Outcomes:
    """{k: recovered} of one cell as the search sees it: the runs on file and the runs finished ahead of it."""

    def __init__(self, sweep, cell, ahead):
        self.sweep, self.cell, self.ahead = sweep, cell, ahead

    def _get(self, k):
        d = self.sweep.on_file(self.cell, k)
        return d if d is not None else self.ahead.get(k)

    def __contains__(self, k):
        return self._get(k) is not None

    def __getitem__(self, k):
        return self._get(k)["recovered"]


class Sweep:
    """Cells (variant, height, controller, direction), each searched for I_max; on the stack (default) or in
    process (mft-closedloop). push-sweep has one variant; ablation and sensitivity have several."""

    def __init__(self, args, setup, variants=None, kind="sweep", config_dir=None, cells=None, executor=None):
        self.args = args
        self.setup = setup
        self.kind = kind
        self.config_dir = str(config_dir or args.config_dir)
        self.variants = {v.name: v for v in (variants or [Variant(profiles=list(getattr(args, "profile", []) or []),
                                                                   rule=setup.criteria.rule)])}
        self.out = Path(args.out)
        self.out.mkdir(parents=True, exist_ok=True)
        self.inprocess = bool(getattr(args, "inprocess", False))
        self.grid = {"start_Ns": args.start, "step_Ns": args.step, "max_Ns": args.max_impulse, "search": args.search,
                     "coarse_Ns": getattr(args, "coarse", 0.5), "above_Ns": getattr(args, "above", 1.0),
                     "runner": "inprocess" if self.inprocess else "stack"}
        header = {"kind": kind, "version": 2, "setup_key": setup.key(), "setup": asdict(setup), "grid": self.grid,
                  "variants": {n: asdict(v) for n, v in self.variants.items()},
                  "config_hash": config_hash(self.config_dir), "config_dir": self.config_dir,
                  "created": time.strftime("%Y-%m-%d %H:%M:%S")}
        self.results = ResultsFile(self.out / "results.jsonl", header, kind)
        self.kmax = int(math.floor((args.max_impulse - args.start) / args.step + 1e-9))
        self.coarse_k = max(1, int(round(self.grid["coarse_Ns"] / args.step)))
        self.above_k = max(0, int(round(self.grid["above_Ns"] / args.step)))
        self.cells = cells or [(v, h, c, setup.direction) for v in self.variants for h in args.heights
                               for c in args.controllers]
        # where the runs happen: stacks on this machine (default) or Dask workers (--scheduler); mftexp.executor
        self.executor = executor or make_executor(args, self.config_dir)
        self.progress = Progress(len(self.executor.slots()), quiet=args.quiet)
        # One lock for the schedule and the counts (results lines are appended under it); `wake` tells waiting slots
        # that a job finished (a search may ask for its next run, or a run ahead may be worth starting).
        self.lock = threading.RLock()
        self.wake = threading.Condition(self.lock)
        # Runs ahead of a search on slots that have no cell to start (default; --no-speculation: off).
        self.speculate = bool(getattr(args, "speculate", True))
        self.pending, self.active, self.extra_queue, self.extra_running = [], {}, [], 0
        self.discarded_runs = 0
        self.cell_runs = {c: 0 for c in self.cells}
        for k in self.results.runs:
            if k[:4] in self.cell_runs:
                self.cell_runs[k[:4]] += 1
        self.new_runs = 0
        self.checked = set()
        self.extra_remaining = 0  # runs outside the cells (e.g. stepping heights), for the time left

    # ------------------------------------------------------------------------------------------ estimates
    def expected_cost(self):
        done = [c for c in self.cells if c in self.results.cells]
        if done:
            return sum(self.cell_runs[c] for c in done) / len(done)
        guess_k = (10.0 - self.args.start) / self.args.step  # a boundary near 10 N s
        if self.args.search == "linear":
            return guess_k + self.above_k
        if self.args.search == "coarse":
            return guess_k / self.coarse_k + self.coarse_k + self.above_k / self.coarse_k
        return 12 + (4 if self.args.keep_rawlogs else 0)

    def remaining_runs(self):
        e = self.expected_cost()
        with self.lock:
            ahead = {c: len(st.ahead) for c, st in self.active.items()}
            return sum(max(1.0, e - self.cell_runs[c] - ahead.get(c, 0)) for c in self.cells
                       if c not in self.results.cells) + self.extra_remaining

    # ------------------------------------------------------------------------------------------------ runs
    def impulse(self, k):
        return round(self.args.start + k * self.args.step, 6)

    def run_dir(self, cell, impulse, suffix=""):
        return self.out / "runs" / cell_name(cell) / f"{ikey(impulse)}{suffix}"

    def setup_for(self, variant):
        s = pushmod.PushSetup(**{k: getattr(self.setup, k) for k in self.setup.__dataclass_fields__})
        s.criteria = pushmod.Criteria(**dict(asdict(self.setup.criteria), rule=variant.rule))
        s.profiles = list(variant.profiles)
        return s

    def run_push(self, variant, height, controller, impulse, rd, slot, record=None, name=None):
        """One run (impulse None: stepping only, no push) on `slot` (mftexp.executor). Returns a RunResult."""
        setup = self.setup_for(variant)
        s = pushmod.scenario(setup, height, controller, impulse or 0.0)
        if impulse is None:
            s.pop("pushes")
        inprocess = self.inprocess and not record
        task = run_task(name or str(rd.relative_to(self.out)), s, variant.profiles,
                        timeout_s=setup.duration_s * (60 if inprocess else 30) + (60 if inprocess else 120),
                        inprocess=inprocess, record=bool(record))
        return slot.run(task, rd, record)

    def run_one(self, cell, impulse, slot, record=None):
        v, h, c, direction = cell
        rd = self.run_dir(cell, impulse, "-rec" if record else "")
        r = self.run_push(self.variants[v], h, c, impulse, rd, slot, record)
        sim, wall, domain = r.sim, r.wall, r.domain
        recovered, reason = pushmod.judge(sim)
        if recovered is None:
            raise ExperimentError(f"{cell_name(cell)} I={impulse}: {reason} (logs in {rd})")
        rec = sim["recovery"]
        return {"variant": v, "height": h, "controller": c, "direction": direction, "impulse_Ns": impulse,
                "recovered": recovered, "reason": reason, "outcome": rec["verdict"]["outcome"],
                "no_fall": rec["verdict"]["no_fall"], "back_to_stepping": rec["verdict"]["back_to_stepping"],
                "fell": sim.get("fell"), "fall_reason": sim.get("fall_reason"),
                "fall_time_s": sim.get("fall_time_s"), "push_time_s": rec.get("push_time_s"),
                "pre": rec.get("pre"), "after": rec.get("after"), "tail": rec.get("tail"),
                "sim_time_s": sim.get("sim_time_s"), "wall_s": round(wall, 3), "domain": domain,
                "worker": r.worker, **({"host": r.host} if r.host else {}),
                "runner": "inprocess" if self.inprocess and not record else "stack",
                "profiles": self.variants[v].profiles, "applied_profiles": sim.get("profiles"), "run_dir": str(rd), "signature": pushmod.signature(sim),
                "setup_key": self.setup.key(), "finished_at": time.strftime("%H:%M:%S")}, wall

    # ---------------------------------------------------------------------------------------------- search
    # A cell's search (imax_search) is replayed on the outcomes known so far: the runs on file and the runs
    # finished ahead of it (CellState.ahead). What it asks for next and nobody runs is a demanded run; what it
    # would ask for next if every run in flight recovered is a run ahead. A run joins results.jsonl only when the
    # replayed search reaches it, in the order the one-after-the-other search would have run it, so the file, the
    # table and a resume are those of that search; runs ahead that the search never reaches are discarded.
    def outcomes(self, cell, st):
        return _Outcomes(self, cell, st.ahead)

    def replay(self, cell, st, assume_recovered=()):
        return replay_search(self.kmax, self.args.search, self.coarse_k, self.above_k, self.outcomes(cell, st),
                             assume_recovered)

    def on_file(self, cell, k):
        return self.results.runs.get(cell + (ikey(self.impulse(k)),))

    def advance(self, cell, st):
        """Files the runs ahead that the search has now reached (in its order); ends the search when it is done."""
        asked, need, result = self.replay(cell, st)
        for k in asked:
            if k in st.ahead and self.on_file(cell, k) is None:
                self.results.add_run(st.ahead.pop(k))
                self.cell_runs[cell] += 1
                self.new_runs += 1
        if need is None:
            self.search_done(cell, st, result)

    def search_done(self, cell, st, result):
        lo, hi, info = result
        for k in list(st.ahead):  # beyond the end of the search: the one-after-the-other search never ran them
            self.discard(cell, st.ahead.pop(k))
        above = [self.impulse(k) for k, ok in info.pop("above", []) if ok]
        for key in ("checks", "non_monotone_scan"):
            for d in info.get(key) or []:
                d["impulse_Ns"] = self.impulse(d.pop("k"))
        # every run of this cell on file: the recoveries above the first failure, the largest recovery
        runs = {float(k[4]): d for k, d in self.results.runs.items() if k[:4] == cell}
        if hi is not None:
            above = sorted({i for i, d in runs.items() if d["recovered"] and i > self.impulse(hi) + 1e-9} | set(above))
        first = runs.get(self.impulse(hi)) if hi is not None else None
        status = "ok" if lo is not None and hi is not None else ("below_start" if lo is None else "at_max")
        st.cell_rec = {"kind": "cell", "variant": cell[0], "height": cell[1], "controller": cell[2],
                       "direction": cell[3], "setup_key": self.setup.key(), "status": status, "search": self.args.search,
                       "i_max_Ns": self.impulse(lo) if lo is not None else None,
                       "recovered_Ns": self.impulse(lo) if lo is not None else None,
                       "failed_Ns": self.impulse(hi) if hi is not None else None,
                       "first_failure": None if first is None else {"outcome": first.get("outcome"),
                                                                    "reason": first["reason"]},
                       "recovered_above_Ns": above,
                       "largest_recovered_Ns": max([i for i, d in runs.items() if d["recovered"]], default=None),
                       **info}
        st.phase = "record"
        if getattr(self.args, "keep_rawlogs", False):
            for label, k in (("recovered", lo), ("failed", hi)):
                if k is None:
                    continue
                imp = self.impulse(k)
                prev = self.results.records.get(cell + (label,))
                if prev and Path(prev["rawlog"]).exists() and prev["impulse_Ns"] == imp:
                    st.rawlogs[label] = prev["rawlog"]
                    st.deterministic = st.deterministic and prev["identical"]
                    continue
                st.record_todo.append((label, imp))
                st.record_labels.append(label)
        if not st.record_todo:
            self.finish_cell(cell, st)

    def discard(self, cell, d):
        import shutil
        self.discarded_runs += 1
        shutil.rmtree(d["run_dir"], ignore_errors=True)
        self.progress.note(f"{cell_name(cell)} I = {d['impulse_Ns']:.2f} N s: run ahead of the search discarded "
                           f"(the search ended before it)")

    def record_finished(self, cell, st, label, d, wall, path):
        imp = d["impulse_Ns"]
        first_run = self.results.runs[cell + (ikey(imp),)]
        same = d["signature"] == first_run["signature"] or first_run.get("runner") == "inprocess" and \
            d["recovered"] == first_run["recovered"]
        st.records_done[label] = {"kind": "record", "variant": cell[0], "height": cell[1], "controller": cell[2],
                                  "direction": cell[3], "label": label, "impulse_Ns": imp, "rawlog": str(path),
                                  "recovered": d["recovered"], "identical": same, "wall_s": round(wall, 3)}
        self.cell_runs[cell] += 1
        self.progress.run_finished(wall, f"{cell_name(cell)} I = {imp:.2f} N s recorded to {Path(path).name}: "
                                         f"{'identical' if same else 'DIFFERENT'} outcome", self.remaining_runs(),
                                   worker=d["worker"])
        if not same:
            log(f"{cell_name(cell)} I = {imp:.2f}: the recorded run differs from the first run "
                f"(lockstep should be deterministic)")
        if st.record_todo or st.record_running:
            return
        for label in st.record_labels:  # in the order the one-after-the-other search writes them
            r = st.records_done[label]
            self.results.add_record(r)
            st.rawlogs[label] = r["rawlog"]
            st.deterministic = st.deterministic and r["identical"]
        self.finish_cell(cell, st)

    def finish_cell(self, cell, st):
        cell_rec = st.cell_rec
        cell_rec["runs"] = self.cell_runs[cell]
        cell_rec["rawlogs"] = st.rawlogs
        cell_rec["deterministic"] = st.deterministic if st.rawlogs else None
        cell_rec["wall_s"] = round(time.monotonic() - st.t0, 1)
        self.results.add_cell(cell_rec)
        del self.active[cell]
        status = cell_rec["status"]
        shown = {"ok": f"I_max = {cell_rec['i_max_Ns']:.2f} N s" if cell_rec["i_max_Ns"] is not None else "",
                 "below_start": f"I_max < {self.args.start} N s",
                 "at_max": f"I_max >= {self.args.max_impulse} N s (no failure found)"}[status]
        if cell_rec["recovered_above_Ns"]:
            shown += f", recovered above the first failure at {', '.join(f'{a:g}' for a in cell_rec['recovered_above_Ns'])}"
        self.progress.note(f"cell {cell_name(cell)} done: {shown}")

    # -------------------------------------------------------------------------------------------- schedule
    def activate(self, cell):
        st = CellState(time.monotonic())
        self.active[cell] = st
        self.advance(cell, st)  # a resumed cell: its runs on file may already end its search

    def next_job(self):
        """The most useful job for a free slot, marked as started; None when there is none now. In this order:
        the jobs outside the cells; a run a search asks for and nobody runs; a recorded re-run of a finished
        search; the first run of a cell not started; a run ahead of a search (the cell with the fewest runs in
        flight): what it will ask for next if the runs in flight recover."""
        if self.extra_queue:
            self.extra_running += 1
            return Job("extra", fn=self.extra_queue.pop(0))
        while True:
            for cell, st in self.active.items():
                if st.phase == "search":
                    need = self.replay(cell, st)[1]
                    if need is not None and need not in st.in_flight:
                        st.in_flight.add(need)
                        return Job("run", cell, st, need)
                elif st.record_todo:
                    label, imp = st.record_todo.pop(0)
                    st.record_running += 1
                    return Job("record", cell, st, label=label, impulse=imp)
            if not self.pending:
                break
            self.activate(self.pending.pop(0))  # its first run is a demanded run: found by the loop above
        if not self.speculate:
            return None
        searching = sorted(((len(st.in_flight), n, cell, st) for n, (cell, st) in enumerate(self.active.items())
                            if st.phase == "search"), key=lambda t: t[:2])
        for _, _, cell, st in searching:
            k = self.replay(cell, st, assume_recovered=st.in_flight)[1]
            if k is not None and k not in st.in_flight and k not in st.failed_ahead:
                st.in_flight.add(k)
                return Job("run", cell, st, k, ahead=True)
        return None

    def all_done(self):
        return not (self.extra_queue or self.extra_running or self.pending or self.active)

    def execute(self, job, slot):
        """Runs one job on `slot` (no lock held); what it returns goes to job_finished."""
        if job.kind == "extra":
            return job.fn(slot)
        if job.kind == "run":
            return self.run_one(job.cell, self.impulse(job.k), slot)
        path = self.out / "rawlogs" / cell_name(job.cell) / f"{job.label}-{job.impulse:.2f}Ns.rawlog"
        path.parent.mkdir(parents=True, exist_ok=True)
        d, wall = self.run_one(job.cell, job.impulse, slot, record=path)
        return d, wall, path

    def job_finished(self, job, out):
        if job.kind == "extra":
            self.extra_running -= 1
            self.extra_remaining -= 1
            return
        cell, st = job.cell, job.st
        if job.kind == "record":
            st.record_running -= 1
            d, wall, path = out
            self.record_finished(cell, st, job.label, d, wall, path)
            return
        d, wall = out
        d = dict({"kind": "run"}, **d)
        st.in_flight.discard(job.k)
        imp = self.impulse(job.k)
        where = d["worker"] if self.executor.kind != "local" else ("" if self.inprocess else f"domain {d['domain']}")
        live = self.active.get(cell) is st and st.phase == "search"
        if live:
            st.ahead[job.k] = d
        self.progress.run_finished(
            wall, f"{cell_name(cell)} I = {imp:.2f} N s: {'recovered' if d['recovered'] else d['reason']} "
                  f"({wall:.1f} s{', ' + where if where else ''}{', ahead of the search' if job.ahead else ''})",
            self.remaining_runs(), worker=d["worker"])
        if live:
            self.advance(cell, st)
        else:
            self.discard(cell, d)

    def job_failed(self, job, error):
        """A run ahead of a search that failed is not fatal (the search may never ask for it): it is run again
        as a demanded run when the search asks for it. Returns True when it was such a run."""
        if job.kind != "run" or not job.ahead or isinstance(error, Interrupted) or REGISTRY.stopping.is_set():
            return False
        job.st.in_flight.discard(job.k)
        job.st.failed_ahead.add(job.k)
        log(f"{cell_name(job.cell)} I = {self.impulse(job.k):.2f} N s, run ahead of the search: {error}; "
            f"it is run again if the search asks for it")
        return True

    # ------------------------------------------------------------------------------------------------- all
    def announce(self, what):
        """Logs the start of a study (`what`, then where its runs go and the load average); returns the load text."""
        load0 = load_text()
        log(what + ("in process, " if self.args.inprocess else "") + self.executor.describe()
            + f"; load average {load0}")
        return load0

    def run(self, extra_jobs=()):
        """Searches every cell not on file with one thread per slot; `extra_jobs` are callables job(slot) run by
        the same slots, first. Returns the wall time."""
        todo = [c for c in self.cells if c not in self.results.cells]
        if self.results.resumed:
            log(f"resuming {self.out / 'results.jsonl'}: {len(self.cells) - len(todo)} of {len(self.cells)} cells "
                f"done, {len(self.results.runs)} runs on file")
        with self.lock:
            self.extra_queue, self.extra_running = list(extra_jobs), 0
            self.extra_remaining = len(extra_jobs)
            self.pending, self.active = list(todo), {}
        errors = []
        slots = self.executor.slots()

        def worker(i):
            slot = slots[i]
            while True:
                job = None
                try:
                    with self.wake:
                        while True:
                            if REGISTRY.stopping.is_set() or errors:
                                return
                            job = self.next_job()
                            if job is not None:
                                break
                            if self.all_done():
                                self.wake.notify_all()
                                return
                            self.wake.wait(0.5)
                    out = self.execute(job, slot)
                    with self.wake:
                        self.job_finished(job, out)
                        self.wake.notify_all()
                except Interrupted:
                    return
                except BaseException as e:  # noqa: the main thread reports it
                    with self.wake:
                        if job is not None and self.job_failed(job, e):
                            self.wake.notify_all()
                            continue
                        errors.append(e)
                        self.wake.notify_all()
                    REGISTRY.stop_all()
                    self.executor.cancel()
                    return

        t0 = time.monotonic()
        run_workers(worker, len(slots), errors,
                    "interrupted: stopping the runs in flight (finished runs are kept in results.jsonl)")
        if self.discarded_runs:
            log(f"{self.discarded_runs} runs ahead of a search were not needed by it (discarded)")
        return time.monotonic() - t0
