"""The MFT preferable space in the experiments' figures: the leg polygon of config/mft_space.yaml, and the paper's
(10) per recorded sample, computed by `mft-space violation` (the model's one function, the one the WBC's
diagnostics and mft-closedloop use): max(A_leg [q_rear, q_fore] - b_leg) [rad] per leg, <= 0 inside."""
import subprocess
from pathlib import Path

from .common import ExperimentError, load_yaml, read_csv


def leg_polygon(config_dir):
    """The leg hexagon's vertices [(q_rear, q_fore)] for drawing."""
    d = load_yaml(Path(config_dir) / "mft_space.yaml")
    try:
        verts = d["leg_polygon"]["vertices"]
    except (KeyError, TypeError):
        raise ExperimentError(f"{config_dir}/mft_space.yaml has no leg_polygon vertices")
    return [(verts[2 * i], verts[2 * i + 1]) for i in range(len(verts) // 2)]


def mft_violations(bin_dir, config_dir, gt_q_csv):
    """{tick, time_s, mft_violation_right, mft_violation_left, mft_violation: lists}, one row per row of gt_q_csv
    (mft-export's gt_q.csv), written beside it as mft_violation.csv."""
    out = Path(gt_q_csv).with_name("mft_violation.csv")
    argv = [str(Path(bin_dir) / "mft-space"), "violation", "--csv", str(gt_q_csv), "--output", str(out),
            "--robot", str(Path(config_dir) / "robot.yaml"), "--polytope", str(Path(config_dir) / "mft_space.yaml")]
    try:
        p = subprocess.run(argv, capture_output=True, text=True, timeout=300)
    except (OSError, subprocess.TimeoutExpired) as e:
        raise ExperimentError(f"mft-space violation on {gt_q_csv}: {e}")
    if p.returncode != 0:
        raise ExperimentError(f"mft-space violation failed on {gt_q_csv}: {(p.stderr or p.stdout).strip()[-300:]}")
    return read_csv(out)
