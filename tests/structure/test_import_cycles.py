#!/usr/bin/env python3
"""No import circle inside our Python packages (mftstack, mftexp): the modules' imports of each other, read with
ast (imports inside functions count too: a deferred import only hides a circle), form no cycle."""
import ast
import sys
import tempfile
import unittest
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
PACKAGES = [ROOT / "python" / "mftstack", ROOT / "python" / "mftexp"]


def module_graph(package_dir):
    """{module: set of modules of the same package it imports}."""
    package = package_dir.name
    modules = {p.stem for p in package_dir.glob("*.py") if p.stem != "__init__"}
    graph = {}
    for name in sorted(modules):
        edges = set()
        tree = ast.parse((package_dir / f"{name}.py").read_text(), filename=name)
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom):
                if node.level == 1 and node.module:
                    target = node.module.split(".")[0]
                elif node.level == 1:  # from . import a, b
                    target = None
                    edges |= {a.name for a in node.names if a.name in modules}
                elif node.module and node.module.split(".")[0] == package and "." in node.module:
                    target = node.module.split(".")[1]
                elif node.module == package:
                    edges |= {a.name for a in node.names if a.name in modules}
                    target = None
                else:
                    target = None
                if target in modules:
                    edges.add(target)
            elif isinstance(node, ast.Import):
                for alias in node.names:
                    parts = alias.name.split(".")
                    if parts[0] == package and len(parts) > 1 and parts[1] in modules:
                        edges.add(parts[1])
        edges.discard(name)
        graph[name] = edges
    return graph


def cycles(graph):
    """Every elementary circle found by a depth-first search, each as a list of modules, smallest first."""
    found = set()

    def visit(start, node, path, on_path):
        for nxt in sorted(graph.get(node, ())):
            if nxt == start:
                found.add(tuple(path))
            elif nxt not in on_path and nxt > start:
                on_path.add(nxt)
                visit(start, nxt, path + [nxt], on_path)
                on_path.discard(nxt)

    for start in sorted(graph):
        visit(start, start, [start], {start})
    return sorted(found)


class ImportCycles(unittest.TestCase):
    def test_no_circle_in_our_packages(self):
        for package in PACKAGES:
            with self.subTest(package=package.name):
                found = cycles(module_graph(package))
                self.assertEqual(found, [], f"{package.name}: import circles " +
                                 "; ".join(" -> ".join(c + (c[0],)) for c in found))

    def test_a_circle_is_found(self):
        # The detector itself, on a scratch package: a -> b -> a (b's import deferred into a function), c alone.
        with tempfile.TemporaryDirectory() as tmp:
            pkg = Path(tmp) / "pkg"
            pkg.mkdir()
            (pkg / "__init__.py").write_text("")
            (pkg / "a.py").write_text("from .b import f\nimport os\n")
            (pkg / "b.py").write_text("def f():\n    from . import a\n    return a\n")
            (pkg / "c.py").write_text("from pkg.a import f\n")
            graph = module_graph(pkg)
            self.assertEqual(graph, {"a": {"b"}, "b": {"a"}, "c": {"a"}})
            self.assertEqual(cycles(graph), [("a", "b")])


if __name__ == "__main__":
    sys.exit(unittest.main())
