#!/usr/bin/python3
"""mft-video: the renderer behind `mft-export FILE --video OUT.mp4|.gif` (docs/guide/videos.md).

mft-export reads the rawlog, computes every drawn point with the project's kinematics and writes JSON lines on
this program's stdin: one header (output, ffmpeg, fps, panels with their ground profile), then one line per
video frame. Each frame is drawn with matplotlib (Agg) into a fixed-size RGBA buffer and piped into ffmpeg, so
neither side keeps frames in memory. Progress with an ETA goes to stderr. Not meant to be run by hand.

Fixed colours (the tests find the hips and feet in the video by them): COLORS in mft_video_panel.py, beside this file.
"""
import json
import os
import subprocess
import sys
import tempfile
import time


def fail(message, status=2):
    print(f"mft-export: {message}", file=sys.stderr, flush=True)
    sys.exit(status)


sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))  # mft_video_panel.py, installed beside this file
try:
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    # COLORS and the push arrow's scales are also read by the video test through this module.
    from mft_video_panel import (COLORS, DPI, FIG_H, PANEL_W, PUSH_M_PER_NS, PUSH_SHOWN_S,  # noqa: F401
                                 PX_PER_M, PanelView)
except ImportError:
    if __name__ == "__main__":
        fail("--video needs python3-matplotlib (Debian: apt-get install python3-matplotlib)")
    raise


def ffmpeg_command(header, size):
    w, h = size
    cmd = [header["ffmpeg"], "-hide_banner", "-loglevel", "error", "-y", "-f", "rawvideo", "-pix_fmt", "rgba",
           "-s", f"{w}x{h}", "-framerate", str(header["fps"]), "-i", "-", "-an"]
    if header["format"] == "gif":
        # One palette per frame (stats_mode=single) keeps ffmpeg streaming: no pass over the whole video.
        cmd += ["-vf", "split[a][b];[a]palettegen=stats_mode=single:max_colors=128[p];[b][p]paletteuse=new=1:dither=none",
                "-loop", "0", "-f", "gif"]
    else:
        cmd += ["-c:v", "libx264", "-preset", "veryfast", "-crf", "20", "-pix_fmt", "yuv420p", "-movflags", "+faststart",
                "-f", "mp4"]
    return cmd + [header["output"]]


class Progress:
    def __init__(self, expected):
        self.expected = expected
        self.t0 = time.monotonic()
        self.tty = sys.stderr.isatty()
        self.next_line = 0.1

    def fmt(self, s):
        s = int(round(s))
        return f"{s // 60}:{s % 60:02d}"

    def update(self, done, final=False):
        el = time.monotonic() - self.t0
        rate = done / el if el > 0 else 0.0
        if final:  # the recordings may end before the scenario's length (a fall): say what was done
            if self.tty:
                print("", file=sys.stderr)
            print(f"mft-export: video done: {done} frames in {self.fmt(el)} ({rate:.1f} frames/s)", file=sys.stderr,
                  flush=True)
            return
        if self.expected > 0:
            frac = min(1.0, done / self.expected)
            bar = "#" * int(30 * frac) + "-" * (30 - int(30 * frac))
            eta = (self.expected - done) / rate if rate > 0 and done < self.expected else 0.0
            text = (f"mft-export: video [{bar}] {100 * frac:3.0f} % {done}/{self.expected} frames, "
                    f"{rate:.1f} frames/s, elapsed {self.fmt(el)}, ETA {self.fmt(eta)}")
        else:
            frac = 0.0
            text = f"mft-export: video {done} frames, {rate:.1f} frames/s, elapsed {self.fmt(el)}"
        if self.tty:
            print("\r" + text, end="", file=sys.stderr, flush=True)
        elif (self.expected > 0 and frac >= self.next_line) or (self.expected <= 0 and done % 300 == 0):
            print(text, file=sys.stderr, flush=True)
            while self.next_line <= frac:
                self.next_line += 0.1


def main():
    line = sys.stdin.readline()
    if not line:
        fail("the renderer got no header")
    header = json.loads(line)
    panels_info = header["panels"]
    width = PANEL_W[len(panels_info)] * len(panels_info)
    fig = Figure(figsize=(width / DPI, FIG_H / DPI), dpi=DPI, facecolor="white")
    canvas = FigureCanvasAgg(fig)
    views = [PanelView(fig, i, PANEL_W[len(panels_info)], info, width) for i, info in enumerate(panels_info)]
    canvas.draw()
    size = canvas.get_width_height()
    if size != (width, FIG_H):
        fail(f"internal: the canvas is {size}, not {(width, FIG_H)}")
    log = open(header["frame_log"], "w") if header.get("frame_log") else None
    errf = tempfile.TemporaryFile(mode="w+")
    proc = subprocess.Popen(ffmpeg_command(header, size), stdin=subprocess.PIPE, stderr=errf)
    progress = Progress(header["frames_expected"])
    frames = 0
    try:
        for line in sys.stdin:
            frame = json.loads(line)
            drawn = [v.update(p, header["speed"], header["fps"]) for v, p in zip(views, frame["panels"])]
            canvas.draw()
            proc.stdin.write(canvas.buffer_rgba())
            if log:
                log.write(json.dumps({"i": frame["i"], "size": [width, FIG_H], "px_per_m": PX_PER_M,
                                      "panels": drawn}) + "\n")
            frames += 1
            progress.update(frames)
        proc.stdin.close()
        rc = proc.wait()
    except BrokenPipeError:
        rc = proc.wait()
    except KeyboardInterrupt:
        proc.kill()
        proc.wait()
        sys.exit(130)
    if log:
        log.close()
    if rc != 0:
        errf.seek(0)
        msg = " ".join(errf.read().split())[-300:]
        fail(f"ffmpeg failed (exit status {rc}) writing {header['final_output']}: {msg or 'no message'}")
    progress.update(frames, final=True)


if __name__ == "__main__":
    main()
