"""The supervisor's errors and its one-line messages on stderr."""
import sys


class SupervisorError(Exception):
    """A problem found before or while running a stack; printed as one clear line, exit status 2."""


class Interrupted(SupervisorError):
    """SIGINT/SIGTERM while the stack was starting: stop the children at once, exit status 130."""


def log(msg, quiet=False):
    if not quiet:
        print(f"mft-supervisor: {msg}", file=sys.stderr, flush=True)


def os_problem(e):
    """One line for an OSError: what failed, on which file."""
    where = f" ({e.filename})" if getattr(e, "filename", None) else ""
    return f"{e.strerror or e}{where}"


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
