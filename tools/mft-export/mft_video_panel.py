"""What mft-video draws: the scale, the fixed colours (the tests find the hips and feet in the video by them), the
ground and one panel per recording, redrawn per frame from the points mft-export computed (mft-video.py)."""

import matplotlib

matplotlib.use("Agg")
from matplotlib.collections import LineCollection  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402
from matplotlib.patches import FancyArrowPatch, Polygon  # noqa: E402

PX_PER_M = 800.0          # the scale of every panel: 1 px = 1.25 mm
PANEL_W = {1: 1280, 2: 800}  # one run: 1.6 m of ground in view; two runs side by side: 1.0 m each
FIG_H = 720
TITLE_H = 48              # the strip above the drawing with the panel's title
DPI = 100
FORCE_M_PER_N = 0.001     # contact force arrows: 1 mm per N (the robot's weight, 226 N, is 0.23 m)
PUSH_M_PER_NS = 0.03      # push arrow: 3 cm per N s
PUSH_SHOWN_S = 0.4        # the push arrow stays this long (simulated time), and at least 4 frames

COLORS = {
    "hip": "#0000ff",         # every hip joint (coaxial hips: one disc)
    "foot_right": "#ff00ff",
    "foot_left": "#00ffff",
    "inside": "#1a9e1a",      # a leg inside the MFT preferable space (right leg; left leg lighter)
    "outside": "#d62020",
    "inside_far": "#8fd48f",
    "outside_far": "#f0a0a0",
    "unknown": "#707070",     # no MFT space in the recording
    "unknown_far": "#b0b0b0",
    "torso": "#9a9a9a",
    "edge": "#303030",
    "force": "#ff8c00",
    "push": "#6e3200",
    "ground": "#5a4628",
    "ground_fill": "#e6d7b4",
    "sky": "#ffffff",
}



class Ground:
    """The ground profile: breakpoints of a piecewise-linear height, flat before the first and after the last."""

    def __init__(self, terrain):
        self.x = list(terrain["x"])
        self.z = list(terrain["z"])

    def at(self, x):
        xs, zs = self.x, self.z
        if x <= xs[0]:
            return zs[0]
        if x >= xs[-1]:
            return zs[-1]
        lo, hi = 0, len(xs) - 1
        while hi - lo > 1:
            mid = (lo + hi) // 2
            if xs[mid] <= x:
                lo = mid
            else:
                hi = mid
        if xs[hi] == xs[lo]:
            return zs[hi]
        f = (x - xs[lo]) / (xs[hi] - xs[lo])
        return zs[lo] + f * (zs[hi] - zs[lo])

    def outline(self, x0, x1):
        pts = [(x0, self.at(x0))]
        pts += [(x, z) for x, z in zip(self.x, self.z) if x0 < x < x1]
        pts.append((x1, self.at(x1)))
        return pts


