#!/usr/bin/env python3
"""The stack on three hosts (docs/guide/distributed.md): Linux network namespaces made by the test (testnet.py) on a
private subnet 10.77.<domain>.0/24, joined by veths through a bridge in a switch namespace; the simulator on
`robot`, the WBC on `ctrl`, estimator, planner and recorder on `aux`, started through
`mft-supervisor --stack`. Faults on the veth links: nftables random loss, tc tbf, link down.

  - lockstep, initial peers: steps in place 10 s without falling, every service answers every tick, the
    recorder writes every tick it received;
  - realtime with 1 % random loss on every link: keeps stepping, the simulator reports the lost commands;
  - realtime, the WBC host's link cut for 200 ms: the simulator damps within 5 ms of the missed deadline for
    about the cut, recovers when the link returns, the recorder loses nothing it received;
  - lockstep through a Fast DDS discovery server (supervised by mft-supervisor on aux);
  - lockstep with one supervisor per host (`--host`), as on real machines;
  - lockstep secured with DDS Security (--secure) across the hosts;
  - a tbf rate limit on the robot's link below the stack's bandwidth: what happens (measured and reported).

Skipped with a clear message where network namespaces cannot be made (not root, no CAP_SYS_ADMIN, no ip/nft/tc).
DDS domains 230-232; each test runs in namespaces of its own (deleted in tearDown even on failure, every
process stopped by pid through the supervisor's `down` or by its run's end)."""
import json
import subprocess
import sys
import time
import unittest
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "python"))
from testnet import TestNet, netns_permitted, realtime_priority  # noqa: E402
from stack_layout import HOSTS, PLACEMENT  # noqa: E402
from mftstack.simlog import SimLog, run_tests  # noqa: E402
from mftstack.testing import BIN, REPO, SCENARIOS, StackTestCase  # noqa: E402

CHAIN_TOPICS = ["GroundTruth", "SensorData", "RobotState", "Reference", "JointCommand", "WbcDiagnostics"]
PERMITTED, WHY_NOT = netns_permitted()
# Stepping in place, 200 ms without a controller make the robot fall for good (measured, docs/guide/distributed.md):
# the cut test stands (0.40 m), as the fault tests do (docs/results/faults.md).
CUT_SCENARIO = "stand.yaml"
STAND_HEIGHT_M = 0.40


def log(msg):
    print(msg, file=sys.stderr, flush=True)


@unittest.skipUnless(PERMITTED, f"distributed tests skipped: network namespaces are not permitted here ({WHY_NOT}); "
                                "they need root with CAP_SYS_ADMIN, iproute2, nftables and tc")
