"""Shared pieces of the measurement scripts (scripts/*.py): their argument parser and one-line errors."""
import argparse
import sys

from .paths import DEFAULT_BIN


def script_parser(prog, doc):
    """The parser of a script whose docstring is its help (first paragraph: description, the rest: epilog),
    with --bin-dir (default: the built executables)."""
    p = argparse.ArgumentParser(prog=prog, description=doc.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter, epilog=doc.split("\n\n", 1)[1])
    p.add_argument("--bin-dir", default=str(DEFAULT_BIN))
    return p


def run_script(main, name):
    """sys.exit(main()) for a script or tool, with one line instead of a traceback for what a user can cause
    (issue 16): Ctrl-C (exit status 130), an unwritable or full output folder, a file that is not UTF-8 (2)."""
    try:
        sys.exit(main())
    except KeyboardInterrupt:
        print(f"{name}: interrupted", file=sys.stderr)
        sys.exit(130)
    except UnicodeDecodeError as e:
        print(f"{name}: error: a file is not UTF-8 text (byte {e.start}: {e.reason})", file=sys.stderr)
        sys.exit(2)
    except OSError as e:
        print(f"{name}: error: {e.strerror or e}{': ' + str(e.filename) if e.filename else ''}", file=sys.stderr)
        sys.exit(2)
