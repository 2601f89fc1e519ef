#!/usr/bin/env python3
"""Run videos (`mft-export FILE --video OUT`, docs/guide/videos.md) from a short push run recorded at test time through
the supervisor (real lockstep stack, DDS domains 6-9). The frames are decoded back with ffmpeg and checked
from pixels: the hips and feet are discs of fixed colours centred where mft-export's kinematics put them
(mapped to pixels with the renderer's own world-to-pixel transform, from --frame-log); the right leg has the
colour of its MFT state; the ground line follows the test's own terrain (a board and a slope in view, in a
test copy of the config folder); the push arrow is drawn at the push, which the base velocity jump confirms. Also
the video's length, --speed, --from/--to, --beside and .gif, and every refused input (exit 2, nothing left
behind). Needs MFT_BIN_DIR (set by CTest), ffmpeg and python3-matplotlib/numpy."""
import json
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import unittest
from pathlib import Path

import numpy as np
import yaml

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "python"))
from mftstack.paths import DEFAULT_BIN as BIN, REPO, SUPERVISOR  # noqa: E402
EXPORT = BIN / "mft-export"
DOMAIN = 6 + os.getpid() % 4  # a block no other test uses (rawlog 10-89, experiments 90-99, stacks 100+)

# The renderer's fixed colours (tools/mft-export/mft-video.py COLORS).
sys.path.insert(0, str(REPO / "tools" / "mft-export"))
import importlib.util  # noqa: E402

_spec = importlib.util.spec_from_file_location("mft_video", REPO / "tools" / "mft-export" / "mft-video.py")
mft_video = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(mft_video)


def rgb(hex_colour):
    return np.array([int(hex_colour[i:i + 2], 16) for i in (1, 3, 5)], dtype=np.int16)


HIP, FOOT_R, FOOT_L = (rgb(mft_video.COLORS[k]) for k in ("hip", "foot_right", "foot_left"))
INSIDE, OUTSIDE, PUSH = (rgb(mft_video.COLORS[k]) for k in ("inside", "outside", "push"))
COLOUR_TOL = 70   # per channel: H.264's 4:2:0 chroma and a GIF palette move colours a little
CENTRE_TOL_PX = 2.0  # 2.5 mm; H.264 4:2:0 chroma shifts a small disc's colour by up to ~1.5 px
MARKER_RADIUS_PX = 9 * 100 / 72 / 2  # ms=9 points at 100 dpi

SCENARIO = """schema_version: 1
name: video-test
description: Step in place at 0.42 m, MFT-WBC, a 3 N s push at the first right-foot lift-off after 2 s.
duration_s: 3.5
controller: mft
estimator: kalman
terrain: video-test
initial_base_height_m: 0.42
fall:
  base_height_below_m: 0.25
  pitch_beyond_rad: 0.8
commands:
  - {at_s: 0.0, mode: stand, z_cmd_m: 0.42, v_cmd_mps: 0.0}
  - {at_s: 1.0, mode: step_in_place, z_cmd_m: 0.42, v_cmd_mps: 0.0}
pushes:
  - {impulse_Ns: 3.0, at_s: 2.0, at_liftoff: right}
"""
DURATION = 3.5
IMPULSE = 3.0
# Ground in view but out of the robot's way (it steps in place at x = 0): a 3 cm board from 0.35 to 0.55 m,
# then a 6 degree slope from 0.6 to 1.0 m (config/terrain format; a test-only copy of the config folder).
TERRAIN = """schema_version: 1
start_x_m: 0.35
start_height_m: 0.0
terrain:
  - {type: board, length_m: 0.2, height_m: 0.03}
  - {type: flat, length_m: 0.05}
  - {type: slope, length_m: 0.4, angle_deg: 6.0}
  - {type: flat, length_m: 0.5}
"""
SLOPE_RISE = 0.4 * np.tan(np.radians(6.0))


def ground_height(x):
    """The test terrain's height, written out independently of sim/terrain.cpp."""
    if 0.35 < x < 0.55:
        return 0.03
    if x <= 0.6:
        return 0.0
    return min(x - 0.6, 0.4) * np.tan(np.radians(6.0))


GROUND_BREAKS = (0.35, 0.55, 0.6, 1.0)