class DistributedTest(StackTestCase):
    tmp_prefix = "mft-distributed-test-"

    def setUp(self):
        super().setUp()
        self.nets = []

    def tearDown(self):
        try:
            self.stacks.close()  # stacks and supervisors first, then their networks
        finally:
            for net in self.nets:
                net.destroy()

    # ------------------------------------------------------------------------------------------ helpers
    def network(self, domain, discovery="initial_peers"):
        net = TestNet.for_test(f"d{domain}", HOSTS, domain)
        self.nets.append(net)
        net.create()
        stack = self.tmp / f"stack-{domain}.yaml"
        stack.write_text(net.stack_yaml(PLACEMENT, discovery, server_host="aux"))
        return net, stack

    def scenario(self, name, duration_s=None):
        if duration_s is None:
            return SCENARIOS / name
        text = (SCENARIOS / name).read_text()
        self.assertIn("duration_s: 10.0", text)
        path = self.tmp / name.replace(".yaml", f"-{duration_s:g}s.yaml")
        path.write_text(text.replace("duration_s: 10.0", f"duration_s: {duration_s}"))
        return path

    def run_start(self, scenario, domain, stack, *extra):
        """Starts `mft-supervisor run --json` in the background; returns (process, run folder)."""
        p = self.stacks.start_run(scenario, domain, "--stack", stack, *extra, run_dir=self.tmp / f"run-{domain}")
        return p, p.run_dir

    def up(self, scenario, domain, stack, *extra):
        return self.stacks.up(scenario, domain, "--stack", stack, *extra)

    def down(self, domain, status):
        return self.stacks.down(domain, status, names=PLACEMENT)

    def assert_stepped_in_place(self, code, s, err, ticks):
        self.assertEqual(code, 0, err[-3000:])
        sim = s["services"]["mft-sim"]
        self.assertFalse(s["fell"], sim.get("fall_reason"))
        self.assertEqual(s["ticks"], ticks)
        return sim

    def check_recorder_kept_what_it_received(self, rec, record_file):
        """Every sample the recorder received is in the file once: received = written + repeated (a re-sent
        tick is written once), nothing dropped, no error, and the rawlog holds exactly `written` ticks."""
        self.assertEqual(rec.get("error", ""), "", rec.get("error"))
        for topic in CHAIN_TOPICS:
            t = rec["topics"][topic]
            self.assertEqual(t["dropped_queue"], 0, (topic, t))
            self.assertEqual(t["received"], t["written"] + t["repeated"], (topic, t))
        info = json.loads(subprocess.run([str(BIN / "mft-export"), str(record_file), "--info", "--json"],
                                         capture_output=True, text=True, timeout=120).stdout)
        for label, topic in (("gt_q", "GroundTruth"), ("joint_q", "SensorData"), ("est_q", "RobotState"),
                             ("plan_ref", "Reference"), ("joint_tau_cmd", "JointCommand"), ("wbc_diag", "WbcDiagnostics")):
            self.assertEqual(info["labels"][label]["count"], rec["topics"][topic]["written"], (label, topic))
        return {t: (rec["topics"][t]["first"], rec["topics"][t]["written"], rec["topics"][t]["tick_gaps"])
                for t in CHAIN_TOPICS}

    @staticmethod
    def link_rates(before, after, seconds):
        """kB/s sent and received by each host over its link."""
        return {h: {"tx_kBps": round((after[h]["tx_bytes"] - before[h]["tx_bytes"]) / seconds / 1e3, 1),
                    "rx_kBps": round((after[h]["rx_bytes"] - before[h]["rx_bytes"]) / seconds / 1e3, 1)}
                for h in before}

    # -------------------------------------------------------------------------------------------- tests
    def test_1_lockstep_three_hosts_steps_in_place(self):
        domain = 230
        net, stack = self.network(domain)
        record = self.tmp / "lockstep.rawlog"
        before = {h: net.counters(h) for h in HOSTS}
        t0 = time.monotonic()
        p, run_dir = self.run_start(self.scenario("step-in-place.yaml"), domain, stack, "--record", record)
        code, s, err = self.stacks.finish(p)
        wall = time.monotonic() - t0
        after = {h: net.counters(h) for h in HOSTS}
        sim = self.assert_stepped_in_place(code, s, err, 10000)
        for name in ("mft-estimator", "mft-planner", "mft-wbc"):
            self.assertEqual(s["services"][name]["ticks"], 10000, name)      # every tick answered once
            self.assertEqual(s["services"][name]["last_tick"], 9999, name)
        self.assertGreater(sim["touchdowns"][0], 5)                           # it really steps
        self.assertEqual(s["stack"]["discovery"], "initial_peers")
        self.assertEqual(s["stack"]["services"]["mft-wbc"], "ctrl")
        kept = self.check_recorder_kept_what_it_received(s["services"]["mft-record"], record)
        # The traffic really crossed the links: the simulator's samples left robot, the commands left ctrl.
        self.assertGreater(after["robot"]["tx_bytes"] - before["robot"]["tx_bytes"], 5e6)
        self.assertGreater(after["ctrl"]["tx_bytes"] - before["ctrl"]["tx_bytes"], 2e6)
        per_tick = {h: round((after[h]["tx_bytes"] - before[h]["tx_bytes"]) / 10000) for h in HOSTS}
        log(f"\nlockstep on three hosts: no fall, 10000 ticks answered by every service, sim wall "
            f"{sim['wall_time_s']:.2f} s ({sim['real_time_factor']:.2f}x real time), {sim['lockstep_resends']} re-sends, "
            f"whole run {wall:.1f} s; recorder (first tick, written, tick gaps) {kept}; bytes sent per tick {per_tick}")

    def test_2_realtime_one_percent_loss_keeps_stepping(self):
        domain = 231
        net, stack = self.network(domain)
        record = self.tmp / "loss.rawlog"
        p, run_dir = self.run_start(self.scenario("step-in-place.yaml"), domain, stack, "--mode", "realtime",
                                    "--record", record)
        self.stacks.wait_for_text(run_dir / "mft-sim.log", "READY mft-sim")
        with realtime_priority():
            for h in HOSTS:
                net.set_loss(h, 1)
        code, s, err = self.stacks.finish(p)
        drops = {h: net.loss_counters(h) for h in HOSTS}
        sim = self.assert_stepped_in_place(code, s, err, 10000)
        self.assertGreater(sum(d[0] for d in drops.values()), 100, drops)      # the loss was there
        self.assertGreater(sim["lost_commands"], 0, sim)                       # and the simulator saw it
        kept = self.check_recorder_kept_what_it_received(s["services"]["mft-record"], record)
        lat = sim["latency_us"]
        wbc = s["services"]["mft-wbc"]
        log(f"\n1 % loss on every link, realtime 10 s: no fall; packets dropped (dropped, passed) per host {drops}; "
            f"simulator: lost commands {sim['lost_commands']} ({sim['lost_commands'] / 10:.1f}/s), deadline misses "
            f"{sim['deadline_misses']} ({sim['deadline_misses'] / 10:.1f}/s), DDS reader deadline misses "
            f"{sim['reader_deadline_misses']}, damping ticks {sim['damping_ticks']}, commands received "
            f"{sim['commands_received']}; WBC answered {wbc['ticks']} ticks; latency p50 {lat['p50']:.0f} us p99 "
            f"{lat['p99']:.0f} us max {lat['max']:.0f} us; recorder (first tick, written, tick gaps) {kept}")

    def test_3_cut_of_the_wbc_link_damps_and_recovers(self):
        domain = 232
        net, stack = self.network(domain)
        record = self.tmp / "cut.rawlog"
        st = self.up(self.scenario(CUT_SCENARIO), domain, stack, "--mode", "realtime", "--record", record)
        sim_log = SimLog(Path(st["run_dir"]) / "mft-sim.log")
        sim_log.wait_for_sim_time(3.0)  # standing, settled
        cut_lo, cut_hi = net.cut("ctrl", 0.2)
        # Until the robot stands again with commands on every tick for a whole second (the progress lines come
        # every second of sim time, so one second after the newest line the link is certainly back). The test
        # used to sleep 2.5 s and then assert the height; 30 s only guards against a hang.
        sim_log.wait_for_commands_flowing(sim_log.sim_time() + 1.0, timeout=30, base_z=STAND_HEIGHT_M, z_tol=0.01)
        s = self.down(domain, st)
        sim, rec = s["mft-sim"], s["mft-record"]
        onset, late_ms, duration_ms = max(sim["damping_episodes"], key=lambda e: e[2])
        silent_ms = 3.0 + late_ms + duration_ms
        detail = f"link down {cut_lo * 1e3:.0f}-{cut_hi * 1e3:.0f} ms, damping episodes {sim['damping_episodes']}"
        self.assertGreater(duration_ms, 150.0, detail)      # the cut, not a stray late command
        # Commands came back soon after the link did, judged against the link's real down time: the `ip` command
        # that brings it back can itself take long on the busy VM even at SCHED_FIFO 85 (docs/guide/distributed.md), and
        # a fixed bound on the damping then fails the harness, not the stack. 400 ms is the old bound (600 ms of
        # damping) less the nominal 200 ms cut; measured recoveries are -2 to +39 ms after the link.
        self.assertLess(silent_ms - cut_hi * 1e3, 400.0, detail)
        self.assertLessEqual(late_ms, 5.0, detail)          # damping <= 5 ms after the deadline
        self.assertGreaterEqual(sim["watchdog_recoveries"], 1)
        kept = self.check_recorder_kept_what_it_received(rec, record)
        # No command from the last one before the cut to the first one after it: the deadline (3 ms), the
        # detection delay and the damping episode. Compared with the cut, what is left is how long the stack
        # took to answer again once the link was back (within the precision of the ip commands' timing).
        log(f"\n{CUT_SCENARIO}: ctrl link down {cut_lo * 1e3:.0f}-{cut_hi * 1e3:.0f} ms: damping {late_ms:.2f} ms after "
            f"the 3 ms deadline, for {duration_ms:.0f} ms (no command for {silent_ms:.0f} ms: recovery "
            f"{silent_ms - cut_hi * 1e3:+.0f} to {silent_ms - cut_lo * 1e3:+.0f} ms after the link); watchdog recoveries "
            f"{sim['watchdog_recoveries']}; fall criterion hit {sim['fell']} {sim.get('fall_reason', '')} at "
            f"{sim['fall_time_s']:.3f} s, largest sag {sim['base_height_error_m']['max'] * 100:.1f} cm, final base height "
            f"{sim['final_base_height_m']:.3f} m; all episodes "
            f"{sim['damping_episodes']}; recorder (first tick, written, tick gaps) {kept}")
        # 200 ms of damping let the base sink ~15 cm: past the fall threshold (base below 0.25 m) on most runs,
        # which a `run` would end with a fall. The long-running stack goes on (--continue-after-fall) and the
        # WBC stands the robot back up once its commands return: that is the recovery asserted here. The
        # damping mode's gain (3 N m s/rad) brakes the weight little: the simulator alone sinks a standing
        # robot 11 cm in 200 ms with it and 17 cm with none (test_sim SimDampingSag). The final height is the
        # commanded robot's: `down` stops the simulator and waits for it before it ends the controller (before,
        # the WBC could end first, leaving the simulator's last ticks to the damping mode on a loaded machine).
        self.assertLess(abs(sim["final_base_height_m"] - STAND_HEIGHT_M), 0.01, sim["final_base_height_m"])

    def test_4_discovery_server_lockstep(self):
        domain = 230
        net, stack = self.network(domain, discovery="server")
        p, run_dir = self.run_start(self.scenario("step-in-place.yaml", 5.0), domain, stack)
        code, s, err = self.stacks.finish(p)
        sim = self.assert_stepped_in_place(code, s, err, 5000)
        for name in ("mft-estimator", "mft-planner", "mft-wbc"):
            self.assertEqual(s["services"][name]["ticks"], 5000, name)
        self.assertEqual(s["stack"]["discovery"], "server")
        self.assertEqual(s["stack"]["services"]["discovery-server"], "aux")
        self.assertIn("### Server is running ###", (run_dir / "discovery-server.log").read_text())
        self.assertIn("<discoveryProtocol>CLIENT</discoveryProtocol>", (run_dir / "dds-robot.xml").read_text())
        log(f"\ndiscovery server on aux, lockstep 5 s: no fall, 5000 ticks answered by every service, sim wall "
            f"{sim['wall_time_s']:.2f} s, {sim['lockstep_resends']} re-sends")

    def test_6_one_supervisor_per_host(self):
        """As on real machines: each host runs its own supervisor with --host (up on ctrl and aux, run on the
        simulator's host), all with the same stack file."""
        domain = 232
        net, stack = self.network(domain)
        scenario = self.scenario("step-in-place.yaml", 5.0)
        status = {}
        for host in ("aux", "ctrl"):
            status[host] = self.stacks.up(scenario, domain, "--stack", stack, host=host)
        self.assertEqual(sorted(status["aux"]["services"]), ["mft-estimator", "mft-planner"])
        self.assertEqual(sorted(status["ctrl"]["services"]), ["mft-wbc"])
        p, run_dir = self.run_start(scenario, domain, stack, "--host", "robot")
        code, s, err = self.stacks.finish(p)
        sim = self.assert_stepped_in_place(code, s, err, 5000)
        self.assertEqual(list(s["services"]), ["mft-sim"])
        ticks = {}
        for host in ("aux", "ctrl"):
            summaries = self.stacks.down(domain, status[host], names=status[host]["services"], host=host)
            self.assertEqual(sorted(summaries), sorted(status[host]["services"]))
            ticks.update({name: summary["ticks"] for name, summary in summaries.items()})
        self.assertEqual(ticks, {"mft-estimator": 5000, "mft-planner": 5000, "mft-wbc": 5000})
        log(f"\none supervisor per host (up --host aux, up --host ctrl, run --host robot), lockstep 5 s: no fall, "
            f"ticks answered {ticks}, sim wall {sim['wall_time_s']:.2f} s")

    def test_7_secured_three_hosts_lockstep(self):
        """DDS Security (docs/guide/security.md) across the hosts: the per-host profiles keep the secured path working."""
        domain = 231
        net, stack = self.network(domain)
        sec = self.tmp / "sec"
        p = subprocess.run(["bash", str(REPO / "scripts" / "make-security.sh"), str(sec)], capture_output=True,
                           text=True, timeout=120)
        self.assertEqual(p.returncode, 0, p.stderr)
        p, run_dir = self.run_start(self.scenario("step-in-place.yaml", 5.0), domain, stack, "--secure", sec)
        code, s, err = self.stacks.finish(p)
        self.assertEqual(code, 0, err[-3000:])
        self.assertTrue(s["secure"])
        self.assertFalse(s["fell"])
        for name in ("mft-estimator", "mft-planner", "mft-wbc"):
            self.assertEqual(s["services"][name]["ticks"], 5000, name)
        log(f"\nsecured, three hosts, lockstep 5 s: no fall, 5000 ticks answered by every service, sim wall "
            f"{s['services']['mft-sim']['wall_time_s']:.2f} s")

    def test_5_rate_limit_below_the_stack_bandwidth(self):
        domain = 231
        net, stack = self.network(domain)
        st = self.up(self.scenario("stand.yaml"), domain, stack, "--mode", "realtime")
        time.sleep(1.5)
        b0 = {h: net.counters(h) for h in HOSTS}
        time.sleep(2.0)
        b1 = {h: net.counters(h) for h in HOSTS}
        rates = self.link_rates(b0, b1, 2.0)
        need_kbit = rates["robot"]["tx_kBps"] * 8
        limit_kbit = int(need_kbit * 0.5)  # half of what the simulator sends
        sim_log = SimLog(Path(st["run_dir"]) / "mft-sim.log")
        with realtime_priority():
            net.set_rate("robot", f"{limit_kbit}kbit", burst="16kb", latency="5ms")
            time.sleep(1.0)
            limited = net.rate_stats("robot")
            net.clear_rate("robot")
        # Commands flow again once the limit is gone: wait for a whole second of sim time without damping after
        # it (progress lines come every second, so one second after the newest line the limit is certainly off).
        # The test used to sleep 2 s and assert that the last damping episode ended 0.5 s before the stack was
        # stopped. With the other core busy that failed (last episode ended at 6.777 s, asserted 6.666 s): on a
        # loaded machine a single late command is a damping episode of its own, at any time (one run: 11 episodes
        # of 1-30 ms in 18 s, before and after the limit, docs/guide/testing.md), so also in those last 0.5 s. What
        # holds under load is that the chain answers every tick again for a sustained stretch; 30 s only guards
        # against a hang (the test prints when the stretch ended; docs/guide/testing.md).
        cleared_after_s = sim_log.sim_time() + 1.0
        flowing_s = sim_log.wait_for_commands_flowing(cleared_after_s, timeout=30)
        s = self.down(domain, st)
        sim = s["mft-sim"]
        log(f"\nlink rates (kB/s) {rates}; tbf {limit_kbit} kbit/s on robot for 1 s: {limited}; simulator: deadline "
            f"misses {sim['deadline_misses']}, damping ticks {sim['damping_ticks']}, episodes {sim['damping_episodes']}, "
            f"fell {sim['fell']} {sim.get('fall_reason', '')}; limit off before t = {cleared_after_s:.1f} s, a second "
            f"without damping ended at t = {flowing_s:.1f} s")
        self.assertGreater(limited["dropped"], 0, limited)               # the limit bit
        self.assertGreaterEqual(sim["deadline_misses"], 1, sim)          # and the simulator noticed
        # The summary agrees with the log: no damping episode in the second the log showed free of damping.
        for onset, _, duration_ms in sim["damping_episodes"]:
            end = onset + duration_ms * 1e-3 if duration_ms >= 0 else sim["sim_time_s"]
            self.assertFalse(onset < flowing_s and end > flowing_s - 1.0, (flowing_s, sim["damping_episodes"]))


if __name__ == "__main__":
    run_tests()  # nice -10, failures printed as they happen (python/mftstack/simlog.py)
