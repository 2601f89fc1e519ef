"""recovery-map: how often each controller recovers, over impulse, gait phase and push direction.

Table II's I_max is one number per cell: the last impulse before the first failure, for one push phase (the
right foot's lift-off) and one direction. This command runs the whole grid: per base height, controller and
direction (forward, backward), and per push phase over one gait cycle, the impulses from --start up in --step
steps; a row (height, controller, direction, phase) stops once --stop-after N s of impulses in a row all failed
(past its last recovery), or at --max-impulse.

Phases: --phases N points of the gait cycle u = 0, 1/N, ... The cycle is the step whose stance leg is the left
(the right foot swings) and then the step on the right leg; u < 0.5 is the planner's phase 2u of the left-stance
step, u >= 0.5 the phase 2u - 1 of the right-stance step. The push goes at that planner phase of the first step
with that stance leg that starts after --push-after (the planner's phase variable and stance leg, not a clock
time; chain/push_schedule.hpp). u = 0 is the paper's push: the right foot's lift-off, with the very trigger
push-sweep uses, so that column is Table II's search on a coarser grid.

The verdict is the project's one recovery criterion (back to stepping in place; chain/push_recovery.hpp):
recovered, drifting (no fall, not stepping in place at the end) or fell (with the fall's reason). Per (height,
controller, direction): the recovery probability over the phases per impulse with Wilson 95 % intervals; I_50
and I_90 (where it falls below 50 % and 90 %, interpolated) with bootstrap 95 % intervals over the phases; per
phase the paper's I_max (last impulse before the first failure) and the largest recovered impulse.

Runs in process by default (mft-closedloop); --stack on the multi-process stack, --scheduler on Dask workers
(either way). Every finished run is a line of OUT/results.jsonl (fsync'ed): the same command resumes.
Outputs: table.md (with the paper's Table II beside), map.json, heatmaps.png, probability.png."""
import json
import math
import os
import threading
import time
from dataclasses import asdict, replace
from pathlib import Path

from . import push as pushmod
from .common import ExperimentError, Progress, log, run_workers
from .executor import make_executor, run_task

DIRECTIONS = ("forward", "backward")


def phase_points(n):
    """[(label, u, stance_leg or None, planner phase or None)] for n points of the cycle; u = 0 is the paper's
    lift-off trigger (stance None)."""
    pts = []
    for i in range(n):
        u = i / n
        if i == 0:
            pts.append(("liftoff", 0.0, None, None))
            continue
        stance, p = ("left", 2 * u) if u < 0.5 else ("right", 2 * u - 1)
        pts.append((f"u{u:.3f}", round(u, 6), stance, round(p, 6)))
    return pts


def impulse_grid(start, step, max_impulse):
    n = int(math.floor((max_impulse - start) / step + 1e-9))
    return [round(start + k * step, 6) for k in range(n + 1)]


def run_scenario_dict(setup, height, controller, direction, point, impulse):
    """push-sweep's scenario (pushmod.scenario); a phase point replaces the lift-off trigger with its phase."""
    s = pushmod.scenario(replace(setup, direction=direction), height, controller, impulse)
    label, _, stance, phase = point
    if stance is not None:
        p = s["pushes"][0]
        del p["at_liftoff"]
        p["at_phase"], p["stance"] = phase, stance
        s["name"] += f"-{label}"
        s["description"] = s["description"].replace(f"the first {setup.liftoff} lift-off",
                                                    f"phase {phase:.3f} of the first {stance}-stance step")
    return s


def run_key(h, c, d, label, impulse):
    return f"{h:.3f}/{c}/{d}/{label}/{impulse:.3f}"


