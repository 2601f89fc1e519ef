"""Numbers on the results pages equal the results files they cite.

A results page marks a generated block with
    <!-- generated: KIND FILE [FILE ...] -->  ...  <!-- end generated -->
(FILE relative to docs/). KIND recovery-map: the block's table rows and outcome lines are what
`mft-experiment recovery-map` writes to table.md for that map.json (its own renderer, run again here);
KIND realtime: the rows `scripts/realtime-table.py` makes of those measure-stack.py JSON files;
KIND table-ii: the table and cell lines `mft-experiment push-sweep` writes to table.md for that summary.json;
KIND ablation: the tables and lines `mft-experiment ablation` writes to ablation.md for that ablation.json.
Also: the README's Table II, and the stack Table II the recovery map prints beside its lift-off column, are the
push sweep's of the table-ii block.
"""
import argparse
import importlib.util
import json
import pathlib
import re
import sys
import unittest

from readme_tables import readme_table_ii

ARGS = None
BLOCK = re.compile(r"<!-- generated: ([\w-]+) ([^>]+?) -->\n(.*?)<!-- end generated -->", re.S)


def load_module(path, name):
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


class ResultsPages(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.root = pathlib.Path(ARGS.source_dir).resolve()
        sys.path.insert(0, str(cls.root / "python"))
        from mftexp import ablation, recovery_report, report
        cls.ablation = ablation
        cls.recovery_report = recovery_report
        cls.sweep_report = report
        cls.realtime_table = load_module(cls.root / "scripts" / "realtime-table.py", "realtime_table")
        cls.blocks = [(page, kind, files.split(), body) for page in sorted((cls.root / "docs").rglob("*.md"))
                      for kind, files, body in BLOCK.findall(page.read_text())]

    def rendered(self, kind, files):
        paths = [self.root / "docs" / f for f in files]
        if kind == "recovery-map":
            self.assertEqual(len(paths), 1)
            lines = self.recovery_report.table_lines(self.recovery_report.load_report(paths[0]))
        elif kind == "table-ii":
            self.assertEqual(len(paths), 1)
            lines = self.sweep_report.table_lines(*self.sweep_report.table_from_summary(json.loads(paths[0].read_text())))
        elif kind == "ablation":
            self.assertEqual(len(paths), 1)
            lines = self.ablation.markdown_lines(json.loads(paths[0].read_text()))
        elif kind == "realtime":
            lines = self.realtime_table.table([str(p) for p in paths])
        else:
            self.fail(f"unknown generated block kind {kind}")
        return [ln for ln in lines if ln.startswith(("|", "- "))]

    def test_every_generated_block_is_what_its_files_give(self):
        kinds = {kind for _, kind, _, _ in self.blocks}
        self.assertTrue({"recovery-map", "realtime", "table-ii", "ablation"} <= kinds, kinds)
        for page, kind, files, body in self.blocks:
            with self.subTest(page=page.name, files=files):
                quoted = [ln for ln in body.splitlines() if ln.startswith(("|", "- "))]
                self.assertEqual(quoted, self.rendered(kind, files))

    def test_readme_and_recovery_maps_quote_the_push_sweep_of_the_results_page(self):
        files = [files for _, kind, files, _ in self.blocks if kind == "table-ii"]
        self.assertEqual(len(files), 1, "one page shows Table II")
        summary = json.loads((self.root / "docs" / files[0][0]).read_text())
        sweep = {round(row["height_m"], 2): {c: row[c]["i_max_Ns"] for c in ("sa", "mft")} for row in summary["table"]}
        self.assertEqual(readme_table_ii(self.root), sweep)
        for c in ("sa", "mft"):
            self.assertEqual(self.recovery_report.STACK_TABLE2[c], {h: v[c] for h, v in sweep.items()})

if __name__ == "__main__":
    parser = argparse.ArgumentParser()
    parser.add_argument("--source-dir", required=True)
    ARGS, rest = parser.parse_known_args()
    unittest.main(argv=[sys.argv[0]] + rest)