def run(cmd, timeout=600, **kw):
    return subprocess.run([str(c) for c in cmd], capture_output=True, text=True, timeout=timeout, **kw)


def report(key, value):
    print(f"\n[video] {key}: {json.dumps(value)}", file=sys.stderr, flush=True)


def probe(path):
    p = run(["ffprobe", "-v", "error", "-show_entries", "stream=width,height,nb_frames:format=duration", "-of", "json",
             path])
    assert p.returncode == 0, p.stderr
    d = json.loads(p.stdout)
    s = d["streams"][0]
    return int(s["width"]), int(s["height"]), float(d["format"]["duration"])


def decoded_frames(path, width, height):
    """The video's frames as HxWx3 uint8 arrays, one at a time (ffmpeg decodes as a stream)."""
    proc = subprocess.Popen(["ffmpeg", "-v", "error", "-i", str(path), "-f", "rawvideo", "-pix_fmt", "rgb24", "-"],
                            stdout=subprocess.PIPE, stderr=subprocess.DEVNULL)
    n = width * height * 3
    try:
        while True:
            buf = proc.stdout.read(n)
            if len(buf) < n:
                break
            yield np.frombuffer(buf, dtype=np.uint8).reshape(height, width, 3)
    finally:
        proc.stdout.close()
        proc.wait(timeout=60)


def to_pixel(panel, point):
    """World (x, z) to image (column, row) with the renderer's mapping; pixel (c, r) covers [c, c+1) x [r, r+1)."""
    x0, x1, z0, z1 = panel["view"]
    left, top, w, h = panel["box"]
    return left + (point[0] - x0) / (x1 - x0) * w, top + (z1 - point[1]) / (z1 - z0) * h


def colour_centre(frame, centre, colour, radius=14):
    """Centroid (column, row) of the pixels of `colour` within `radius` px of `centre`, and their number."""
    c, r = int(round(centre[0])), int(round(centre[1]))
    h, w, _ = frame.shape
    r0, r1, c0, c1 = max(0, r - radius), min(h, r + radius + 1), max(0, c - radius), min(w, c + radius + 1)
    patch = frame[r0:r1, c0:c1].astype(np.int16)
    match = np.all(np.abs(patch - colour) <= COLOUR_TOL, axis=2)
    rows, cols = np.nonzero(match)
    if len(rows) == 0:
        return None, 0
    return (c0 + cols.mean() + 0.5, r0 + rows.mean() + 0.5), len(rows)


def pixel_colour(frame, point):
    """Median colour of the 3x3 pixels around a point (column, row)."""
    c, r = int(point[0]), int(point[1])
    return np.median(frame[r - 1:r + 2, c - 1:c + 2].reshape(-1, 3).astype(np.int16), axis=0)


def read_csv(path):
    with open(path) as f:
        names = f.readline().strip().split(",")
        data = np.loadtxt(f, delimiter=",", ndmin=2)
    return {n: data[:, i] for i, n in enumerate(names)}


