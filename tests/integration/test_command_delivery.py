#!/usr/bin/env python3
"""Every reader the stack has gets mft-cmd's requests, the recorder included, or the loss is counted and named
(docs/guide/operator-commands.md, "Every reader gets it").

One recorded realtime stack standing (`up --record`, domain 88). Live changes (`--set`), operator commands and
pushes, applied and rejected, are sent three at a time: every request mft-cmd reports delivered to mft-record is
in the rawlog with its seq, exactly once. Then the recorder is stopped (SIGSTOP) for longer than mft-cmd's
--timeout: mft-cmd exits 6, names mft-record for each request, and those requests are not in the rawlog; after
SIGCONT the next requests reach it again. Needs MFT_BIN_DIR (set by CTest)."""
import concurrent.futures
import csv
import os
import signal
import subprocess
import sys
import unittest
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "python"))
from mftstack.testing import BIN, StackUpTestCase, mft_cmd  # noqa: E402

DOMAIN = 88
RECORDER = "mft-record"
TOPIC_OF = {"--set": "config_change", "--mode": "operator_cmd", "--push": "disturbance"}
# Bounds for a loaded machine; mft-cmd returns as soon as every reader acknowledged and the verdict came.
BOUNDS = ("--timeout", 20, "--verdict-timeout", 30)


def round_of_requests(seq):
    """One round: (argv, the seqs it carries, the exit statuses it may end with when every reader has it)."""
    return [
        (["--set", "wbc.weights.slack=1e4"], [seq], (0, 1)),
        (["--set", "wbc.weights.slack=1e5", "--set", "planner.foot_placement.k_v=0.15"], [seq + 1, seq + 2], (0, 1)),
        (["--set", "wbc.weights.slak=1"], [seq + 3], (1,)),          # unknown key: rejected by the WBC
        (["--mode", "stand", "--height", 0.42], [seq + 4], (0,)),
        (["--mode", "stand", "--height", 0.41], [seq + 5], (0,)),
        (["--mode", "stand", "--height", 0.9], [seq + 6], (1,)),     # out of reach: rejected by the planner
        (["--push", 1.0], [seq + 7], (0,)),
        (["--push", 250], [seq + 8], (1,)),                          # beyond the largest push: rejected
    ]


def send(argv, seqs, *extra):
    """mft-cmd with --seq (the first seq; --set numbers its changes on from it); (code, JSON, stderr)."""
    code, result, err, _ = mft_cmd(DOMAIN, *argv, "--seq", seqs[0], *extra, timeout=120)
    return code, result, err


def reaches(result):
    """[(delivered_to, not_delivered_to)] of each request in mft-cmd's JSON (one per change for --set)."""
    parts = result.get("changes", [result])
    return [(p["delivered_to"], p["not_delivered_to"]) for p in parts]


def export_seqs(rawlog, out):
    """{label: sorted seqs} of the requests in the rawlog (config_change: the requests, applied 0)."""
    p = subprocess.run([str(BIN / "mft-export"), str(rawlog), "--csv", str(out), "--labels", ",".join(TOPIC_OF.values())],
                       capture_output=True, text=True, timeout=300)
    if p.returncode != 0:
        raise AssertionError(f"mft-export {rawlog}: exit {p.returncode}: {p.stderr}")
    seqs = {}
    for label in TOPIC_OF.values():
        path = out / f"{label}.csv"
        rows = []
        if path.exists():  # a label without observations gets no file
            with open(path) as f:
                rows = list(csv.DictReader(f))
        if label == "config_change":
            rows = [r for r in rows if float(r["applied"]) == 0.0]
        seqs[label] = sorted(int(float(r["seq"])) for r in rows)
    return seqs


