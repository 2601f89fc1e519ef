#!/usr/bin/python3
"""Draws the paper's Fig. 5 from the data file written by mft-space.

usage: mft_space_figure.py DATA.json OUT.png
Left: Cartesian foot space, reachable (light gray) and gridded preferable space (green), with the fitted
joint-space polygon mapped by forward kinematics. Right: actuated joint space with the polygon edges in black.
Exit code 3 when matplotlib is missing, 2 on bad input.
"""
import json
import sys

try:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.colors import ListedColormap
    from matplotlib.collections import PatchCollection
    from matplotlib.patches import Patch, Rectangle
    from matplotlib.lines import Line2D
    import numpy as np
except ImportError as exc:  # the tool reports this and skips the figure
    sys.stderr.write(f"mft_space_figure.py: {exc}\n")
    sys.exit(3)

GRAY = "#d9d9d9"
GREEN = "#3cb44b"
CMAP = ListedColormap(["white", GRAY, GREEN])


def grid_mesh(grid):
    """Cell edges and label matrix of a grid whose nodes sit at lo + i * step."""
    gx, gy = grid["x"], grid["y"]
    labels = np.frombuffer(grid["labels"].encode(), dtype=np.uint8) - ord("0")
    labels = labels.reshape(gy["n"], gx["n"])
    xe = gx["lo"] + (np.arange(gx["n"] + 1) - 0.5) * gx["step"]
    ye = gy["lo"] + (np.arange(gy["n"] + 1) - 0.5) * gy["step"]
    return xe, ye, labels


def draw_grid(ax, grid, edge_width):
    xe, ye, labels = grid_mesh(grid)
    ax.pcolormesh(xe, ye, labels, cmap=CMAP, vmin=0, vmax=2, shading="flat", rasterized=True)
    if edge_width > 0:
        # The gridded look of the paper: outline each green cell (only those; masked meshes still draw edges).
        rows, cols = np.nonzero(labels == 2)
        cells = [Rectangle((xe[c], ye[r]), xe[c + 1] - xe[c], ye[r + 1] - ye[r]) for r, c in zip(rows, cols)]
        ax.add_collection(PatchCollection(cells, facecolor=GREEN, edgecolor="#1e7a2c", linewidth=edge_width))
    return labels


def closed(points):
    pts = np.asarray(points, dtype=float)
    return np.vstack([pts, pts[:1]]) if len(pts) else pts


def main():
    if len(sys.argv) != 3:
        sys.stderr.write(__doc__)
        return 2
    try:
        with open(sys.argv[1], encoding="utf-8") as f:
            d = json.load(f)
    except (OSError, ValueError) as exc:
        sys.stderr.write(f"mft_space_figure.py: cannot read {sys.argv[1]}: {exc}\n")
        return 2

    fig, (axc, axj) = plt.subplots(1, 2, figsize=(11.5, 5.2), gridspec_kw={"width_ratios": [1.45, 1.0]})

    # Left: Cartesian foot space in the leg frame (hip axis at the origin).
    draw_grid(axc, d["cartesian"], 0.3)
    img = np.asarray(d["polygon_cartesian"], dtype=float)
    if len(img):
        img = closed(img)
        axc.plot(img[:, 0], img[:, 1], "-", color="black", linewidth=1.2)
    axc.plot([0], [0], marker="o", color="black", markersize=5)
    axc.annotate("hip axis", (0, 0), textcoords="offset points", xytext=(6, 4), fontsize=8)
    axc.set_aspect("equal")
    axc.set_xlabel("foot x (forward) [m]")
    axc.set_ylabel("foot z (up) [m]")
    axc.set_title("Cartesian space")
    cart = d["cartesian"]
    xe, ye, labels = grid_mesh(cart)
    rows, cols = np.nonzero(labels > 0)
    if len(rows):
        pad = 0.03
        axc.set_xlim(xe[cols.min()] - pad, xe[cols.max() + 1] + pad)
        axc.set_ylim(ye[rows.min()] - pad, ye[rows.max() + 1] + pad)
    axc.grid(True, linewidth=0.3, alpha=0.5)

    # Right: actuated joint space with the polygon.
    draw_grid(axj, d["joint"], 0.0)
    poly = closed(d["polygon"])
    if len(poly):
        axj.plot(poly[:, 0], poly[:, 1], "-", color="black", linewidth=1.6)
    rh, fh = d["rear_hip"], d["fore_hip"]
    axj.set_xlim(rh[0] - 0.08, rh[1] + 0.08)
    axj.set_ylim(fh[0] - 0.08, fh[1] + 0.08)
    axj.set_aspect("equal")
    axj.set_xlabel(r"Rear Hip $q_4$ / $q_8$ [rad]")
    axj.set_ylabel(r"Fore Hip $q_6$ / $q_{10}$ [rad]")
    axj.set_title("Actuated joint space")
    axj.grid(True, linewidth=0.3, alpha=0.5)

    handles = [
        Patch(facecolor=GRAY, edgecolor="none", label="reachable space"),
        Patch(facecolor=GREEN, edgecolor="#1e7a2c", label="gridded MFT preferable space"),
        Line2D([], [], color="black", linewidth=1.6, label="conservative polygon (left: its image by FK)"),
    ]
    fig.legend(handles=handles, loc="lower center", ncol=3, frameon=False, fontsize=9, bbox_to_anchor=(0.5, 0.0))
    lti, raci = d["lti"], d["raci"]
    fig.suptitle(
        f"MFT preferable space of one leg ({d['robot']}): LTI in [{lti[0]:g}, {lti[1]:g}], "
        f"RACI ({d['raci_form']}) in [{raci[0]:g}, {raci[1]:g}] N/$\\sqrt{{kg}}$ at {d['accel_max']:g} m/s$^2$\n"
        f"polygon area {d['area']:.3f} rad$^2$, coverage {100 * d['coverage']:.1f} %, r = {d['r_max']:.4f} rad",
        fontsize=10)
    fig.tight_layout(rect=(0, 0.08, 1, 0.93))
    try:
        fig.savefig(sys.argv[2], dpi=150)
    except OSError as exc:
        sys.stderr.write(f"mft_space_figure.py: cannot write {sys.argv[2]}: {exc}\n")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
