#!/usr/bin/env python3
"""No arrow runs back up a floor: every `#include "folder/..."` of a C++ file stays within the folders its floor
may use. common/ uses nothing of ours; model/ common/; sim/, estimator/, planner/, wbc/ model/ and common/ only
(so wbc/ never includes planner/); chain/ those; services/ not tools/. Python, the packages in python/: mftstack
(the supervisor's) imports no other of ours; mftexp (mft-experiment's library) may import mftstack, never the
reverse."""
import ast
import re
import sys
import unittest
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
ALGORITHMS = {"model", "common"}
ALLOWED = {
    "common": {"common"},
    "model": {"model", "common"},
    "sim": {"sim"} | ALGORITHMS,
    "estimator": {"estimator"} | ALGORITHMS,
    "planner": {"planner"} | ALGORITHMS,
    "wbc": {"wbc"} | ALGORITHMS,
    "chain": {"chain", "sim", "estimator", "planner", "wbc"} | ALGORITHMS,
    "services": {"services", "chain", "sim", "estimator", "planner", "wbc", "idl"} | ALGORITHMS,
}
OUR_FOLDERS = set(ALLOWED) | {"tools", "idl", "tests", "examples"}
# python/<package>: the packages of ours each may import (itself included).
PYTHON_ALLOWED = {
    "mftstack": {"mftstack"},
    "mftexp": {"mftexp", "mftstack"},
}
INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"/]+)/', re.M)


def back_arrows(root):
    """(file, included folder) for every include its floor may not use."""
    wrong = []
    for floor, allowed in ALLOWED.items():
        for path in sorted((root / floor).rglob("*")):
            if path.suffix not in (".cpp", ".hpp", ".h") or not path.is_file():
                continue
            for folder in INCLUDE.findall(path.read_text(errors="replace")):
                if folder in OUR_FOLDERS and folder not in allowed:
                    wrong.append((str(path.relative_to(root)), folder))
    return wrong


def python_imports(package_dir):
    names = set()
    for path in package_dir.rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text(), filename=str(path))):
            if isinstance(node, ast.Import):
                names |= {a.name.split(".")[0] for a in node.names}
            elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
                names.add(node.module.split(".")[0])
    return names


def python_back_arrows(python_dir):
    """(package, imported package of ours) for every import its floor may not use; a package in python/ that has
    no floor yet is reported as (package, None)."""
    wrong = []
    for package in sorted(p for p in python_dir.iterdir() if (p / "__init__.py").is_file()):
        allowed = PYTHON_ALLOWED.get(package.name)
        if allowed is None:
            wrong.append((package.name, None))
            continue
        wrong += [(package.name, name) for name in sorted(python_imports(package))
                  if name in PYTHON_ALLOWED and name not in allowed]
    return wrong


class Floors(unittest.TestCase):
    def test_no_include_runs_up_a_floor(self):
        wrong = back_arrows(ROOT)
        self.assertEqual(wrong, [], "includes against the floors:\n" + "\n".join(f"  {f} includes {d}/" for f, d in wrong))

    def test_the_scan_sees_a_back_arrow(self):
        # The scan itself: a wbc/ file that included planner/ would be named.
        import tempfile
        with tempfile.TemporaryDirectory() as tmp:
            (Path(tmp) / "wbc").mkdir()
            (Path(tmp) / "wbc" / "x.hpp").write_text('#include "planner/plan_output.hpp"\n#include "model/a.hpp"\n')
            self.assertEqual(back_arrows(Path(tmp)), [("wbc/x.hpp", "planner")])

    def test_no_python_import_runs_up_a_floor(self):
        self.assertEqual(sorted(PYTHON_ALLOWED), sorted(p.name for p in (ROOT / "python").iterdir()
                                                        if (p / "__init__.py").is_file()))
        self.assertEqual(python_back_arrows(ROOT / "python"), [])
        # mftexp does build on mftstack (paths, registry, supervisor): the arrow the floors allow is used
        self.assertIn("mftstack", python_imports(ROOT / "python" / "mftexp"))

    def test_the_python_scan_sees_a_back_arrow(self):
        # The scan itself: a mftstack module that imported mftexp would be named, and so would a new package.
        import tempfile
        with tempfile.TemporaryDirectory() as tmp:
            for package, text in (("mftstack", "from mftexp.common import REGISTRY\nimport os\n"),
                                  ("mftexp", "from mftstack import paths\n"), ("newpkg", "")):
                (Path(tmp) / package).mkdir()
                (Path(tmp) / package / "__init__.py").write_text(text)
            self.assertEqual(python_back_arrows(Path(tmp)), [("mftstack", "mftexp"), ("newpkg", None)])


if __name__ == "__main__":
    sys.exit(unittest.main())
