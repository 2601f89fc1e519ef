#!/usr/bin/env python3
"""Function and main lengths in the thin floors (tools/, services/, python/, chain/).

The limits: no function over 80 lines, no program main file over 150 lines, tools/ at most 7,000 lines of C++ and
Python (libraries live in their floors: python/, chain/, model/, common/; tools/ holds thin programs). C++
functions are found by a brace scan (a `{` that opens a function body: after `)` and qualifiers, at namespace level
or inside a class); Python functions by ast. Prints the longest function per folder and every main's length; with --check, exits 1 and
names every violation. --json prints the same figures as one object.
"""
import argparse
import ast
import json
import re
import sys
from pathlib import Path

FLOORS = ("tools", "services", "python", "chain")
FUNCTION_LIMIT = 80
MAIN_LIMIT = 150
TOOLS_LIMIT = 7000
CXX_SUFFIXES = (".cpp", ".hpp", ".h", ".cc")


def strip_cxx(text):
    """The source with comments, string and char literals blanked (newlines kept, so line numbers hold)."""
    out = []
    i, n = 0, len(text)
    while i < n:
        c = text[i]
        two = text[i:i + 2]
        if two == "//":
            while i < n and text[i] != "\n":
                i += 1
        elif two == "/*":
            end = text.find("*/", i + 2)
            end = n if end < 0 else end + 2
            out.append("\n" * text.count("\n", i, end))
            i = end
        elif c == 'R' and text[i:i + 2] == 'R"':
            m = re.match(r'R"([^(\s]*)\(', text[i:])
            if not m:
                out.append(c)
                i += 1
                continue
            close = ")" + m.group(1) + '"'
            end = text.find(close, i)
            end = n if end < 0 else end + len(close)
            out.append('""' + "\n" * text.count("\n", i, end))
            i = end
        elif c == "'" and re.match(r"[0-9A-Fa-f]", text[i - 1:i] or " ") and re.match(r"[0-9A-Fa-f]", text[i + 1:i + 2] or " "):
            out.append(c)  # a digit separator (2'000'000)
            i += 1
        elif c in "\"'":
            j = i + 1
            while j < n and text[j] != c:
                j += 2 if text[j] == "\\" else 1
            out.append(c + c)
            i = j + 1
        else:
            out.append(c)
            i += 1
    return "".join(out)


# A body opens a function when the text before its `{` ends with `)` plus optional qualifiers / a trailing
# return type / a constructor's initializer list, and the head is not a control statement or a lambda.
_HEAD_END = re.compile(r"\)\s*(const|override|final|noexcept(\([^)]*\))?|mutable|&|&&|\s)*(->\s*[\w:<>,\s*&]+)?$")
_CONTROL = re.compile(r"\b(if|for|while|switch|catch|return)\s*\($|^\s*\[|\]\s*\($")
_NAME = re.compile(r"([~\w:]+(?:operator\s*\S+?)?)\s*\($")


def _function_head(head):
    """The function name when `head` (the text before a `{`, from the previous `;`, `{` or `}`) opens a function."""
    h = head.strip()
    if not h:
        return None
    # A constructor's initializer list: `Foo::Foo(args) : a_(x), b_{y}` -- cut at the first top-level ` : `.
    m = re.search(r"\)\s*(?:noexcept\s*)?:(?!:)", h)
    if m:
        h = h[:m.start() + 1]
    if not _HEAD_END.search(h):
        return None
    depth, k = 0, len(h)
    # the `(` matching the last `)` of the head
    close = h.rfind(")")
    for k in range(close, -1, -1):
        if h[k] == ")":
            depth += 1
        elif h[k] == "(":
            depth -= 1
            if depth == 0:
                break
    before = h[:k + 1]
    if _CONTROL.search(before) or "=" in before.split("(")[0] or re.search(r"\]\s*\($", before):
        return None
    name = _NAME.search(before)
    if not name:
        return None
    word = name.group(1)
    if word in ("if", "for", "while", "switch", "catch", "return", "sizeof", "decltype", "alignof"):
        return None
    return word


def cxx_functions(path):
    """(name, first line, line count) of every function body in a C++ file, outermost bodies only."""
    text = strip_cxx(path.read_text(errors="replace"))
    functions = []
    stack = []  # per open brace: (is_function, name, line, depth of function nesting)
    last_stop = 0
    line = 1
    inside_function = 0
    for i, c in enumerate(text):
        if c == "\n":
            line += 1
        elif c == "{":
            # `a_{1}`, `Vec<int>{}`: a brace initializer (a constructor's member list), not a body or a scope.
            initializer = i > 0 and (text[i - 1].isalnum() or text[i - 1] in "_>")
            name = None
            if inside_function == 0 and not initializer:
                name = _function_head(text[last_stop:i].split("#")[-1])
            stack.append((name, line, initializer))
            if name:
                inside_function += 1
            if not initializer:
                last_stop = i + 1
        elif c == "}":
            if stack:
                name, start, initializer = stack.pop()
                if name:
                    inside_function -= 1
                    functions.append((name, start, line - start + 1))
                if not initializer:
                    last_stop = i + 1
        elif c == ";":
            last_stop = i + 1
    return functions


