#!/usr/bin/env python3
"""The sweep's schedule with runs ahead of a search (mftexp.sweep.Sweep.run, no stack): stand-in slots answer each
run from a fixed outcome pattern after a short sleep. With speculation the sweep must give what the paper's search
gives one run after the other (find_imax on the same pattern): the same I_max and cell records, the same runs in
results.jsonl in the same order per cell, the same recorded re-runs; the second slot must stay busy while one
long cell is left; an interrupted sweep resumes to the same file."""
import argparse
import json
import sys
import tempfile
import threading
import time
import unittest
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "python"))
from mftexp import push as pushmod  # noqa: E402
from mftexp.common import REGISTRY, DEFAULT_CONFIG, Interrupted  # noqa: E402
from mftexp.executor import RunResult  # noqa: E402
from mftexp.sweep import Sweep, find_imax  # noqa: E402

START, STEP = 3.0, 0.1
# Outcome patterns per (height, controller) on the grid k = 0, 1, ... (R recovered, F failed; beyond: failed).
# Non-monotone on purpose (recoveries above the first failure, an isolated failure below a later one), and one
# long cell (0.46 mft) that is left alone at the end of the sweep.
PATTERNS = {
    (0.38, "sa"): "RRRRRFRRFRFFFFFFFFFFF",
    (0.38, "mft"): "RRRRRRRRFFRFFFFFFFF",
    (0.46, "sa"): "RRRFFFFFFFFFFFFFF",
    (0.46, "mft"): "R" * 40 + "FRFFRFFFFFFFFFF",
}


def pattern_recovered(height, controller, impulse):
    k = int(round((impulse - START) / STEP))
    p = PATTERNS[(round(height, 2), controller)]
    return k < len(p) and p[k] == "R"


class FakeSlot:
    def __init__(self, executor, index):
        self.executor, self.domain, self.name = executor, 90 + index, f"fake/{index}"

    def run(self, task, run_dir, record_path=None):
        ex = self.executor
        s = task["scenario"]
        impulse = abs(s["pushes"][0]["impulse_Ns"])
        recovered = pattern_recovered(s["initial_base_height_m"], s["controller"], impulse)
        with ex.lock:
            ex.started += 1
            n = ex.started
            if ex.stop_after is not None and n > ex.stop_after:
                REGISTRY.stopping.set()  # what Ctrl-C does: every run in flight ends with Interrupted
            if REGISTRY.stopping.is_set():
                raise Interrupted()
        t0 = time.monotonic()
        time.sleep(ex.run_s)
        Path(run_dir).mkdir(parents=True, exist_ok=True)
        if record_path:
            Path(record_path).write_text("fake rawlog")
        with ex.lock:
            ex.busy.append((t0, time.monotonic(), self.name))
            ex.asked.append((s["initial_base_height_m"], s["controller"], round(impulse, 6), bool(record_path)))
        outcome = "recovered" if recovered else "fell"
        sim = {"fell": not recovered, "fall_time_s": None if recovered else 3.6, "ticks": 8000,
               "fall_reason": None if recovered else "base below 0.25 m",
               "recovery": {"verdict": {"outcome": outcome, "recovered": recovered, "no_fall": recovered,
                                        "back_to_stepping": recovered, "reason": outcome},
                            "push_time_s": 3.1, "pre": None, "after": None, "tail": None}}
        return RunResult(sim, time.monotonic() - t0, self.name, self.domain)


class FakeExecutor:
    kind = "local"

    def __init__(self, workers, run_s=0.03, stop_after=None):
        self.workers, self.run_s, self.stop_after = workers, run_s, stop_after
        self.lock = threading.Lock()
        self.started, self.busy, self.asked = 0, [], []

    def slots(self):
        return [FakeSlot(self, i) for i in range(self.workers)]

    def describe(self):
        return f"{self.workers} stand-in slots"

    def info(self):
        return {"backend": "fake", "workers": self.workers}

    def cancel(self):
        pass

    def close(self):
        pass


def make_args(out, speculate, heights=(0.38, 0.46), controllers=("sa", "mft")):
    return argparse.Namespace(out=str(out), start=START, step=STEP, max_impulse=8.0, search="linear", coarse=0.5,
                              above=0.5, heights=list(heights), controllers=list(controllers),
                              config_dir=str(DEFAULT_CONFIG), quiet=True, keep_rawlogs=True, inprocess=False,
                              profile=[], speculate=speculate)


def run_sweep(out, speculate, workers=2, stop_after=None, **kw):
    ex = FakeExecutor(workers, stop_after=stop_after)
    sweep = Sweep(make_args(out, speculate, **kw), pushmod.PushSetup(), executor=ex)
    wall = sweep.run()
    return sweep, ex, wall


def file_lines(out):
    """results.jsonl's lines, with the output folder written as OUT (two sweeps in two folders compare equal)."""
    text = (Path(out) / "results.jsonl").read_text().replace(str(out), "OUT")
    return [json.loads(line) for line in text.splitlines()]


def comparable(lines):
    """The results file without what may differ between two schedules: timing, slot, domain, run order across cells.
    Per cell, the order of its run lines is kept."""
    drop = {"wall_s", "worker", "domain", "finished_at", "created"}
    per_cell = {}
    for d in lines[1:]:
        key = (d["kind"], d.get("height"), d.get("controller"))
        per_cell.setdefault(key, []).append({k: v for k, v in d.items() if k not in drop})
    return per_cell


