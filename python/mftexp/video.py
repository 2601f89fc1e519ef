"""Run videos of an experiment's recorded runs, side by side on one clock (`mft-export A --video OUT --beside B`,
docs/guide/videos.md): `case` shows the same push with both controllers (the paper's Fig. 6 in motion), `terrain` the
course. --no-video skips them."""
import json
import subprocess
from pathlib import Path

from .common import ExperimentError, bounded, log


video_speed = bounded(float, 0.01, 1000, "must be in [0.01, 1000]: {t}")


def add_video_options(p):
    p.add_argument("--no-video", dest="video", action="store_false",
                   help="do not write the side-by-side run video (rendering takes about as long as the runs)")
    p.add_argument("--video-speed", type=video_speed, default=1.0, metavar="S",
                   help="simulated seconds per video second (default 1: real time)")


def write_video(args, rawlogs, out):
    """Renders the first two rawlogs side by side into `out` (replaced if there); returns mft-export's summary."""
    cmd = [str(Path(args.bin_dir) / "mft-export"), str(rawlogs[0]), "--video", str(out), "--overwrite", "--json",
           "--speed", repr(args.video_speed)]
    if len(rawlogs) > 1:
        cmd += ["--beside", str(rawlogs[1])]
    if not args.quiet:
        log(f"video: rendering {Path(out).name} from {', '.join(Path(r).name for r in rawlogs[:2])}")
    # progress (with its ETA) goes straight to our stderr unless --quiet
    p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE if args.quiet else None, text=True,
                       timeout=3600)
    if p.returncode != 0:
        raise ExperimentError(f"the video {out} failed (mft-export exit status {p.returncode})"
                              + (f": {p.stderr.strip().splitlines()[-1]}" if args.quiet and p.stderr.strip() else ""))
    return json.loads(p.stdout)