class Recorded(unittest.TestCase):
    """One 3.5 s lockstep push run recorded once, shared by every check."""

    @classmethod
    def setUpClass(cls):
        cls.tmp = Path(tempfile.mkdtemp(prefix="mft-video-test-"))
        cls.rawlog = cls.tmp / "push.rawlog"
        config = cls.tmp / "config"
        shutil.copytree(REPO / "config", config)
        (config / "terrain" / "video-test.yaml").write_text(TERRAIN)
        scenario = cls.tmp / "video-test.yaml"
        scenario.write_text(SCENARIO)
        env = dict(os.environ, MFT_RUNS_DIR=str(cls.tmp / "runs"))
        p = run([sys.executable, SUPERVISOR, "run", scenario, "--domain", DOMAIN, "--bin-dir", BIN, "--config-dir",
                 config, "--record", cls.rawlog, "--run-dir", cls.tmp / "run", "--json"], timeout=300, env=env)
        if p.returncode != 0 or not cls.rawlog.is_file():
            shutil.rmtree(cls.tmp, ignore_errors=True)
            raise AssertionError(f"recording the fixture run failed (exit {p.returncode}): {p.stderr[-2000:]}")
        csv = cls.tmp / "csv"
        p = run([EXPORT, cls.rawlog, "--csv", csv, "--labels", "gt_q,gt_qd,contact_force"])
        assert p.returncode == 0, p.stderr
        cls.gt_q = read_csv(csv / "gt_q.csv")
        cls.gt_qd = read_csv(csv / "gt_qd.csv")
        cls.force = read_csv(csv / "contact_force.csv")
        cls.row_of_tick = {int(t): i for i, t in enumerate(cls.gt_q["tick"])}
        poly = yaml.safe_load((REPO / "config" / "mft_space.yaml").read_text())["leg_polygon"]
        cls.leg_A = np.array(poly["A"]).reshape(-1, 2)
        cls.leg_b = np.array(poly["b"])

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def render(self, out, *extra, check=True):
        t0 = time.monotonic()
        p = run([EXPORT, self.rawlog, "--video", out, "--json", *extra])
        wall = time.monotonic() - t0
        if check:
            self.assertEqual(p.returncode, 0, p.stderr[-2000:])
            return json.loads(p.stdout), wall
        return p, wall

    def frame_log(self, path):
        return [json.loads(line) for line in Path(path).read_text().splitlines()]

    def check_robot_pixels(self, frame, panel, tag):
        """Hips and feet: a disc of their colour centred on the kinematics' point; the right thigh in the colour
        of the leg's MFT state."""
        legs = panel["legs"]
        markers = [(legs[0]["hip_rear"], HIP, "hip"), (legs[0]["foot"], FOOT_R, "right foot")]
        right_px = to_pixel(panel, legs[0]["foot"])
        left_px = to_pixel(panel, legs[1]["foot"])
        if np.hypot(right_px[0] - left_px[0], right_px[1] - left_px[1]) > 2 * MARKER_RADIUS_PX + 4:
            markers.append((legs[1]["foot"], FOOT_L, "left foot"))  # not hidden under the right foot
        for point, colour, name in markers:
            expected = to_pixel(panel, point)
            found, n = colour_centre(frame, expected, colour)
            self.assertIsNotNone(found, f"{tag}: no {name} pixels near {expected}")
            self.assertGreater(n, 40, f"{tag}: only {n} {name} pixels near {expected}")
            err = np.hypot(found[0] - expected[0], found[1] - expected[1])
            self.assertLess(err, CENTRE_TOL_PX, f"{tag}: {name} drawn at {found}, kinematics at {expected}")
            self.errors.append(err)
        inside = legs[0]["inside_mft"]
        mid = (0.5 * (legs[0]["hip_rear"][0] + legs[0]["knee_rear"][0]), 0.5 * (legs[0]["hip_rear"][1] + legs[0]["knee_rear"][1]))
        got = pixel_colour(frame, to_pixel(panel, mid))
        want = INSIDE if inside else OUTSIDE
        self.assertTrue(np.all(np.abs(got - want) <= COLOUR_TOL), f"{tag}: right thigh {got}, expected {want} "
                                                                  f"(inside_mft {inside})")

    def check_frame_log_against_recording(self, panel):
        """The drawn points belong to the recorded state at the frame's tick."""
        i = self.row_of_tick[panel["tick"]]
        for leg in panel["legs"]:
            self.assertAlmostEqual(leg["hip_rear"][0], self.gt_q["x"][i], delta=1e-9)
            self.assertAlmostEqual(leg["hip_rear"][1], self.gt_q["z"][i], delta=1e-9)
            self.assertLess(np.hypot(leg["foot"][0] - leg["foot_fore"][0], leg["foot"][1] - leg["foot_fore"][1]), 1e-6)
        for k, (leg, (qr, qf)) in enumerate(zip(panel["legs"], (("q4", "q6"), ("q8", "q10")))):
            v = np.max(self.leg_A @ np.array([self.gt_q[qr][i], self.gt_q[qf][i]]) - self.leg_b)
            if abs(v) > 1e-6:
                self.assertEqual(leg["inside_mft"], bool(v <= 0), f"leg {k} at tick {panel['tick']}: max(Aq-b) = {v}")
            # a foot carrying weight is on the ground (sunk by its contact spring only)
            if self.force["fz_right" if k == 0 else "fz_left"][i] > 50:
                self.assertLess(abs(leg["foot"][1] - ground_height(leg["foot"][0])), 0.003,
                                f"stance foot {k} at {leg['foot']}")

    def check_ground_pixels(self, frame, panel, tag):
        """The ground line at the test terrain's height (board, slope), sky above it, ground fill below."""
        x0, x1, _, _ = panel["view"]
        line, fill, sky = (rgb(mft_video.COLORS[k]) for k in ("ground", "ground_fill", "sky"))
        feet_x = [leg["foot"][0] for leg in panel["legs"]]
        checked = 0
        for x in np.arange(x0 + 0.02, x1 - 0.02, 0.013):
            if min(abs(x - b) for b in GROUND_BREAKS) < 0.01 or abs(x - round(x, 1)) < 0.008 or \
                    min(abs(x - f) for f in feet_x) < 0.05:
                continue  # an edge, a tick mark, or a foot standing on the line
            col, row = to_pixel(panel, (x, ground_height(x)))
            c = int(col)
            rows = [r for r in range(int(row) - 16, int(row) + 17)
                    if np.all(np.abs(frame[r, c].astype(np.int16) - line) <= COLOUR_TOL)]
            self.assertTrue(rows, f"{tag}: no ground line near row {row:.1f} at x = {x:.3f} m")
            self.assertLess(abs(np.mean(rows) + 0.5 - row), CENTRE_TOL_PX, f"{tag}: ground line at x = {x:.3f} m "
                                                                           f"drawn at row {np.mean(rows):.1f}, expected {row:.1f}")
            self.assertTrue(np.all(np.abs(pixel_colour(frame, (col, row - 8)) - sky) <= COLOUR_TOL), f"{tag}: x = {x:.3f}")
            self.assertTrue(np.all(np.abs(pixel_colour(frame, (col, row + 8)) - fill) <= COLOUR_TOL), f"{tag}: x = {x:.3f}")
            checked += 1
        self.assertGreater(checked, 60, f"{tag}: too few ground columns checked")
        self.ground_columns += checked

    def test_1_frames_show_hips_and_feet_where_the_kinematics_puts_them(self):
        out, log = self.tmp / "window.mp4", self.tmp / "window.jsonl"
        res, wall = self.render(out, "--from", "1.5", "--to", "3.5", "--frame-log", log)
        frames = self.frame_log(log)
        self.assertEqual(res["frames"], 60)
        self.assertEqual(len(frames), 60)
        w, h, duration = probe(out)
        self.assertEqual((w, h), tuple(frames[0]["size"]))
        self.assertAlmostEqual(duration, 2.0, delta=1.0 / 30)
        self.errors = []
        self.ground_columns = 0
        decoded = 0
        push_frames = []
        for entry, frame in zip(frames, decoded_frames(out, w, h)):
            panel = entry["panels"][0]
            self.assertAlmostEqual(panel["t"], 1.5 + entry["i"] / 30.0, delta=0.0011)
            self.check_frame_log_against_recording(panel)
            self.check_robot_pixels(frame, panel, f"frame {entry['i']} (t = {panel['t']:.3f} s)")
            if entry["i"] % 6 == 0:
                self.check_ground_pixels(frame, panel, f"frame {entry['i']}")
            if panel["push_drawn"]:
                push_frames.append(entry["i"])
                tip = (panel["com"][0] - 0.14 - 0.5 * IMPULSE * mft_video.PUSH_M_PER_NS, panel["com"][1])
                found, n = colour_centre(frame, to_pixel(panel, tip), PUSH, radius=6)
                self.assertGreater(n, 20, f"frame {entry['i']}: no push arrow at {to_pixel(panel, tip)}")
            decoded += 1
        self.assertEqual(decoded, 60)
        report("pixel_check", {"frames": decoded, "markers": len(self.errors),
                               "max_centre_error_px": round(max(self.errors), 3),
                               "mean_centre_error_px": round(float(np.mean(self.errors)), 3),
                               "ground_columns_checked": self.ground_columns})
        # The push: drawn from the foot-switch lift-off on; the base velocity jumps there.
        push = next(e["panels"][0]["push"] for e in frames if e["panels"][0]["push"])
        self.assertEqual(push["impulse_Ns"], IMPULSE)
        dxd = np.diff(self.gt_qd["xd"])
        k = int(np.argmax(np.abs(dxd)))
        jump_t = self.gt_qd["time_s"][k + 1]
        mass = 16.4 + 2 * 2 * (0.5 + 1.15)
        report("push", {"drawn_at_s": push["t"], "largest_velocity_jump_at_s": jump_t, "jump_mps": round(dxd[k], 4),
                        "impulse_over_mass_mps": round(IMPULSE / mass, 4), "frames_with_arrow": push_frames})
        self.assertLessEqual(abs(jump_t - push["t"]), 0.0021, "the push is drawn where the base velocity jumps")
        self.assertGreater(dxd[k], 0.5 * IMPULSE / mass)
        shown = [i for i in range(60) if 0 <= 1.5 + i / 30 - push["t"] < mft_video.PUSH_SHOWN_S - 0.002]
        self.assertTrue(set(shown) <= set(push_frames) and len(push_frames) >= len(shown) > 0, (shown, push_frames))
        report("render_window", {"frames": res["frames"], "wall_s": round(wall, 2), "frames_per_s": res["frames_per_s"],
                                 "bytes": res["bytes"]})

    def test_2_real_time_by_default_and_speed(self):
        out = self.tmp / "whole.mp4"
        res, wall = self.render(out, "--fps", "20")
        w, h, duration = probe(out)
        last_t = self.gt_q["time_s"][-1]
        report("whole_run_mp4", {"run_s": round(last_t + 0.001, 3), "video_s": duration, "frames": res["frames"],
                                 "bytes": res["bytes"], "wall_s": round(wall, 2), "frames_per_s": res["frames_per_s"]})
        self.assertEqual(res["frames"], int(np.ceil((last_t + 0.001) * 20 - 1e-6)))
        self.assertAlmostEqual(duration, last_t + 0.001, delta=1.0 / 20 + 1e-3)
        res, _ = self.render(self.tmp / "fast.mp4", "--speed", "4", "--fps", "10")
        self.assertEqual(res["frames"], int(np.ceil((last_t + 0.001) / 0.4 - 1e-6)))
        self.assertAlmostEqual(probe(self.tmp / "fast.mp4")[2], (last_t + 0.001) / 4, delta=0.1 + 1e-3)

    def test_3_side_by_side_gif(self):
        out, log = self.tmp / "pair.gif", self.tmp / "pair.jsonl"
        res, wall = self.render(out, "--beside", self.rawlog, "--from", "2.0", "--to", "2.5", "--fps", "10",
                                "--frame-log", log)
        frames = self.frame_log(log)
        w, h, duration = probe(out)
        self.assertEqual(res["frames"], 5)
        self.assertEqual(w, frames[0]["size"][0])
        self.errors = []
        n = 0
        for entry, frame in zip(frames, decoded_frames(out, w, h)):
            self.assertEqual(len(entry["panels"]), 2)
            left, right = entry["panels"]
            self.assertEqual(right["box"][0], left["box"][2])  # the second run in the right half
            for side, panel in (("left", left), ("right", right)):
                self.check_robot_pixels(frame, panel, f"gif frame {entry['i']} {side}")
            n += 1
        self.assertEqual(n, 5)
        report("gif_side_by_side", {"frames": n, "bytes": res["bytes"], "wall_s": round(wall, 2),
                                    "max_centre_error_px": round(max(self.errors), 3)})

    def test_4_refused_inputs(self):
        existing = self.tmp / "exists.mp4"
        existing.write_text("keep me")
        cases = [
            ([self.rawlog, "--video", existing], "already exists", None),
            ([self.rawlog, "--video", self.tmp / "no-such-dir" / "v.mp4"], "cannot write", None),
            ([self.rawlog, "--video", self.tmp / "v.avi"], "must end in .mp4 or .gif", None),
            ([self.rawlog, "--video", self.tmp / "v.mp4", "--from", "2", "--to", "1"], "--to must be after --from", None),
            ([self.rawlog, "--video", self.tmp / "v.mp4", "--from", "50"], "not before the end", None),
            ([self.rawlog, "--video", self.tmp / "v.mp4", "--from", "-1"], "--from", None),
            ([self.rawlog, "--video", self.tmp / "v.mp4", "--speed", "0"], "--speed", None),
            ([self.rawlog, "--video", self.tmp / "v.mp4", "--fps", "0"], "--fps", None),
            ([self.rawlog, "--csv", self.tmp / "c", "--from", "1"], "only applies to --video", None),
            ([SCENARIO_FILE_PLACEHOLDER, "--video", self.tmp / "v.mp4"], "refused", None),
            ([self.rawlog, "--video", self.tmp / "v.mp4"], "needs ffmpeg", {"PATH": "/nonexistent"}),
        ]
        text_file = self.tmp / "not-a-rawlog.txt"
        text_file.write_text("hello\n")
        for args, message, env in cases:
            args = [text_file if a is SCENARIO_FILE_PLACEHOLDER else a for a in args]
            p = run([EXPORT, *args], env=dict(os.environ, **env) if env else None, timeout=60)
            self.assertEqual(p.returncode, 2, (args, p.stderr))
            first = p.stderr.splitlines()[0] if p.stderr else ""
            self.assertIn(message, first, (args, p.stderr))
            self.assertTrue(first.startswith("mft-export"), first)
            self.assertNotIn("Traceback", p.stderr)
        self.assertEqual(existing.read_text(), "keep me")
        self.assertFalse((self.tmp / "v.mp4").exists())
        self.assertEqual([f.name for f in self.tmp.iterdir() if ".partial" in f.name], [])
        # --overwrite replaces it
        res, _ = self.render(existing, "--overwrite", "--from", "3.0", "--to", "3.2")
        self.assertEqual(res["frames"], 6)
        self.assertEqual(probe(existing)[:2], (1280, 720))

    def test_5_interrupt_leaves_nothing(self):
        out = self.tmp / "interrupted.mp4"
        p = subprocess.Popen([str(EXPORT), str(self.rawlog), "--video", str(out), "--fps", "60"], stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, text=True)
        # wait for the first progress line (the renderer is running), bounded
        deadline = time.monotonic() + 120
        line = ""
        while time.monotonic() < deadline and "frames" not in line:
            line = p.stderr.readline()
            if not line and p.poll() is not None:
                break
        self.assertIn("frames", line, "no progress line from the renderer within 120 s")
        p.send_signal(signal.SIGINT)
        _, err = p.communicate(timeout=120)
        self.assertEqual(p.returncode, 130, err)
        self.assertIn("interrupted", err)
        self.assertFalse(out.exists())
        self.assertEqual([f.name for f in self.tmp.iterdir() if ".partial" in f.name], [])

    @unittest.skipUnless(os.geteuid() == 0 and shutil.which("unshare"), "needs root and unshare for a small tmpfs")
    def test_6_full_disk_is_an_error_and_leaves_nothing(self):
        # ffmpeg exited 0 on a full disk and left an MP4 without its index (moov box); mft-export said
        # "100 frames ... 10.00 s of video", exit 0. A 64 kB tmpfs of its own (unshare -m) is the full disk.
        out = self.tmp / "full"
        out.mkdir()
        script = (f"mount -t tmpfs -o size=64k tmpfs {out} && {EXPORT} {self.rawlog} --video {out / 'v.mp4'} "
                  f"--from 2.0 --to 3.0; echo rc=$?; ls -A {out}")
        p = subprocess.run(["unshare", "-m", "--propagation", "private", "sh", "-c", script], capture_output=True,
                           text=True, timeout=300)
        if "rc=" not in p.stdout:
            self.skipTest(f"cannot mount a tmpfs here: {p.stderr.strip()}")
        self.assertEqual(p.stdout.split(), ["rc=2"], p.stderr)  # exit 2 and nothing left in the folder
        self.assertRegex(p.stderr, r"mft-export: (the encoder left .*v\.mp4 incomplete \(.*; disk full\?\)|"
                                   r"ffmpeg failed).*no video written|No space left on device")
        self.assertNotIn("Traceback", p.stderr)


SCENARIO_FILE_PLACEHOLDER = object()

if __name__ == "__main__":
    for tool in ("ffmpeg", "ffprobe"):
        if not shutil.which(tool):
            print(f"test_video: {tool} is not installed (Debian: apt-get install ffmpeg)", file=sys.stderr)
            sys.exit(1)
    unittest.main(verbosity=2)
