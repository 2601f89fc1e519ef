#!/usr/bin/env python3
"""The thin floors keep their limits (scripts/check-sizes.py): no function over 80 lines in tools/, services/,
python/ and chain/, no main over 150 lines, tools/ at most 7,000 lines. First checks the scanner on a scratch file
of known lengths."""
import importlib.util
import sys
import tempfile
import unittest
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
spec = importlib.util.spec_from_file_location("check_sizes", ROOT / "scripts" / "check-sizes.py")
check_sizes = importlib.util.module_from_spec(spec)
spec.loader.exec_module(check_sizes)

SAMPLE = r'''#include "a/b.hpp"
namespace x {
struct S {
  int f() const { return 1; }
  S() : a_{1}, b_(2) {
    int y[] = {1, 2};
  }
  int a_, b_;
};
static int g(int a) {
  auto l = [&](int k) {
    return k + a;
  };
  const char* s = "}{";  // }
  if (a > 2'000) { return l(a); }
  return 0;
}
}  // namespace x
int main(int argc, char** argv) {
  return x::g(argc);
}
'''


class Sizes(unittest.TestCase):
    def test_scanner_on_known_lengths(self):
        with tempfile.TemporaryDirectory() as tmp:
            path = Path(tmp) / "main.cpp"
            path.write_text(SAMPLE)
            self.assertEqual(check_sizes.cxx_functions(path), [("f", 4, 1), ("S", 5, 3), ("g", 10, 8), ("main", 19, 3)])
            self.assertTrue(check_sizes.is_main(path, check_sizes.cxx_functions(path)))

    def test_limits_hold(self):
        r = check_sizes.report(check_sizes.scan(ROOT))
        v = r["violations"]
        lines = [f"function {f['length']} lines: {f['file']}:{f['line']} {f['name']}" for f in v["functions"]]
        lines += [f"main {n} lines: {p}" for p, n in v["mains"].items()]
        if v["tools_lines"]:
            lines.append(f"tools/ {v['tools_lines']} lines, over {r['tools_limit']}: move library code to its floor")
        self.assertEqual(lines, [], "over the limits:\n  " + "\n  ".join(lines))

    def test_tools_total_is_limited(self):
        """tools/ is counted over its C++ and Python files only, and one line over the limit is a violation."""
        def files(n):
            return [{"path": "tools/a/x.cpp", "lines": n, "main": False, "functions": []},
                    {"path": "python/p/y.py", "lines": 50000, "main": False, "functions": []}]
        limit = check_sizes.TOOLS_LIMIT
        self.assertIsNone(check_sizes.report(files(limit))["violations"]["tools_lines"])
        over = check_sizes.report(files(limit + 1))
        self.assertEqual((over["tools_code_lines"], over["violations"]["tools_lines"]), (limit + 1, limit + 1))

    def test_a_long_function_and_a_long_main_are_named(self):
        """The check can fail: a scratch tree with an 81-line function in a 151-line main is two violations."""
        with tempfile.TemporaryDirectory() as tmp:
            root = Path(tmp)
            for floor in check_sizes.FLOORS:
                (root / floor).mkdir()
            body = "".join(f"  x += {i};\n" for i in range(79))
            text = "int main() {\n  int x = 0;\n" + body + "}\n" + "// padding\n" * 69
            (root / "tools" / "main.cpp").write_text(text)
            v = check_sizes.report(check_sizes.scan(root))["violations"]
            self.assertEqual([(f["file"], f["name"], f["length"]) for f in v["functions"]],
                             [("tools/main.cpp", "main", 82)])
            self.assertEqual(v["mains"], {"tools/main.cpp": 151})


if __name__ == "__main__":
    sys.exit(unittest.main())
