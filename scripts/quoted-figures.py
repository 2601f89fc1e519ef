#!/usr/bin/env python3
"""Figures in the prose of the results pages: each one is in the file it quotes.

A results page states a figure in one of two places only:
  - a generated block (`<!-- generated: KIND FILE ... -->`, checked by scripts/results-blocks.py), or
  - a quoted passage:
        <!-- quotes: FILE [FILE ...] -->  prose ...  <!-- end quotes -->
    (FILE relative to docs/, e.g. results/data/x.json, or ../config/sim.yaml). Every number in the passage's
    prose must occur in one of its files at the precision printed: 12.7 matches 12.66, not 12.6. A file's numbers
    are its JSON values and every number inside its strings and keys (JSON, JSON lines), or every number in its
    text (any other file: a command's captured output, a configuration). A figure may be printed in another unit
    than the file's: x100 (a fraction as a percentage), x1000 or /1000 (s and ms, ms and us), /60 (s as
    minutes). Signs are ignored ("down to -0.5 rad" quotes -0.5). 1,376 and 60 000 are one figure each, and so is 10⁶.
Not figures: numbers in `code` and code blocks, ordered lists' markers, link targets, headings, images and
comments; dates, clock times, commits;
"Table II", "Fig. 6", "eq. 13", "2-vCPU". Any other number outside those two places is reported as unquoted.

The default checks docs/results/*.md and exits 1 listing every figure not found and every unquoted one, as the
test docs_results_pages does; `--page` checks the pages given (the test checks the README's quoted passages with
`--quoted-only`)."""
import argparse
import json
import re
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
QUOTES = re.compile(r"<!-- quotes: ([^>]+?) -->\n(.*?)<!-- end quotes -->", re.S)
GENERATED = re.compile(r"<!-- generated: [^>]+? -->\n.*?<!-- end generated -->", re.S)
FENCE = re.compile(r"^[ \t]*```.*?^[ \t]*```", re.S | re.M)
LIST_MARKER = re.compile(r"^\s*\d+\.\s", re.M)
NUMBER = re.compile(r"(?<![\w.])(?:\d{1,3}(?:[ \u202f\u00a0]\d{3})+(?![\d,])|\d+(?:,\d{3})*)"  # 60 000, 1,376
                    r"(?:\.\d+)?(?:e[+−-]?\d+)?(?![\w])")
SUPERSCRIPT_POWER = re.compile(r"\b10(⁻?[⁰¹²³⁴⁵⁶⁷⁸⁹]+)")
SUPERSCRIPTS = str.maketrans("⁻⁰¹²³⁴⁵⁶⁷⁸⁹", "-0123456789")
NOT_FIGURES = [
    re.compile(r"`[^`]*`"),                                  # code: commands, paths, options
    re.compile(r"\]\([^)]*\)"),                              # link targets
    re.compile(r"<!--.*?-->", re.S),                         # comments
    re.compile(r"\b\d{4}-\d{2}-\d{2}\b"),                    # dates
    re.compile(r"\b\d{1,2}:\d{2}(?::\d{2})?\b"),             # clock times
    re.compile(r"\b[0-9a-f]{7,40}\b"),                       # commits
    re.compile(r"\b(?:Tables?|Figs?\.|eqs?\.|Problem|§)\s*[\dIVX]+(?:[-–][\dIVX]+)?\b"),
    re.compile(r"\b\d+-vCPU\b"),
]
SCALES = (1.0, 100.0, 1000.0, 1e-3, 1.0 / 60.0)


def value(printed):
    """The number PRINTED stands for: 1,376 and 60 000 are thousands-grouped."""
    return float(re.sub(r"[, \u202f\u00a0]", "", printed).replace("−", "-"))


def powers_of_ten(text):
    """10⁶ written as 1e6, so that it reads as one figure."""
    return SUPERSCRIPT_POWER.sub(lambda m: "1e" + m.group(1).translate(SUPERSCRIPTS), text)


def numbers_in_text(text):
    return [value(m.group(0)) for m in NUMBER.finditer(powers_of_ten(text))]


