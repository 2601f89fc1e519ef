#!/usr/bin/env python3
"""The generated blocks of the docs' pages, rendered from the results files they cite.

A page marks a block with
    <!-- generated: KIND FILE [FILE ...] -->  ...  <!-- end generated -->
(FILE relative to docs/). KIND says which tool's renderer makes the block from its files:
  recovery-map  the table rows and outcome lines `mft-experiment recovery-map` writes to table.md (map.json)
  table-ii      the table and cell lines `mft-experiment push-sweep` writes to table.md (summary.json)
  ablation      the tables and lines `mft-experiment ablation` writes to ablation.md (ablation.json)
  realtime      the rows `scripts/realtime-table.py` makes of measure-stack.py JSON files
  lockstep      the rows `scripts/realtime-table.py --lockstep` makes of measure-stack.py JSON files
  realtime-stages  the table `scripts/realtime-table.py --stages` makes of measure-stack.py JSON files
  realtime-targets the targets table `scripts/realtime-table.py --targets` makes of measure-stack.py JSON files
  speed         the table `scripts/speed-table.py` makes of mft-qp bench, mft-bench and mft-wakeup JSON files
  fault-matrix  every line `scripts/fault-matrix.py` writes to fault-matrix.md (fault-matrix.json)
  terrain-scan  the heights x speeds grid of `mft-experiment terrain-scan`'s terrain_scan.json
  fuzzing       the table `scripts/fuzz-table.py` makes of `scripts/fuzz.sh --json` files
A block is compared on its table rows and list items (a sentence of the page may sit inside it), a fault matrix
on every line (its first line holds the verdict). `--write`
replaces the body of each block that is out of date by what its files give (a current block keeps its text);
the default only checks, as test docs_results_pages does."""
import argparse
import importlib.util
import json
import re
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
BLOCK = re.compile(r"(<!-- generated: ([\w-]+) ([^>]+?) -->\n)(.*?)(<!-- end generated -->)", re.S)


def load_script(name):
    path = ROOT / "scripts" / f"{name}.py"
    spec = importlib.util.spec_from_file_location(name.replace("-", "_"), path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def render(kind, paths):
    """The lines KIND's renderer makes of the files PATHS (absolute)."""
    sys.path.insert(0, str(ROOT / "python"))
    from mftexp import ablation, recovery_report, report, terrain_scan
    one = (lambda: json.loads(paths[0].read_text())) if len(paths) == 1 else None
    if kind in ("recovery-map", "table-ii", "ablation", "fault-matrix", "terrain-scan") and one is None:
        raise ValueError(f"a {kind} block cites one file, not {len(paths)}")
    if kind == "recovery-map":
        return recovery_report.table_lines(recovery_report.load_report(paths[0]))
    if kind == "table-ii":
        return report.table_lines(*report.table_from_summary(one()))
    if kind == "ablation":
        return ablation.markdown_lines(one())
    if kind == "realtime":
        return load_script("realtime-table").table([str(p) for p in paths])
    if kind == "lockstep":
        return load_script("realtime-table").lockstep_table([str(p) for p in paths])
    if kind == "realtime-stages":
        return load_script("realtime-table").stages_table([str(p) for p in paths])
    if kind == "realtime-targets":
        return load_script("realtime-table").targets_table([str(p) for p in paths])
    if kind == "speed":
        return load_script("speed-table").table([str(p) for p in paths])
    if kind == "fault-matrix":
        return load_script("fault-matrix").table_lines(one())
    if kind == "terrain-scan":
        return terrain_scan.grid_lines(one())
    if kind == "fuzzing":
        return load_script("fuzz-table").table([str(p) for p in paths])
    raise ValueError(f"unknown generated block kind {kind}")


def compared(kind, lines):
    """The lines a block of KIND is checked on."""
    if kind == "fault-matrix":
        return [ln for ln in lines if ln.strip()]
    return [ln for ln in lines if ln.startswith(("|", "- "))]


def blocks(docs):
    """(page, kind, files, body) of every generated block under DOCS."""
    return [(page, kind, files.split(), body) for page in sorted(docs.rglob("*.md"))
            for _, kind, files, body, _ in BLOCK.findall(page.read_text())]


def write_page(page, docs):
    def body(m):  # a block that is current keeps its text (headings, sentences); a stale one gets the renderer's
        lines = render(m.group(2), [docs / f for f in m.group(3).split()])
        if compared(m.group(2), m.group(4).splitlines()) == compared(m.group(2), lines):
            return m.group(0)
        return m.group(1) + "\n".join(lines) + "\n" + m.group(5)
    old = page.read_text()
    new = BLOCK.sub(body, old)
    if new != old:
        page.write_text(new)
    return new != old


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--docs", default=str(ROOT / "docs"), help="the docs folder (default: the repository's)")
    ap.add_argument("--write", action="store_true", help="render every out-of-date block again from its files")
    a = ap.parse_args()
    docs = Path(a.docs)
    try:
        if a.write:
            for page in sorted(docs.rglob("*.md")):
                if write_page(page, docs):
                    print(f"rewrote {page.relative_to(docs)}")
            return 0
        stale = [f"{page.relative_to(docs)}: {kind} {' '.join(files)}" for page, kind, files, body in blocks(docs)
                 if compared(kind, body.splitlines()) != compared(kind, render(kind, [docs / f for f in files]))]
    except (OSError, ValueError, KeyError) as e:
        print(f"results-blocks: {e}", file=sys.stderr)
        return 2
    for s in stale:
        print(f"out of date: {s}", file=sys.stderr)
    return 1 if stale else 0


if __name__ == "__main__":
    sys.exit(main())