class MapResults:
    """results.jsonl: a header line (the settings) and one line per finished run, fsync'ed; resumable."""

    def __init__(self, path, header):
        self.path, self.lock, self.runs = Path(path), threading.Lock(), {}
        if self.path.exists():
            self._load(header)
        else:
            self._append(header)

    def _load(self, header):
        lines = [x for x in self.path.read_text().splitlines() if x.strip()]
        good = []
        for n, line in enumerate(lines, 1):
            try:
                good.append(json.loads(line))
            except ValueError:
                if n != len(lines):
                    raise ExperimentError(f"{self.path}:{n}: not a JSON line; is this a recovery-map results file?")
                log(f"{self.path}: dropping an incomplete last line")
        if not good or good[0].get("kind") != "recovery-map":
            raise ExperimentError(f"{self.path}: not a recovery-map results file (no 'recovery-map' header line)")
        if good[0].get("settings") != header["settings"]:
            raise ExperimentError(f"{self.path} was made with other settings ({good[0].get('settings')}); resume it "
                                  f"with the same options or choose another --out")
        for d in good[1:]:
            self.runs[run_key(d["height"], d["controller"], d["direction"], d["phase"], d["impulse_Ns"])] = d
        self.path.write_text("".join(json.dumps(d) + "\n" for d in good))
        log(f"resuming {self.path}: {len(self.runs)} runs on file")

    def _append(self, d):
        line = (json.dumps(d) + "\n").encode()
        with self.lock:
            fd = os.open(self.path, os.O_WRONLY | os.O_APPEND | os.O_CREAT, 0o644)
            try:  # one write of the whole line, on disk before the run counts as done
                os.write(fd, line)
                os.fsync(fd)
            finally:
                os.close(fd)

    def add(self, d):
        self._append(d)
        with self.lock:
            self.runs[run_key(d["height"], d["controller"], d["direction"], d["phase"], d["impulse_Ns"])] = d

    def get(self, key):
        with self.lock:
            return self.runs.get(key)


FALL_KINDS = (("base below", "base too low"), ("pitch beyond", "pitched over"), ("singular", "leg singular"),
              ("not finite", "state not finite"))


def outcome_of(sim):
    """(outcome, how) from a run's summary: recovered | drifting | fell | not_pushed; for a fall, how it fell (the
    run monitor's first criterion: base too low, pitched over, <body> on the ground, leg singular)."""
    v = (sim.get("recovery") or {}).get("verdict") or {}
    outcome = v.get("outcome", "not_pushed")
    if outcome != "fell":
        return outcome, None
    reason = sim.get("fall_reason") or ""
    for text, kind in FALL_KINDS:
        if text in reason:
            return outcome, kind
    body = (sim.get("first_body_contact") or {}).get("body")
    return outcome, f"{body} on the ground" if body else (reason or "fell")