class SpeculationTest(unittest.TestCase):
    def setUp(self):
        # on tmpfs where there is one: results.jsonl is fsync'ed line by line, slow on a busy disk
        shm = Path("/dev/shm")
        self.tmp = tempfile.TemporaryDirectory(prefix="mft-test-speculation-", dir=shm if shm.is_dir() else None)
        self.dir = Path(self.tmp.name)
        REGISTRY.stopping.clear()

    def tearDown(self):
        REGISTRY.stopping.clear()
        self.tmp.cleanup()

    def reference(self, height, controller, kmax, above_k):
        asked = []

        def rec(k):
            asked.append(k)
            return pattern_recovered(height, controller, START + STEP * k)
        lo, fail, _ = find_imax(rec, kmax, "linear", 5, above_k)
        return lo, fail, asked

    def test_same_imax_runs_and_records_as_the_search_one_run_after_the_other(self):
        serial, serial_ex, _ = run_sweep(self.dir / "serial", speculate=False, workers=1)
        fast, fast_ex, _ = run_sweep(self.dir / "ahead", speculate=True, workers=2)
        for (h, c) in PATTERNS:
            lo, fail, asked = self.reference(h, c, serial.kmax, serial.above_k)
            cell = fast.results.cells[("default", h, c, "forward")]
            self.assertEqual(cell["i_max_Ns"], round(START + STEP * lo, 6), (h, c))
            self.assertEqual(cell["failed_Ns"], round(START + STEP * fail, 6), (h, c))
            runs = [d["impulse_Ns"] for d in file_lines(self.dir / "ahead")
                    if d["kind"] == "run" and (d["height"], d["controller"]) == (h, c)]
            self.assertEqual(runs, [round(START + STEP * k, 6) for k in asked], f"{h} {c}: runs on file, in order")
            self.assertEqual(sorted(fast.results.records[("default", h, c, "forward", lab)]["impulse_Ns"]
                                    for lab in ("recovered", "failed")),
                             sorted([cell["recovered_Ns"], cell["failed_Ns"]]))
        self.assertEqual(comparable(file_lines(self.dir / "ahead")), comparable(file_lines(self.dir / "serial")))
        # every run ahead was reached by its search: nothing discarded with the linear search, none run twice
        self.assertEqual(fast.discarded_runs, 0)
        pushed = [a for a in fast_ex.asked if not a[3]]
        self.assertEqual(len(pushed), len(set(pushed)))
        self.assertEqual(len(pushed), len([a for a in serial_ex.asked if not a[3]]))

    def test_the_second_slot_works_on_the_last_cell(self):
        # Two cells, one short (4 + 5 runs), one long (41 + 5 runs). Once the short cell is done, without runs
        # ahead one slot works alone; with them the runs of the long cell overlap in time on both slots.
        kw = dict(heights=(0.46,), controllers=("sa", "mft"))
        overlapping = {}
        for speculate in (False, True):
            sweep, ex, _ = run_sweep(self.dir / f"tail-{speculate}", speculate=speculate, **kw)
            short_done = max(t1 for (t0, t1, _), a in zip(ex.busy, ex.asked) if a[1] == "sa")
            tail = [(t0, t1, slot) for (t0, t1, slot), a in zip(ex.busy, ex.asked) if a[1] == "mft" and t0 >= short_done]
            both = [r for r in tail if any(o[2] != r[2] and o[0] < r[1] and r[0] < o[1] for o in ex.busy)]
            overlapping[speculate] = len(both) / len(tail)
            self.assertGreater(len(tail), 30, "the long cell was not left alone at the end")
        print(f"runs of the last cell that overlap a run on the other slot: without runs ahead "
              f"{overlapping[False]:.2f}, with {overlapping[True]:.2f}")
        self.assertLess(overlapping[False], 0.2, "without runs ahead the last cell still used both slots")
        self.assertGreater(overlapping[True], 0.9, "with runs ahead a slot idled while the last cell was searched")

    def test_an_interrupted_sweep_resumes_to_the_same_file(self):
        sweep, _, _ = run_sweep(self.dir / "cut", speculate=True, stop_after=25)  # stops after 25 runs started
        REGISTRY.stopping.clear()
        cut = file_lines(self.dir / "cut")
        # what is on file is, per cell, a prefix of the runs the search asks for, in its order
        for (h, c) in PATTERNS:
            _, _, asked = self.reference(h, c, sweep.kmax, sweep.above_k)
            runs = [d["impulse_Ns"] for d in cut if d["kind"] == "run" and (d["height"], d["controller"]) == (h, c)]
            self.assertEqual(runs, [round(START + STEP * k, 6) for k in asked][:len(runs)], (h, c))
        self.assertLess(len([d for d in cut if d["kind"] == "run"]), 25)
        _, ex2, _ = run_sweep(self.dir / "cut", speculate=True)
        on_file_before = {(d["height"], d["controller"], d["impulse_Ns"]) for d in cut if d["kind"] == "run"}
        rerun = [a for a in ex2.asked if not a[3] and (a[0], a[1], a[2]) in on_file_before]
        self.assertEqual(rerun, [], "a run on file was run again")
        run_sweep(self.dir / "whole", speculate=False, workers=1)
        self.assertEqual(comparable(file_lines(self.dir / "cut")), comparable(file_lines(self.dir / "whole")))


if __name__ == "__main__":
    unittest.main(verbosity=2)
