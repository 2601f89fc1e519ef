#!/usr/bin/env python3
"""The ROS 2 message package ros2/mft says exactly what idl/mft_msgs.idl says (docs/guide/interop.md#ros-2): one .msg
per struct of module mft::msg::dds_ (named <Name>_ as ROS 2's rmw_fastrtps names message <Name> of package
mft), the same fields in the same order with the matching ROS 2 types and array sizes, every IDL constant once
in the message that uses it, ROS 2's naming rules, and a package.xml / CMakeLists.txt that list it all. Parses
both sides itself; needs no ROS 2 installation."""
import re
import sys
import unittest
import xml.etree.ElementTree as ET
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "python"))
from mftstack.paths import REPO  # noqa: E402

IDL = REPO / "idl" / "mft_msgs.idl"
PKG = REPO / "ros2" / "mft"
# IDL type -> ROS 2 .msg type (the wire layout is the same: char and octet are one byte each)
IDL_TO_ROS = {"unsigned long long": "uint64", "double": "float64", "boolean": "bool", "octet": "uint8",
              "short": "int16", "long": "int32", "char": "uint8"}


def strip_comments(text):
    return re.sub(r"//[^\n]*", "", text)


def parse_idl():
    text = strip_comments(IDL.read_text())
    modules = re.findall(r"module (\w+)", text)
    consts = {n: int(v) for n, v in re.findall(r"const octet (\w+) = (\d+);", text)}
    body = text[text.index("module dds_"):]
    structs = {}
    for name, fields in re.findall(r"struct (\w+) \{(.*?)\};", body, re.S):
        out = []
        for decl in [d.strip() for d in fields.split(";") if d.strip()]:
            m = re.fullmatch(r"(unsigned long long|double|boolean|octet|short|long|char)\s+(\w+)(?:\[(\d+)\])?", decl)
            if not m:
                raise AssertionError(f"{IDL}: field '{decl}' of {name} has a type this test does not map")
            out.append((m.group(2), IDL_TO_ROS[m.group(1)], int(m.group(3)) if m.group(3) else None))
        structs[name] = out
    return modules, consts, structs


def parse_msg(path):
    fields, consts = [], {}
    for raw in path.read_text().splitlines():
        line = raw.split("#", 1)[0].strip()
        if not line:
            continue
        c = re.fullmatch(r"(\w+)\s+([A-Z][A-Z0-9_]*)\s*=\s*(\d+)", line)
        if c:
            consts[c.group(2)] = (c.group(1), int(c.group(3)))
            continue
        f = re.fullmatch(r"(\w+)(?:\[(\d+)\])?\s+(\w+)", line)
        if not f:
            raise AssertionError(f"{path}: cannot read '{raw}'")
        fields.append((f.group(3), f.group(1), int(f.group(2)) if f.group(2) else None))
    return fields, consts


class Ros2PackageMatchesTheIdl(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.modules, cls.consts, cls.structs = parse_idl()
        cls.msgs = {p.stem: parse_msg(p) for p in sorted((PKG / "msg").glob("*.msg"))}

    def test_type_names_are_what_ros2_puts_on_the_wire(self):
        self.assertEqual(self.modules[:3], ["mft", "msg", "dds_"])
        self.assertTrue(self.structs)
        for name in self.structs:
            self.assertTrue(name.endswith("_") and not name.endswith("__"), name)

    def test_one_message_per_struct_with_the_same_fields(self):
        self.assertEqual(sorted(n[:-1] for n in self.structs), sorted(self.msgs))
        for name, fields in self.structs.items():
            self.assertEqual(self.msgs[name[:-1]][0], fields, f"ros2/mft/msg/{name[:-1]}.msg differs from the IDL")

    def test_every_constant_once_with_its_value(self):
        seen = {}
        for msg, (_, consts) in self.msgs.items():
            for cname, (ctype, value) in consts.items():
                self.assertNotIn(cname, seen, f"{cname} in {msg} and {seen.get(cname)}")
                seen[cname] = msg
                self.assertEqual(ctype, "uint8", cname)
                self.assertEqual(value, self.consts.get(cname), f"{msg}.{cname}")
        self.assertEqual(sorted(seen), sorted(self.consts))

    def test_names_follow_ros2_rules(self):
        field_rule = re.compile(r"[a-z](?:[a-z0-9_]*[a-z0-9])?")
        for msg, (fields, consts) in self.msgs.items():
            self.assertRegex(msg, r"^[A-Z][A-Za-z0-9]*$")
            for fname, _, _ in fields:
                self.assertTrue(field_rule.fullmatch(fname) and "__" not in fname, f"{msg}.{fname}")
            for cname in consts:
                self.assertRegex(cname, r"^[A-Z](?:[A-Z0-9_]*[A-Z0-9])?$")

    def test_package_files_list_every_message(self):
        root = ET.parse(PKG / "package.xml").getroot()
        self.assertEqual(root.findtext("name"), self.modules[0])
        self.assertEqual(root.findtext("member_of_group"), "rosidl_interface_packages")
        cmake = (PKG / "CMakeLists.txt").read_text()
        self.assertIn(f"project({self.modules[0]})", cmake)
        listed = re.findall(r'"msg/(\w+)\.msg"', cmake)
        self.assertEqual(sorted(listed), sorted(self.msgs))


if __name__ == "__main__":
    unittest.main(verbosity=2)
