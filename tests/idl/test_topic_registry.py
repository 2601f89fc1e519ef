#!/usr/bin/env python3
"""The topic registry (idl/topics.yaml with idl/mft_msgs.idl, docs/reference/architecture.md#the-topic-registry): the
copies kept in the repository (ros2/mft, the docs' topic table) are what the registry makes of them, the
permissions it gives are those the stack was secured with before it existed, and a bad row is refused with
its reason."""
import subprocess
import sys
import tempfile
import unittest
import xml.etree.ElementTree as ET
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "python"))
from mftstack import topics  # noqa: E402
from mftstack.paths import REPO  # noqa: E402

GEN = REPO / "idl" / "gen_topics.py"
# scripts/make-security.sh's hand-written PUB/SUB tables, as they were when the registry replaced them, and since
# then the recorder reading CommandVerdict (recorded from rawlog schema 2 on).
PERMISSIONS_BEFORE = {
    "sim": ("SensorData GroundTruth CommandVerdict", "JointCommand Disturbance RecorderProgress"),
    "estimator": ("RobotState", "SensorData GroundTruth"),
    "planner": ("Reference CommandVerdict ConfigChange", "RobotState OperatorCommand ConfigChange"),
    "wbc": ("JointCommand WbcDiagnostics CommandVerdict ConfigChange", "RobotState Reference ConfigChange"),
    "record": ("RecorderProgress", "SensorData GroundTruth RobotState OperatorCommand Reference JointCommand "
                                   "WbcDiagnostics Disturbance ConfigChange CommandVerdict"),
    "cmd": ("OperatorCommand Disturbance ConfigChange", "CommandVerdict"),
}

# The rawlog ids of the topics recorded when the ids were written into the registry: the order the recordings made
# until then hold (test_rawlog_versions reads it back from tests/data/rawlog). An id never changes; a new recorded
# topic takes the next.
RAWLOG_IDS = {"GroundTruth": 0, "SensorData": 1, "RobotState": 2, "Reference": 3, "JointCommand": 4,
              "WbcDiagnostics": 5, "OperatorCommand": 6, "Disturbance": 7, "ConfigChange": 8, "CommandVerdict": 9}


def gen(*args):
    return subprocess.run([sys.executable, str(GEN), *args], capture_output=True, text=True, timeout=60)


class TopicRegistry(unittest.TestCase):
    def test_kept_copies_are_generated(self):
        r = gen("check")
        self.assertEqual(r.returncode, 0, r.stderr)

    def test_every_message_has_one_row_and_the_chain_keeps_its_slots(self):
        reg = topics.load()
        self.assertEqual([t.type for t in reg.topics], list(reg.structs))
        self.assertEqual(reg.names(chain=True), ["SensorData", "GroundTruth", "RobotState", "Reference",
                                                 "JointCommand", "WbcDiagnostics"])
        self.assertEqual(reg.names(faults=True), ["SensorData", "GroundTruth", "RobotState", "OperatorCommand",
                                                  "Reference", "JointCommand", "WbcDiagnostics", "Disturbance"])

    def test_permissions_are_those_of_before(self):
        reg = topics.load()
        for identity, (pub, sub) in PERMISSIONS_BEFORE.items():
            got_pub, got_sub = reg.permissions(identity)
            self.assertEqual(sorted(got_pub), sorted(pub.split()), identity)
            self.assertEqual(sorted(got_sub), sorted(sub.split()), identity)
        lines = gen("security").stdout.splitlines()
        self.assertIn("cmd pub OperatorCommand Disturbance ConfigChange", lines)

    def test_rawlog_ids_never_change_and_a_new_topic_takes_the_next(self):
        reg = topics.load()
        got = {t.type: t.rawlog_id for t in reg.recorded()}
        self.assertEqual({k: got.get(k) for k in RAWLOG_IDS}, RAWLOG_IDS)
        self.assertEqual(sorted(got.values()), list(range(len(got))))
        self.assertEqual([t.type for t in reg.recorded()][:len(RAWLOG_IDS)], list(RAWLOG_IDS))
        self.assertEqual({t.type for t in reg.topics if not t.record}, {"RecorderProgress"})

    def test_every_qos_class_names_profiles_of_dds_profiles_xml(self):
        root = ET.parse(REPO / "config" / "dds_profiles.xml").getroot()
        names = {e.get("profile_name") for e in root.iter() if e.get("profile_name")}
        for qos, (writers, readers) in topics.QOS_PROFILES.items():
            for profile in writers + readers:
                self.assertIn(profile, names, f"qos {qos}")
        self.assertEqual({t.qos for t in topics.load().topics}, set(topics.QOS_CLASSES))

    def test_bad_rows_are_refused_with_the_reason(self):
        good = (REPO / "idl" / "topics.yaml").read_text()
        cases = {"wire: rt/mft/sensor_data": ("wire: rt/mft/sensors", "is not ROS 2's name"),
                 "writers: [sim]": ("writers: [simulator]", "not a security identity"),
                 "qos: progress": ("qos: fast", "is not one of"),
                 "bad_values: {mode: 99}": ("bad_values: {mood: 99}", "not a field of OperatorCommand"),
                 "    rawlog_id: 9\n": ("", "rawlog_id is given exactly when record is true"),
                 "    rawlog_id: 8\n": ("    rawlog_id: 9\n", "not 0..9 each once"),
                 "record: false\n": ("record: false\n    rawlog_id: 10\n", "rawlog_id is given exactly when"),
                 "qos: event": ("qos: chain", "a recorded stream topic needs the fields tick, stamp_ns")}
        with tempfile.TemporaryDirectory() as d:
            for old, (new, why) in cases.items():
                p = Path(d) / "topics.yaml"
                p.write_text(good.replace(old, new, 1))
                r = gen("list", "--registry", str(p))
                self.assertEqual(r.returncode, 2, new)
                self.assertIn(why, r.stderr)
            p.write_text(good.replace("  - type: ConfigChange", "  - type: ConfigChanges", 1))
            r = gen("list", "--registry", str(p))
            self.assertEqual(r.returncode, 2)
            self.assertIn("no struct ConfigChanges_", r.stderr)


if __name__ == "__main__":
    unittest.main(verbosity=2)
