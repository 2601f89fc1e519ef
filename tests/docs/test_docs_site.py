"""The documentation site and the pages it is made of.

- `mkdocs build --strict` succeeds and writes a page for every entry of the navigation, where every Markdown table
  became a table (a stray `|` in a cell leaves it a paragraph of pipes);
- every Markdown file under docs/ is in the navigation (none left out);
- every relative link in docs/ and README.md names a file that exists, and an anchor into a Markdown page names
  one of its headings;
- no page outside the notebook, and not the README, speaks of issue numbers (they mean nothing to a user).
"""
import argparse
import pathlib
import re
import subprocess
import sys
import tempfile
import unittest

import yaml

ARGS = None
LINK = re.compile(r"(?<!!)\[[^\]]*\]\(([^)\s]+)\)|!\[[^\]]*\]\(([^)\s]+)\)")
ISSUE = re.compile(r"\b[Ii]ssues? \d+|\bissue-\d+")


def nav_pages(nav):
    for entry in nav:
        value = next(iter(entry.values())) if isinstance(entry, dict) else entry
        if isinstance(value, list):
            yield from nav_pages(value)
        else:
            yield value


def slugs(heading):
    """Anchors a heading may be reached by: mkdocs' (runs of '-' and spaces collapsed) and GitHub's."""
    text = re.sub(r"\[([^\]]*)\]\([^)]*\)", r"\1", heading)
    text = re.sub(r"[`*]", "", text).strip().lower()
    kept = re.sub(r"[^\w\s-]", "", text)
    return {re.sub(r"[-\s]+", "-", kept).strip("-"), kept.replace(" ", "-")}


def anchors_of(page):
    found = set()
    in_code = False
    for line in page.read_text(encoding="utf-8").splitlines():
        if line.startswith("```"):
            in_code = not in_code
        elif not in_code and line.startswith("#"):
            found |= slugs(line.lstrip("#"))
    return found


def links_of(page):
    in_code = False
    for number, line in enumerate(page.read_text(encoding="utf-8").splitlines(), 1):
        if line.startswith("```"):
            in_code = not in_code
            continue
        if in_code:
            continue
        for match in LINK.finditer(re.sub(r"`[^`]*`", "", line)):
            yield number, match.group(1) or match.group(2)


class DocsSite(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.root = pathlib.Path(ARGS.source_dir)
        cls.docs = cls.root / "docs"
        cls.config = yaml.safe_load((cls.root / "mkdocs.yml").read_text())

    def test_strict_build_writes_every_page(self):
        with tempfile.TemporaryDirectory() as out:
            run = subprocess.run(["mkdocs", "build", "--strict", "--quiet", "-d", out], cwd=self.root,
                                 capture_output=True, text=True, timeout=100)
            self.assertEqual(run.returncode, 0, run.stderr[-3000:])
            for page in nav_pages(self.config["nav"]):
                stem = page[:-3]
                html = stem[:-5] + "index.html" if stem.endswith("index") else stem + "/index.html"
                self.assertTrue((pathlib.Path(out) / html).is_file(), f"no {html} for {page}")
                self.assertFalse("|---|" in (pathlib.Path(out) / html).read_text(), f"a table of {page} not rendered")

    def test_every_page_is_in_the_navigation(self):
        in_nav = set(nav_pages(self.config["nav"]))
        on_disk = {str(p.relative_to(self.docs)) for p in self.docs.rglob("*.md")}
        self.assertEqual(on_disk - in_nav, set(), "pages left out of mkdocs.yml's nav")
        self.assertEqual(in_nav - on_disk, set(), "nav entries without a page")

    def test_links_and_anchors_resolve(self):
        broken = []
        for page in sorted(self.docs.rglob("*.md")) + [self.root / "README.md"]:
            for number, target in links_of(page):
                if re.match(r"[a-z]+:", target):
                    continue  # http(s), mailto
                path, _, anchor = target.partition("#")
                dest = (page.parent / path).resolve() if path else page
                if not dest.exists():
                    broken.append(f"{page.relative_to(self.root)}:{number}: {target} (no such file)")
                elif anchor and dest.suffix == ".md" and anchor not in anchors_of(dest):
                    broken.append(f"{page.relative_to(self.root)}:{number}: {target} (no such heading)")
        self.assertEqual(broken, [], "\n".join(broken))

    def test_no_issue_numbers_on_the_users_pages(self):
        found = []
        for page in sorted(self.docs.rglob("*.md")) + [self.root / "README.md"]:
            if "notebook" in page.relative_to(self.root).parts:
                continue
            for number, line in enumerate(page.read_text(encoding="utf-8").splitlines(), 1):
                if ISSUE.search(line):
                    found.append(f"{page.relative_to(self.root)}:{number}: {line.strip()[:100]}")
        self.assertEqual(found, [], "\n".join(found))


if __name__ == "__main__":
    parser = argparse.ArgumentParser()
    parser.add_argument("--source-dir", required=True)
    ARGS, rest = parser.parse_known_args()
    unittest.main(argv=[sys.argv[0]] + rest, verbosity=2)