class EveryReaderGetsTheRequest(StackUpTestCase):
    """The tests run in name order against one stack; the last one stops it and reads the recording."""

    tmp_prefix = "mft-cmd-delivery-"
    stack_scenario = "stand.yaml"
    stack_domain = DOMAIN
    stack_run_dir = True

    @classmethod
    def stack_up_args(cls):
        cls.rawlog = cls.stacks.path / "delivery.rawlog"
        return ("--mode", "realtime", "--record", cls.rawlog)

    @classmethod
    def setUpClass(cls):
        cls.delivered = {label: [] for label in TOPIC_OF.values()}  # seqs mft-cmd reported delivered to the recorder
        cls.lost = {label: [] for label in TOPIC_OF.values()}       # seqs it reported missing from the recorder
        super().setUpClass()

    def note(self, argv, seqs, result):
        """Files each request's seq under what mft-cmd said of the recorder."""
        label = TOPIC_OF[argv[0]]
        for seq, (delivered, missed) in zip(seqs, reaches(result)):
            if RECORDER in delivered:
                self.delivered[label].append(seq)
            if RECORDER in [m["service"] for m in missed]:
                self.lost[label].append(seq)

    def send_all(self, requests, *extra):
        with concurrent.futures.ThreadPoolExecutor(max_workers=3) as pool:
            futures = [(argv, seqs, codes, pool.submit(send, argv, seqs, *extra)) for argv, seqs, codes in requests]
            return [(argv, seqs, codes) + f.result() for argv, seqs, codes, f in futures]

    def assert_delivered_rounds(self, first_seq, rounds):
        requests = [r for i in range(rounds) for r in round_of_requests(first_seq + 100 * i)]
        for argv, seqs, codes, code, result, err in self.send_all(requests, *BOUNDS):
            self.assertIsNotNone(result, f"{argv}: no JSON (exit {code}): {err}")
            self.assertIn(code, codes, (argv, result, err))
            for delivered, missed in reaches(result):
                self.assertEqual(missed, [], (argv, result, err))
                self.assertIn(RECORDER, delivered, (argv, result))
                self.assertIn("mft-planner" if argv[0] != "--push" else "mft-sim", delivered, (argv, result))
            self.note(argv, seqs, result)

    def test_1_every_request_reaches_every_reader(self):
        self.assert_delivered_rounds(1000, 2)

    def test_2_a_stopped_recorder_is_named_and_counted(self):
        pid = self.status["services"][RECORDER]["pid"]
        requests = [(["--set", "wbc.weights.slack=1e4"], [3000], (6,)), (["--mode", "stand", "--height", 0.42], [3001], (6,)),
                    (["--mode", "stand", "--height", 0.9], [3002], (6,)), (["--push", 1.0], [3003], (6,))]
        os.kill(pid, signal.SIGSTOP)
        try:  # stopped for the whole of each call: longer than its --timeout of 2 s
            results = self.send_all(requests, "--timeout", 2, "--verdict-timeout", 30)
        finally:
            os.kill(pid, signal.SIGCONT)
        for (argv, seqs, codes, code, result, err), verdict in zip(results, ["applied", "applied", "rejected", "applied"]):
            self.assertEqual(code, 6, (argv, result, err))
            self.assertEqual(result["exit_code"], 6, result)
            self.assertFalse(result["acknowledged"], result)
            for delivered, missed in reaches(result):
                self.assertEqual([m["service"] for m in missed], [RECORDER], (argv, result))
                self.assertRegex(missed[0]["reason"], "not discovered|gone from the domain", result)
                self.assertNotIn(RECORDER, delivered, result)
            self.assertIn("did not reach every reader of the stack: mft-record (", err)
            self.assertIn("so the recording lacks it", err)
            final = result["changes"][0]["result"] if "changes" in result else result["result"]
            self.assertEqual(final, "rejected" if verdict == "rejected" else "applied", (argv, result))
            self.note(argv, seqs, result)
        self.assertEqual(sum(len(v) for v in self.lost.values()), 4, self.lost)

    def test_3_after_sigcont_the_recorder_gets_the_requests_again(self):
        self.assert_delivered_rounds(4000, 1)

    def test_4_the_rawlog_holds_exactly_the_requests_reported_delivered(self):
        self.stacks.down(DOMAIN)
        recorded = export_seqs(self.rawlog, self.stacks.path / "csv")
        for label in TOPIC_OF.values():
            self.assertEqual(recorded[label], sorted(self.delivered[label]), label)  # count and seq
            self.assertFalse(set(recorded[label]) & set(self.lost[label]), label)
        counts = {label: len(v) for label, v in recorded.items()}
        self.assertEqual(counts, {"config_change": 12, "operator_cmd": 9, "disturbance": 6}, recorded)
        print(f"\nrecorded requests {counts}; reported lost (recorder stopped) "
              f"{ {k: len(v) for k, v in self.lost.items()} }", file=sys.stderr)


if __name__ == "__main__":
    unittest.main(verbosity=2)
