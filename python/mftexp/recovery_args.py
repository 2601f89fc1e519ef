"""recovery-map's command line (cli.py hands in its argument types and option groups, so this module imports
nothing of cli.py)."""
import argparse

from . import recovery_map as _map
from .common import bounded


def directions_list(text):
    ds = [x.strip() for x in text.split(",") if x.strip()]
    unknown = sorted(set(ds) - set(_map.DIRECTIONS))
    if unknown or not ds:
        raise argparse.ArgumentTypeError(f"unknown direction {unknown[0]!r} (forward, backward)" if unknown
                                         else "no direction given")
    return ds


# The positive numbers of the grid and the runs: option, default, what it is.
NUMBERS = (("--start", 3.0, "first impulse [N s], the paper's"),
           ("--step", 0.25, "impulse step [N s]"),
           ("--max-impulse", 30.0, "largest impulse [N s]"),
           ("--stop-after", 2.0, "a row ends after this many N s of failures in a row: past its last recovery"),
           ("--push-after", 3.0, "pushes are armed at this time [s] (stepping starts at 1 s), as push-sweep"),
           ("--observe", 5.0, "run length after --push-after [s]; the last 1 s is the recovery window"))


def add_parser(sub, heights_list, controllers_list, positive, add_common, add_distributed):
    r = sub.add_parser("recovery-map", help="recovery probability over impulse, gait phase and direction",
                       description=_map.__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    r.add_argument("--heights", type=heights_list, default=[0.44],
                   help="reference base heights [m] (default 0.44: 2391 runs; cost: docs/results/recovery-map.md)")
    r.add_argument("--controllers", type=controllers_list, default=["sa", "mft"], help="default sa,mft")
    r.add_argument("--directions", type=directions_list, default=list(_map.DIRECTIONS), help="default forward,backward")
    r.add_argument("--phases", type=bounded(int, 1, 64, "--phases must be 1..64: {v}"), metavar="N", default=8, help="push phases per gait cycle (default 8, at least 8)")
    r.add_argument("--allow-few-phases", action="store_true", help="allow --phases below 8 (tests, quick looks)")
    for flag, default, text in NUMBERS:
        r.add_argument(flag, type=positive, default=default, help=f"{text} (default {default:g})")
    r.add_argument("--bootstrap", type=bounded(int, 10, 100000, "--bootstrap must be 10..100000: {v}"), default=2000, help="bootstrap resamplings (default 2000)")
    r.add_argument("--stack", action="store_true", help="run on the multi-process stack (default: in process, "
                                                        "mft-closedloop, the same libraries and recovery verdict)")
    r.add_argument("--out", help="output folder; an existing one is resumed (default runs/recovery-map-<time>)")
    add_common(r)
    add_distributed(r)
    return r