class RecoveryMap:
    """The grid's rows, each scanned upward on one slot; the slots are the executor's (local or Dask)."""

    def __init__(self, args, setup):
        self.args, self.setup = args, setup
        self.out = Path(args.out)
        self.out.mkdir(parents=True, exist_ok=True)
        self.points = phase_points(args.phases)
        self.impulses = impulse_grid(args.start, args.step, args.max_impulse)
        self.stop_k = max(1, int(round(args.stop_after / args.step)))
        self.rows = [(h, c, d, p) for h in args.heights for c in args.controllers for d in args.directions
                     for p in self.points]
        self.inprocess = not args.stack
        settings = {"setup_key": setup.key(), "setup": asdict(setup), "impulses": [args.start, args.step, args.max_impulse],
                    "stop_after_Ns": args.stop_after, "phases": args.phases,
                    "runner": "inprocess" if self.inprocess else "stack"}
        self.results = MapResults(self.out / "results.jsonl", {"kind": "recovery-map", "settings": settings,
                                                               "created": time.strftime("%Y-%m-%d %H:%M:%S")})
        self.lock = threading.Lock()
        self.next_row = 0
        self.rows_finished, self.runs_in_finished = 0, 0

    def row_runs(self, row):
        """The impulses the row's scan runs, given the outcomes so far (on file): from the first, until
        stop_k failures in a row or the grid's end. Yields each impulse; the caller runs it when not on file."""
        fails = 0
        for i in self.impulses:
            yield i
            d = self.results.get(run_key(*row[:3], row[3][0], i))
            fails = 0 if d["recovered"] else fails + 1
            if fails >= self.stop_k:
                return

    def expected_left(self):
        """A guess of the runs left for the ETA: each row not finished as long as the mean finished row (half the
        grid before any has finished), less the runs the rows in progress did."""
        with self.lock:
            finished, runs_in_finished, started = self.rows_finished, self.runs_in_finished, self.next_row
        per_row = runs_in_finished / finished if finished else len(self.impulses) / 2
        in_progress = len(self.results.runs) - runs_in_finished
        return max(0.0, (len(self.rows) - finished) * per_row - in_progress)

    def run_one(self, slot, row, impulse):
        h, c, d, point = row
        task = run_task(f"{run_key(h, c, d, point[0], impulse).replace('/', '_')}",
                        run_scenario_dict(self.setup, h, c, d, point, impulse), self.setup.profiles,
                        timeout_s=600.0, inprocess=self.inprocess)
        r = slot.run(task, self.out / "runs" / task["name"])
        recovered, reason = pushmod.judge(r.sim)
        if recovered is None:
            raise ExperimentError(f"run {task['name']}: {reason}")
        outcome, how = outcome_of(r.sim)
        rec = {"height": h, "controller": c, "direction": d, "phase": point[0], "cycle_u": point[1],
               "stance": point[2], "planner_phase": point[3], "impulse_Ns": impulse, "recovered": recovered,
               "outcome": outcome, "how": how, "push_time_s": (r.sim.get("recovery") or {}).get("push_time_s"),
               "wall_s": round(r.wall, 3), "worker": r.worker, "runner": "inprocess" if self.inprocess else "stack"}
        self.results.add(rec)
        return rec, r.wall

    def scan(self, slot, row):
        n = 0
        for i in self.row_runs(row):
            n += 1
            if self.results.get(run_key(*row[:3], row[3][0], i)) is not None:
                continue
            rec, wall = self.run_one(slot, row, i)
            self.progress.run_finished(wall, f"{row[0]:.2f} m {row[1]} {row[2]} {row[3][0]} I = {i:.2f} N s: "
                                             f"{rec['outcome']}", self.expected_left(), worker=rec["worker"])
        with self.lock:
            self.rows_finished += 1
            self.runs_in_finished += n

    def run(self):
        executor = make_executor(self.args, self.args.config_dir)
        slots = executor.slots()
        self.progress = Progress(len(slots), quiet=self.args.quiet)
        self.progress.note(f"{len(self.rows)} rows (heights x controllers x directions x {len(self.points)} phases), "
                           f"impulses {self.impulses[0]:g}..{self.impulses[-1]:g} N s by {self.args.step:g}, "
                           f"{'in process' if self.inprocess else 'on the stack'}, "
                           f"{executor.describe() if executor.kind != 'local' or not self.inprocess else f'{len(slots)} runs at a time'}")
        errors = []

        def worker(i):
            while not errors:
                with self.lock:
                    if self.next_row >= len(self.rows):
                        return
                    row = self.rows[self.next_row]
                    self.next_row += 1
                try:
                    self.scan(slots[i], row)
                except Exception as e:  # noqa: reported once, as one line, by run_workers
                    errors.append(e)
                    executor.cancel()
        try:
            run_workers(worker, len(slots), errors, "interrupted: stopping the runs in flight (finished runs are kept "
                                                    "in results.jsonl)")
        finally:
            executor.close()
        return [d for d in self.results.runs.values()]


def cmd_recovery_map(args):
    from .recovery_report import write_outputs
    if args.phases < 8 and not args.allow_few_phases:
        raise ExperimentError("--phases must be at least 8 (one gait cycle); --allow-few-phases for a quick look")
    if args.start > args.max_impulse or args.max_impulse > 100:
        raise ExperimentError("need --start <= --max-impulse <= 100 N s (the scenario format's limit)")
    setup = pushmod.PushSetup(push_after_s=args.push_after, observe_s=args.observe, profiles=list(args.profile))
    t0 = time.monotonic()
    m = RecoveryMap(args, setup)
    runs = m.run()
    return write_outputs(m, runs, t0)