def python_functions(path):
    try:
        tree = ast.parse(path.read_text(errors="replace"), filename=str(path))
    except SyntaxError:
        return []
    found = []
    for node in ast.walk(tree):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            found.append((node.name, node.lineno, node.end_lineno - node.lineno + 1))
    return found


def is_python(path):
    if path.suffix == ".py":
        return True
    if path.suffix or not path.is_file():
        return False
    try:
        with path.open(errors="replace") as f:
            first = f.readline()
    except OSError:
        return False
    return first.startswith("#!") and "python" in first


def is_main(path, functions):
    """A program's main file: the C++ file that defines main(), a Python script run as a program."""
    if path.suffix in CXX_SUFFIXES:
        return any(name == "main" for name, _, _ in functions)
    text = path.read_text(errors="replace")
    return path.name == "__main__.py" or "if __name__ == \"__main__\"" in text or (
        path.suffix == "" and text.startswith("#!"))


def scan(root):
    files = []
    for floor in FLOORS:
        for path in sorted((root / floor).rglob("*")):
            if not path.is_file() or "__pycache__" in path.parts:
                continue
            if path.suffix in CXX_SUFFIXES:
                functions = cxx_functions(path)
            elif is_python(path):
                functions = python_functions(path)
            else:
                continue
            lines = path.read_text(errors="replace").count("\n")
            files.append({"path": str(path.relative_to(root)), "lines": lines,
                          "main": is_main(path, functions),
                          "functions": [{"name": n, "line": l, "length": k} for n, l, k in functions]})
    return files


def folder_of(path):
    parts = Path(path).parts
    return "/".join(parts[:2]) if len(parts) > 2 else parts[0]


def report(files):
    longest = {}
    for f in files:
        for fn in f["functions"]:
            folder = folder_of(f["path"])
            if folder not in longest or fn["length"] > longest[folder]["length"]:
                longest[folder] = dict(fn, file=f["path"])
    mains = {f["path"]: f["lines"] for f in files if f["main"]}
    long_functions = [dict(fn, file=f["path"]) for f in files for fn in f["functions"]
                      if fn["length"] > FUNCTION_LIMIT]
    long_mains = {p: n for p, n in mains.items() if n > MAIN_LIMIT}
    tools_total = sum(f["lines"] for f in files if f["path"].startswith("tools/"))
    return {"function_limit": FUNCTION_LIMIT, "main_limit": MAIN_LIMIT, "tools_limit": TOOLS_LIMIT,
            "tools_code_lines": tools_total, "longest_per_folder": longest, "mains": mains,
            "violations": {"functions": long_functions, "mains": long_mains,
                           "tools_lines": tools_total if tools_total > TOOLS_LIMIT else None}}


def print_text(r):
    print(f"tools/ C++ and Python lines: {r['tools_code_lines']} (limit {r['tools_limit']})")
    print(f"longest function per folder (limit {r['function_limit']}):")
    for folder, fn in sorted(r["longest_per_folder"].items()):
        print(f"  {fn['length']:5d}  {folder:32s} {fn['name']} ({fn['file']}:{fn['line']})")
    print(f"mains (limit {r['main_limit']}):")
    for path, n in sorted(r["mains"].items()):
        print(f"  {n:5d}  {path}")
    v = r["violations"]
    if v["functions"] or v["mains"] or v["tools_lines"]:
        print(f"violations: {len(v['functions'])} functions over {r['function_limit']} lines, "
              f"{len(v['mains'])} mains over {r['main_limit']} lines")
        if v["tools_lines"]:
            print(f"  tools/   {v['tools_lines']} lines, over {r['tools_limit']}")
        for fn in sorted(v["functions"], key=lambda f: -f["length"]):
            print(f"  function {fn['length']:4d}  {fn['file']}:{fn['line']} {fn['name']}")
        for path, n in sorted(v["mains"].items(), key=lambda x: -x[1]):
            print(f"  main     {n:4d}  {path}")
    else:
        print("violations: none")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--root", type=Path, default=Path(__file__).resolve().parent.parent,
                        help="repository root (default: this script's repository)")
    parser.add_argument("--check", action="store_true", help="exit 1 when a limit is broken")
    parser.add_argument("--json", action="store_true", help="print the figures as JSON")
    args = parser.parse_args()
    if not all((args.root / floor).is_dir() for floor in FLOORS):
        print(f"error: {args.root} has not the folders {', '.join(FLOORS)}", file=sys.stderr)
        return 2
    r = report(scan(args.root))
    if args.json:
        print(json.dumps(r, indent=1))
    else:
        print_text(r)
    v = r["violations"]
    return 1 if args.check and (v["functions"] or v["mains"] or v["tools_lines"]) else 0


if __name__ == "__main__":
    sys.exit(main())