def numbers_in_json(value, out):
    if isinstance(value, bool):
        return
    if isinstance(value, (int, float)):
        out.append(float(value))
    elif isinstance(value, str):
        out.extend(numbers_in_text(value))
    elif isinstance(value, list):
        for v in value:
            numbers_in_json(v, out)
    elif isinstance(value, dict):
        for k, v in value.items():
            out.extend(numbers_in_text(str(k)))
            numbers_in_json(v, out)


def numbers_in_file(path):
    """Every number the file at PATH holds (see the module's text)."""
    text = path.read_text()
    out = []
    if path.suffix == ".json":
        numbers_in_json(json.loads(text), out)
    elif path.suffix == ".jsonl":
        for line in text.splitlines():
            if line.strip():
                numbers_in_json(json.loads(line), out)
    else:
        out = numbers_in_text(text)
    return {abs(v) for v in out}


def prose(text):
    """TEXT without what is not a figure: code, links, headings, images, comments, dates, commits."""
    text = FENCE.sub("", text)
    text = "\n".join(ln for ln in text.splitlines() if not ln.lstrip().startswith(("#", "![")))
    text = LIST_MARKER.sub(" ", text)
    for pattern in NOT_FIGURES:
        text = pattern.sub(" ", text)
    return powers_of_ten(text)


def figures(text):
    """(printed, value, decimals) of every figure in TEXT's prose."""
    out = []
    for m in NUMBER.finditer(prose(text)):
        printed = m.group(0)
        mantissa = printed.split("e")[0]
        decimals = len(mantissa.split(".")[1]) if "." in mantissa else 0
        out.append((printed, value(printed), decimals))
    return out


def found(value, decimals, pool):
    tolerance = 0.5 * 10.0 ** -decimals + 1e-9
    if "e" in f"{value}" or value >= 1e5:  # 1e5: a relative match
        tolerance = max(tolerance, abs(value) * 1e-6)
    return any(abs(v * s - value) <= tolerance for v in pool for s in SCALES)


def check_page(page, docs, unquoted=True):
    """Problems of PAGE: (kind, where, figure) for figures not found in their files and (with UNQUOTED) figures
    outside generated blocks and quoted passages."""
    text = page.read_text()
    problems = []
    for m in QUOTES.finditer(text):
        files = [docs / f for f in m.group(1).split()]
        missing = [f for f in files if not f.is_file()]
        if missing:
            problems.append(("missing file", m.group(1), " ".join(str(f) for f in missing)))
            continue
        pool = {v for f in files for v in numbers_in_file(f)}
        line = text[:m.start()].count("\n") + 1
        for printed, value, decimals in figures(m.group(2)):
            if not found(value, decimals, pool):
                problems.append(("not in its files", f"line {line}: {m.group(1)}", printed))
    if not unquoted:
        return problems
    rest = QUOTES.sub("", GENERATED.sub("", text))
    for ln in prose(rest).splitlines():
        for m in NUMBER.finditer(ln):
            problems.append(("unquoted", ln.strip()[:90], m.group(0)))
    return problems


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--docs", default=str(ROOT / "docs"), help="the docs folder (default: the repository's)")
    ap.add_argument("--page", nargs="+", action="extend", help="check these pages only (paths)")
    ap.add_argument("--quoted-only", action="store_true", help="check the quoted passages only, not the figures "
                    "outside them (a page that is not a results page)")
    ap.add_argument("--json", action="store_true", help="print the problems as JSON")
    a = ap.parse_args()
    docs = Path(a.docs)
    pages = [Path(p) for p in a.page] if a.page else sorted((docs / "results").glob("*.md"))
    try:
        problems = {str(p.name): check_page(p, docs, not a.quoted_only) for p in pages}
    except (OSError, ValueError) as e:
        print(f"quoted-figures: {e}", file=sys.stderr)
        return 2
    if a.json:
        print(json.dumps({p: [list(x) for x in v] for p, v in problems.items()}, indent=1))
    else:
        for page, found_problems in problems.items():
            for kind, where, figure in found_problems:
                print(f"{page}: {kind}: {figure}  ({where})")
        print(f"{sum(map(len, problems.values()))} problems in {len(pages)} pages", file=sys.stderr)
    return 1 if any(problems.values()) else 0


if __name__ == "__main__":
    sys.exit(main())
