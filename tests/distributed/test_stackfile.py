#!/usr/bin/env python3
"""The stack file of mft-supervisor --stack (docs/guide/distributed.md), without network namespaces: strict checks
(every error names the file and the key, nothing starts), the per-host DDS profiles it writes, and a short
lockstep run of config/stacks/local.yaml (every service on 127.0.0.1 through the stack-file path, DDS
domain 230 on loopback; the namespace tests use their own networks)."""
import json
import os
import sys
import unittest
import xml.etree.ElementTree as ET
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "python"))
from mftstack import ddsxml, stackfile  # noqa: E402
from mftstack.processes import ALL_SERVICES  # noqa: E402
from mftstack.simlog import reserve_cpu_share  # noqa: E402
from mftstack.testing import CONFIG, SCENARIOS, StackTestCase  # noqa: E402

STACKS = CONFIG / "stacks"
NS = "{http://www.eprosima.com/XMLSchemas/fastRTPS_Profiles}"
SERVICES = "services: {mft-sim: a, mft-wbc: b, mft-estimator: b, mft-planner: b}\n"


class StackFileTest(StackTestCase):
    tmp_prefix = "mft-stackfile-test-"

    def write(self, text, name="stack.yaml"):
        path = self.tmp / name
        path.write_text(text)
        return path

    def supervisor(self, *args, timeout=120):
        return self.stacks.supervisor(*args, timeout=timeout)

    def test_bad_stack_files_are_refused_before_anything_starts(self):
        hosts = "hosts: {a: {address: 127.0.0.1}, b: {address: 127.0.0.2}}\n"
        cases = [
            ("hosts: {a: {address: 127.0.0.1, adress: 1}}\n" + SERVICES, "unknown key hosts.a.adress"),
            (hosts + SERVICES + "speed: 2\n", "unknown key speed"),
            (hosts + SERVICES.replace("mft-wbc: b", "mft-wbc: c"), "services.mft-wbc: unknown host 'c'"),
            (hosts + SERVICES.replace("mft-wbc: b", "mft-wcb: b"), "unknown key services.mft-wcb"),
            (hosts + "services: {mft-sim: a, mft-wbc: b, mft-estimator: b}\n", "services: no host for mft-planner"),
            ("hosts: {a: {address: 127.0.0.300}, b: {address: 127.0.0.2}}\n" + SERVICES,
             "hosts.a.address: '127.0.0.300' is not an IPv4 address"),
            ("hosts: {a: {address: 127.0.0.1}, b: {address: 127.0.0.1}}\n" + SERVICES,
             "hosts.b.address: 127.0.0.1 is also the address of host a"),
            ("hosts: {a: {address: 127.0.0.1}, a: {address: 127.0.0.2}}\n" + SERVICES, "duplicate key a"),
            (hosts + SERVICES + "discovery: multicast\n", "discovery: unknown value 'multicast'"),
            (hosts + SERVICES + "discovery: server\n", "discovery_server: discovery: server needs"),
            (hosts + SERVICES + "discovery: server\ndiscovery_server: {host: c}\n", "discovery_server.host: unknown host 'c'"),
            (hosts + SERVICES + "discovery: server\ndiscovery_server: {host: a, port: 99999}\n",
             "discovery_server.port: '99999' is not a UDP port"),
            (hosts + SERVICES + "discovery_server: {host: a}\n", "discovery_server: only used with discovery: server"),
            ("hosts: [a, b\n", "not valid YAML"),
            # Checked against the machine: an address that is not local, a namespace that does not exist.
            ("hosts: {a: {address: 127.0.0.1}, b: {address: 192.0.2.77}}\n" + SERVICES,
             "hosts.b.address: 192.0.2.77 is not an address of this machine"),
            ("hosts: {a: {address: 127.0.0.1}, b: {address: 10.77.0.2, netns: mft-no-such-ns-" + str(os.getpid()) + "}}\n"
             + SERVICES, "hosts.b.netns: "),  # does not exist (or: needs root)
        ]
        for text, expect in cases:
            stack = self.write(text)
            code, out, err = self.supervisor("run", SCENARIOS / "stand.yaml", "--domain", 230, "--stack", stack)
            self.assertEqual(code, 2, (text, err))
            self.assertIn(expect, err, text)
            self.assertIn(str(stack.name), err)                      # the file is named
        one_host = "hosts: {a: {address: 127.0.0.1}}\nservices: {mft-sim: a, mft-wbc: a, mft-estimator: a, mft-planner: a}\n"
        refused_runs = [
            (self.tmp / "nope.yaml", [], "does not exist"),
            # A discovery server has no DDS Security identity: refused with --secure
            (self.write(one_host + "discovery: server\ndiscovery_server: {host: a}\n", "server.yaml"),
             ["--secure", self.tmp / "sec"], "discovery: server does not work with --secure"),
            # --record needs mft-record placed
            (self.write(one_host, "one.yaml"), ["--record", self.tmp / "r.rawlog"], "no host for mft-record"),
        ]
        for stack, extra, expect in refused_runs:
            code, out, err = self.supervisor("run", SCENARIOS / "stand.yaml", "--domain", 230, "--stack", stack, *extra)
            self.assertEqual(code, 2, (stack, err))
            self.assertIn(expect, err)
        self.assertFalse((self.tmp / "runs").exists(), "a run folder was created: something started")

    def test_shipped_stack_files_are_valid(self):
        for path in sorted(STACKS.glob("*.yaml")):
            st = stackfile.load_stack(path, ALL_SERVICES)
            self.assertIn(st.discovery, ("initial_peers", "server"), path)

    def test_host_profiles(self):
        stack = self.write("hosts:\n  a: {address: 10.1.2.1, netns: nsa}\n  b: {address: 10.1.2.2}\n" + SERVICES)
        st = stackfile.load_stack(stack, ["mft-sim", "mft-wbc", "mft-estimator", "mft-planner"])
        self.assertEqual(st.launcher("a"), ["ip", "netns", "exec", "nsa"])
        self.assertEqual(st.launcher("b"), [])
        out = ddsxml.write_host_profiles(st, CONFIG, self.tmp)
        root = ET.parse(out["b"]).getroot()
        self.assertEqual([a.text for a in root.iter(NS + "interfaceWhiteList") for a in a.iter(NS + "address")], ["10.1.2.2"])
        peers = root.find(f".//{NS}initialPeersList")
        self.assertEqual([a.text for a in peers.iter(NS + "address")], ["10.1.2.1", "10.1.2.2"])
        self.assertEqual(root.find(f".//{NS}maxInitialPeersRange").text, str(ddsxml.MAX_PARTICIPANTS_PER_HOST))
        # Everything else is the project's profile: the same QoS profiles.
        names = lambda r: sorted(e.get("profile_name") for e in r.iter() if e.get("profile_name"))
        self.assertEqual(names(root), names(ET.parse(CONFIG / "dds_profiles.xml").getroot()))

        stack = self.write("hosts:\n  a: {address: 10.1.2.1}\n  b: {address: 10.1.2.2}\n" + SERVICES +
                           "discovery: server\ndiscovery_server: {host: b, port: 11900}\n")
        st = stackfile.load_stack(stack, ["mft-sim", "mft-wbc", "mft-estimator", "mft-planner"])
        out = ddsxml.write_host_profiles(st, CONFIG, self.tmp)
        root = ET.parse(out["a"]).getroot()
        self.assertIsNone(root.find(f".//{NS}initialPeersList"))
        self.assertEqual(root.find(f".//{NS}discoveryProtocol").text, "CLIENT")
        remote = root.find(f".//{NS}RemoteServer")
        self.assertEqual(remote.get("prefix"), ddsxml.DISCOVERY_SERVER_PREFIX)
        self.assertEqual([e.text for e in remote.iter(NS + "address")] + [e.text for e in remote.iter(NS + "port")],
                         ["10.1.2.2", "11900"])
        server = ET.parse(out[ddsxml.DISCOVERY_SERVER]).getroot()
        self.assertEqual(server.find(f".//{NS}discoveryProtocol").text, "SERVER")
        self.assertEqual([a.text for a in server.iter(NS + "address")], ["10.1.2.2", "10.1.2.2"])  # whitelist, locator

    def test_local_stack_runs_like_the_default(self):
        text = (SCENARIOS / "step-in-place.yaml").read_text().replace("duration_s: 10.0", "duration_s: 2.0")
        scenario = self.write(text, "step-2s.yaml")
        code, out, err = self.supervisor("run", scenario, "--domain", 230, "--stack", STACKS / "local.yaml", "--json",
                                         "--run-dir", self.tmp / "run", timeout=240)
        self.assertEqual(code, 0, err[-3000:])
        s = json.loads(out)
        self.assertFalse(s["fell"])
        self.assertEqual(s["ticks"], 2000)
        for name in ("mft-estimator", "mft-planner", "mft-wbc"):
            self.assertEqual(s["services"][name]["ticks"], 2000, name)
        self.assertEqual(s["stack"]["services"]["mft-sim"], "local")
        log = (self.tmp / "run" / "mft-sim.log").read_text()
        self.assertIn(f"--profiles {self.tmp / 'run' / 'dds-local.xml'}", log)
        self.assertNotIn("ip netns exec", log)


if __name__ == "__main__":
    reserve_cpu_share()  # a share of the CPU whatever else runs (python/mftstack/simlog.py)
    unittest.main(verbosity=2)
