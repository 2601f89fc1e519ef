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


def error_text(e):
    """The one line after "error: " for a refusal, a file that is not UTF-8, or an OSError."""
    if isinstance(e, UnicodeDecodeError):
        return f"a file is not UTF-8 text (byte {e.start}: {e.reason})"
    if isinstance(e, OSError):
        return os_problem(e)
    return str(e)
