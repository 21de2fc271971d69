"""Draw docs/conventions.png: axes, signs, hinges, gravity and tip forces of the reduced model,
and docs/hand_layout.png: the hand's layout seen from below (fingers, azimuths, pads) and an
object at its default placement.

Run: python docs/make_conventions_figure.py [OUT.png]   (default: docs/conventions.png; the
layout figure is written next to it as hand_layout.png)
"""
from __future__ import annotations

import math
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from softhand.reduced.design import HandDesign  # noqa: E402
from softhand.reduced.grasp import PAPER_WEIGHTS  # noqa: E402
from softhand.reduced.kinematics import hinge_angles, joint_positions, link_angles  # noqa: E402
from softhand.studies.io.files import save_figure  # noqa: E402


def _arrow(ax, start, vec, text, color, offset=(0, 0)):
    ax.annotate("", xy=start + vec, xytext=start,
                arrowprops=dict(arrowstyle="-|>", color=color, lw=1.8))
    ax.text(*(start + vec + np.asarray(offset)), text, color=color, fontsize=10)


def draw(design: HandDesign, theta_deg: float = 50.0):
    """The open finger and the finger bent to theta_deg (w = the paper's 180 mm, normalised)."""
    w = np.array(PAPER_WEIGHTS[180.0])
    w = w / w.sum()
    fig, ax = plt.subplots(figsize=(6.4, 7.2))
    open_pts = joint_positions(np.zeros(design.n_s), design)
    ax.plot(open_pts[:, 0], open_pts[:, 1], "--", color="0.6", lw=1.5, label="open (theta = 0)")
    theta = math.radians(theta_deg)
    pts = joint_positions(hinge_angles(theta, w), design)
    ax.plot(pts[:, 0], pts[:, 1], "-", color="k", lw=3, label=f"theta = {theta_deg:g} deg, theta_hat = w theta")
    ax.plot(pts[1:-1, 0], pts[1:-1, 1], "o", ms=7, mfc="w", mec="k", label="hinges (hinge_s_mm)")
    ax.plot(*pts[0], "s", ms=9, color="k")
    ax.text(pts[0, 0] + 6, pts[0, 1] - 3, "finger base (base_offset_mm, 0)", fontsize=9)
    mid = 0.5 * (pts[3] + pts[4])
    ax.annotate("pad side (hinge plate) faces the axis;\nthe tube lies on the outer side",
                xy=mid - np.array([3.0, 0.0]), xytext=(5, 95), fontsize=8,
                arrowprops=dict(arrowstyle="->", color="0.4"))
    ax.axvline(0.0, color="0.3", lw=1, ls="-.")
    ax.text(1.5, 185, "hand axis", fontsize=9, color="0.3")
    origin = np.array([0.0, 0.0])
    _arrow(ax, origin, np.array([30.0, 0.0]), "x (outward)", "C0", (-8, 9))
    _arrow(ax, origin, np.array([0.0, 30.0]), "y (down)", "C0", (2, 8))
    _arrow(ax, np.array([-45.0, 40.0]), np.array([0.0, 30.0]), "g", "C2", (2, 0))
    tip = pts[-1]
    alpha = link_angles(hinge_angles(theta, w), design)[-1]
    n_out = np.array([math.cos(alpha), math.sin(alpha)])
    _arrow(ax, tip, 25 * np.array([1.0, 0.0]), "F_x > 0", "C3", (2, -2))
    _arrow(ax, tip, 25 * np.array([0.0, 1.0]), "F_y = mg/n", "C3", (2, 6))
    _arrow(ax, tip, 25 * n_out, "F_v: along n_out", "C1", (2, 2))
    ax.text(tip[0] - 75, tip[1] - 8, f"tip link: alpha = theta - theta0\n= {math.degrees(alpha):.0f} deg "
            "from the downward vertical,\ninward positive", fontsize=8)
    base_dir = open_pts[1] - open_pts[0]
    ax.text(*(open_pts[0] + 0.5 * base_dir + np.array([4, 0])), "theta0 = 20 deg (outward)", fontsize=8)
    ax.set_xlim(-60, 180)
    ax.set_ylim(215, -20)        # y points down
    ax.set_aspect("equal")
    ax.set_xlabel("x [mm]  (outward from the hand axis)")
    ax.set_ylabel("y [mm]  (down, along gravity)")
    ax.legend(loc="lower left", fontsize=8)
    ax.set_title("Reduced-model kinematics: hand frame and signs")
    return fig


