"""Numbers on the results pages equal the results files they cite.

Every generated block (`<!-- generated: KIND FILE ... -->`) is what its files give, by the renderer
`scripts/results-blocks.py` names for KIND (the tool that measured them). Also: the README's Table II, and the stack
Table II the recovery map prints beside its lift-off column, are the push sweep's of the table-ii block. And every
figure in a results page's prose, and in the README's quoted passages, is in the file its passage quotes
(`scripts/quoted-figures.py`).
"""
import argparse
import importlib.util
import json
import pathlib
import sys
import tempfile
import unittest

from readme_tables import readme_table_ii

ARGS = None


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
        from mftexp import recovery_report
        cls.recovery_report = recovery_report
        cls.results = load_module(cls.root / "scripts" / "results-blocks.py", "results_blocks")
        cls.blocks = cls.results.blocks(cls.root / "docs")
        cls.quoted = load_module(cls.root / "scripts" / "quoted-figures.py", "quoted_figures")

    def test_every_generated_block_is_what_its_files_give(self):
        kinds = {kind for _, kind, _, _ in self.blocks}
        self.assertTrue({"recovery-map", "realtime", "table-ii", "ablation", "lockstep", "speed", "fault-matrix",
                         "terrain-scan", "fuzzing", "realtime-targets"} <= kinds,
                        kinds)
        for page, kind, files, body in self.blocks:
            with self.subTest(page=page.name, files=files):
                rendered = self.results.render(kind, [self.root / "docs" / f for f in files])
                self.assertEqual(self.results.compared(kind, body.splitlines()), self.results.compared(kind, rendered))

    def test_readme_and_recovery_maps_quote_the_push_sweep_of_the_results_page(self):
        files = [files for _, kind, files, _ in self.blocks if kind == "table-ii"]
        self.assertEqual(len(files), 1, "one page shows Table II")
        summary = json.loads((self.root / "docs" / files[0][0]).read_text())
        sweep = {round(row["height_m"], 2): {c: row[c]["i_max_Ns"] for c in ("sa", "mft")} for row in summary["table"]}
        self.assertEqual(readme_table_ii(self.root), sweep)
        for c in ("sa", "mft"):
            self.assertEqual(self.recovery_report.STACK_TABLE2[c], {h: v[c] for h, v in sweep.items()})

    def test_every_figure_of_a_results_page_is_in_the_file_it_quotes(self):
        pages = sorted((self.root / "docs" / "results").glob("*.md"))
        self.assertGreaterEqual(len(pages), 8)
        for page in pages:
            with self.subTest(page=page.name):
                self.assertEqual(self.quoted.check_page(page, self.root / "docs"), [])

    def test_the_readmes_quoted_figures_are_in_their_files(self):
        readme = self.root / "README.md"
        self.assertIn("<!-- quotes: results/data/push-sweep", readme.read_text())
        self.assertEqual(self.quoted.check_page(readme, self.root / "docs", unquoted=False), [])

    def test_the_figure_check_finds_a_misquote_and_an_unquoted_figure(self):
        with tempfile.TemporaryDirectory() as tmp:
            docs = pathlib.Path(tmp)
            (docs / "data.json").write_text(json.dumps({"i_max_Ns": 12.66, "why": "fell at 6.473 s", "frac": 0.252,
                                                        "ticks": 60000}))
            page = docs / "page.md"
            page.write_text("## Fig. 6 on 2026-11-28 at bcfa0af\n<!-- quotes: data.json -->\n"
                            "Recovers up to 12.7 N s (`--start 12.0`), falls at 6.47 s, +25.2 %, 60 000 ticks; "
                            "12.6 is wrong, and so is tick + 10⁶.\n<!-- end quotes -->\nLoose 3.3 here.\n")
            problems = self.quoted.check_page(page, docs)
        self.assertEqual([(kind, figure) for kind, _, figure in problems],
                         [("not in its files", "12.6"), ("not in its files", "1e6"), ("unquoted", "3.3")])

if __name__ == "__main__":
    parser = argparse.ArgumentParser()
    parser.add_argument("--source-dir", required=True)
    ARGS, rest = parser.parse_known_args()
    unittest.main(argv=[sys.argv[0]] + rest)