class PanelView:
    """One run's drawing area and its artists, updated in place every frame."""

    def __init__(self, fig, index, width_px, info, fig_w):
        self.info = info
        self.ground = Ground(info["terrain"])
        left = index * width_px
        ax_h = FIG_H - TITLE_H
        self.box_px = (left, TITLE_H, width_px, ax_h)  # left, top, width, height in image pixels
        self.width_m, self.height_m = width_px / PX_PER_M, ax_h / PX_PER_M
        ax = fig.add_axes([left / fig_w, 0.0, width_px / fig_w, ax_h / FIG_H])
        ax.set_axis_off()
        ax.set_facecolor(COLORS["sky"])
        ax.set_autoscale_on(False)
        self.ax = ax
        fig.text((left + width_px / 2) / fig_w, 1.0 - (TITLE_H / 2) / FIG_H,
                 f"{info['title']}  ({info['scenario']}, {info['mode']})", ha="center", va="center", fontsize=15,
                 weight="bold")
        if index > 0:  # a divider between the two runs
            fig.add_artist(Line2D([left / fig_w] * 2, [0, 1], color="#404040", lw=2))
        self.fill = Polygon([[0, 0]], closed=True, facecolor=COLORS["ground_fill"], edgecolor="none", zorder=1)
        ax.add_patch(self.fill)
        (self.ground_line,) = ax.plot([], [], color=COLORS["ground"], lw=2, zorder=2)
        self.ticks = LineCollection([], colors=COLORS["ground"], linewidths=1, zorder=2)
        ax.add_collection(self.ticks)
        self.tick_labels = [ax.text(0, 0, "", fontsize=9, ha="center", va="top", color=COLORS["ground"], zorder=2,
                                    clip_on=True)
                            for _ in range(int(self.width_m / 0.5) + 3)]
        self.legs = []
        for leg in (1, 0):  # the left leg behind the torso, the right leg (nearer the viewer) in front
            z = 3 if leg == 1 else 6
            lw = 5 if leg == 1 else 7
            rear, = ax.plot([], [], lw=lw, solid_capstyle="round", solid_joinstyle="round", zorder=z)
            fore, = ax.plot([], [], lw=lw, solid_capstyle="round", solid_joinstyle="round", zorder=z)
            knees, = ax.plot([], [], "o", ms=5, color=COLORS["edge"], zorder=z + 0.1)
            self.legs.append((leg, rear, fore, knees))
        self.torso = Polygon([[0, 0]], closed=True, facecolor=COLORS["torso"], edgecolor=COLORS["edge"], lw=1.5,
                             zorder=4)
        ax.add_patch(self.torso)
        (self.boom,) = ax.plot([], [], "o", ms=11, markerfacecolor="white", markeredgecolor=COLORS["edge"],
                               markeredgewidth=2, zorder=5)
        self.boom_label = ax.text(0, 0, "boom", fontsize=8, ha="left", va="bottom", color=COLORS["edge"], zorder=5,
                                  clip_on=True)
        self.forces = []
        for _ in range(2):
            a = FancyArrowPatch((0, 0), (0, 0.1), arrowstyle="-|>", mutation_scale=18, lw=2.5, color=COLORS["force"],
                                zorder=7)
            ax.add_patch(a)
            self.forces.append(a)
        self.push = FancyArrowPatch((0, 0), (0.1, 0), arrowstyle="simple,head_width=1.2,head_length=1.0",
                                    mutation_scale=14, color=COLORS["push"], zorder=9)
        ax.add_patch(self.push)
        self.push_label = ax.text(0, 0, "", fontsize=11, ha="center", va="bottom", color=COLORS["push"], weight="bold",
                                  zorder=9, clip_on=True)
        (self.foot_left,) = ax.plot([], [], "o", ms=9, color=COLORS["foot_left"], markeredgewidth=0, zorder=8)
        (self.foot_right,) = ax.plot([], [], "o", ms=9, color=COLORS["foot_right"], markeredgewidth=0, zorder=8.1)
        (self.hips,) = ax.plot([], [], "o", ms=9, color=COLORS["hip"], markeredgewidth=0, zorder=8.2)
        self.clock = ax.text(0.02, 0.975, "", transform=ax.transAxes, fontsize=20, family="monospace", va="top",
                             zorder=10)
        self.status = ax.text(0.02, 0.905, "", transform=ax.transAxes, fontsize=11, family="monospace", va="top",
                              zorder=10, linespacing=1.4)
        key = ("legs: green inside, red outside the MFT preferable space" if info["mft_space"]
               else "legs: grey (no MFT space in the recording)")
        ax.text(0.98, 0.975, key + "\nfeet: magenta right, cyan left; hips blue\norange: ground force (1 mm/N)",
                transform=ax.transAxes, fontsize=9, ha="right", va="top", zorder=10, linespacing=1.4)
        self.ended = ax.text(0.5, 0.55, "", transform=ax.transAxes, fontsize=16, ha="center", color="#a00000",
                             weight="bold", zorder=10)

    def view(self, base_x):
        """The camera: centred on the base, the ground (averaged over +-0.4 m, so a step edge does not jolt it)
        12 cm above the bottom edge."""
        level = sum(self.ground.at(base_x + 0.05 * k) for k in range(-8, 9)) / 17.0
        x0 = base_x - self.width_m / 2
        z0 = level - 0.12
        return x0, x0 + self.width_m, z0, z0 + self.height_m

    def update(self, p, speed, fps):
        x0, x1, z0, z1 = self.view(p["base"][0])
        ax = self.ax
        ax.set_xlim(x0, x1)
        ax.set_ylim(z0, z1)
        outline = self.ground.outline(x0 - 0.05, x1 + 0.05)
        self.ground_line.set_data([q[0] for q in outline], [q[1] for q in outline])
        self.fill.set_xy(outline + [(x1 + 0.05, z0 - 1.0), (x0 - 0.05, z0 - 1.0)])
        segs, k = [], int(x0 / 0.1) - 1
        labels = iter(self.tick_labels)
        for lab in self.tick_labels:
            lab.set_visible(False)  # an empty text still costs a layout per frame
        while k * 0.1 <= x1 + 0.1:
            x = k * 0.1
            g = self.ground.at(x)
            major = k % 5 == 0
            segs.append([(x, g), (x, g - (0.03 if major else 0.015))])
            if major:
                lab = next(labels, None)
                if lab is not None:
                    lab.set_position((x, g - 0.035))
                    lab.set_text(f"{x:.1f} m")
                    lab.set_visible(True)
            k += 1
        self.ticks.set_segments(segs)
        for leg, rear, fore, knees in self.legs:
            L = p["legs"][leg]
            inside = L["inside_mft"]
            name = "unknown" if inside is None else ("inside" if inside else "outside")
            color = COLORS[name if leg == 0 else name + "_far"]
            rear.set_data([L["hip_rear"][0], L["knee_rear"][0], L["foot"][0]],
                          [L["hip_rear"][1], L["knee_rear"][1], L["foot"][1]])
            fore.set_data([L["hip_fore"][0], L["knee_fore"][0], L["foot_fore"][0]],
                          [L["hip_fore"][1], L["knee_fore"][1], L["foot_fore"][1]])
            rear.set_color(color)
            fore.set_color(color)
            knees.set_data([L["knee_rear"][0], L["knee_fore"][0]], [L["knee_rear"][1], L["knee_fore"][1]])
        self.torso.set_xy(p["torso"])
        self.boom.set_data([p["com"][0]], [p["com"][1]])
        self.boom_label.set_position((p["com"][0] + 0.012, p["com"][1] + 0.012))
        for arrow, L in zip(self.forces, p["legs"]):
            fx, fz = L["force"]
            show = (fx * fx + fz * fz) ** 0.5 > 2.0
            arrow.set_visible(show)
            if show:
                arrow.set_positions(tuple(L["foot"]), (L["foot"][0] + fx * FORCE_M_PER_N, L["foot"][1] + fz * FORCE_M_PER_N))
        push = p["push"]
        shown = max(PUSH_SHOWN_S, 4.0 * speed / fps)
        push_drawn = push is not None and 0.0 <= p["t"] - push["t"] < shown
        self.push.set_visible(push_drawn)
        self.push_label.set_visible(push_drawn)
        if push_drawn:
            d = 1.0 if push["impulse_Ns"] >= 0 else -1.0
            length = max(0.04, abs(push["impulse_Ns"]) * PUSH_M_PER_NS)
            cx, cz = p["com"]
            tip = (cx - d * 0.14, cz)
            self.push.set_positions((tip[0] - d * length, cz), tip)
            self.push_label.set_position((tip[0] - d * length / 2, cz + 0.03))
            self.push_label.set_text(f"push {abs(push['impulse_Ns']):g} N s")
        self.clock.set_text(f"t = {p['t']:7.3f} s" + ("" if speed == 1 else f"   x{speed:g}"))
        above = p["base"][1] - p["ground_z"]
        lines = [f"base height {p['base'][1]:.3f} m" + ("" if abs(p["ground_z"]) < 1e-9 else f" ({above:.3f} m above the ground)")]
        lines.append("LTI  right {:.2f}  left {:.2f}".format(p["legs"][0]["lti"], p["legs"][1]["lti"]))
        if push is not None:
            lines.append(f"push {push['impulse_Ns']:g} N s at t = {push['t']:.3f} s")
        self.status.set_text("\n".join(lines))
        self.ended.set_visible(p["ended"])
        if p["ended"]:
            self.ended.set_text(f"recording ends at t = {p['t']:.3f} s")
        self.hips.set_data([L[k][0] for L in p["legs"] for k in ("hip_rear", "hip_fore")],
                           [L[k][1] for L in p["legs"] for k in ("hip_rear", "hip_fore")])
        self.foot_right.set_data([p["legs"][0]["foot"][0]], [p["legs"][0]["foot"][1]])
        self.foot_left.set_data([p["legs"][1]["foot"][0]], [p["legs"][1]["foot"][1]])
        # What was drawn where: the frame as mft-export computed it, with this panel's world-to-pixel mapping
        # (column = left + (x - x0) / (x1 - x0) * width, row = top + (z1 - z) / (z1 - z0) * height).
        return dict(p, view=[x0, x1, z0, z1], box=list(self.box_px), push_drawn=push_drawn)