def draw_layout(design: HandDesign):
    """The hand seen from below (x right, z up in the picture) and from the side of finger 0, the
    paper's four fingers open, their pads, and a 180 mm sphere at its default placement."""
    from softhand.reduced import hand_layout
    from softhand.reduced.objects import GraspObject

    fig, (top, side) = plt.subplots(1, 2, figsize=(11, 5))
    q = np.zeros((design.n, design.n_s))
    p = hand_layout.pads(q, design)
    placed = hand_layout.place_object(GraspObject(diameter_mm=180.0), design)
    for i, phi in enumerate(hand_layout.azimuths(design)):
        j = p.joints[i]
        top.plot(j[:, 0], j[:, 2], "-o", color="#4a4f57", ms=3)
        for k in range(design.n_s + 1):
            c, a, w = p.centre[i, k], p.along[i, k], p.across[i, k]
            hl, hw = p.half[k]
            corners = np.array([c - hl * a - hw * w, c + hl * a - hw * w, c + hl * a + hw * w, c - hl * a + hw * w])
            top.fill(corners[:, 0], corners[:, 2], color="#b0b4bb", alpha=0.5)
        top.text(*(1.3 * j[-1, [0, 2]]), f"finger {i}\n{np.degrees(phi):.0f} deg", ha="center", fontsize=8)
    circle = plt.Circle((0, 0), 90.0, color="#e0a060", alpha=0.3)
    top.add_patch(circle)
    _arrow(top, np.zeros(2), np.array([60.0, 0.0]), "x", "black", (2, 4))
    _arrow(top, np.zeros(2), np.array([0.0, 60.0]), "z = x cross y", "black", (-30, 6))
    top.set_aspect("equal")
    top.set_xlim(-175, 175)
    top.set_ylim(-175, 175)
    top.set_title("from above (y, the palm's axis, points into the page)", fontsize=10)
    top.set_xlabel("x [mm]")
    top.set_ylabel("z [mm]")
    for i in (0, 2):
        j = p.joints[i]
        xs = j @ hand_layout.finger_frames(design).e_out[0]
        side.plot(xs, j[:, 1], "-o", color="#4a4f57", ms=3)
    side.add_patch(plt.Circle((0, placed.centre[1]), 90.0, color="#e0a060", alpha=0.3))
    side.axhline(0.0, color="k", lw=2)
    side.text(5, -4, "palm (y = 0)", fontsize=8)
    side.annotate("", xy=(0, placed.centre[1] - 90), xytext=(0, 0), arrowprops=dict(arrowstyle="<->"))
    side.text(4, 0.5 * (placed.centre[1] - 90), "10 mm", fontsize=8)
    side.set_ylim(220, -30)
    side.set_aspect("equal")
    side.set_title("side, fingers 0 and 2 open; 180 mm sphere placed")
    side.set_xlabel("x [mm]")
    side.set_ylabel("y [mm] (down)")
    return fig


def main(argv: list[str]) -> None:
    out = Path(argv[0]) if argv else Path(__file__).with_name("conventions.png")
    save_figure(draw(HandDesign()), out, dpi=110)
    print(out)
    layout = out.with_name("hand_layout.png")
    save_figure(draw_layout(HandDesign()), layout, dpi=110)
    print(layout)


if __name__ == "__main__":
    main(sys.argv[1:])
