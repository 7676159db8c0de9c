#!/usr/bin/env python3
"""Renders one frame of a run to a PNG: the fluid particles coloured by their speed (or another
field), the solids' particles in grey, the domain walls left out.

Usage: render_frame.py FRAME.vtu OUT.png [--field speed|pressure|density] [--view 3d|side]
Needs Debian's python3-meshio and python3-matplotlib.
"""
import argparse

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import matplotlib.ticker  # noqa: E402
import meshio  # noqa: E402
import numpy as np  # noqa: E402


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("frame")
    parser.add_argument("out")
    parser.add_argument("--field", default="speed", choices=["speed", "pressure", "density"])
    parser.add_argument("--view", default="3d", choices=["3d", "side"])
    parser.add_argument("--title", default="")
    parser.add_argument("--elevation", type=float, default=22, help="3d view: degrees above the floor")
    parser.add_argument("--azimuth", type=float, default=-62, help="3d view: degrees about the vertical")
    args = parser.parse_args()

    m = meshio.read(args.frame)
    kind = m.point_data["type"].ravel()
    x = m.points
    fluid = kind == 0
    solid = (kind == 2) | (kind == 3) | ((kind == 1) & (m.point_data["object"].ravel() >= 0))
    if args.field == "speed":
        value = np.linalg.norm(m.point_data["velocity"], axis=1)
        label = "speed, m/s"
    else:
        value = m.point_data[args.field].ravel()
        label = args.field
    fig = plt.figure(figsize=(8, 4.5), dpi=120)
    if args.view == "3d":
        ax = fig.add_subplot(projection="3d")
        ax.scatter(x[solid, 0], x[solid, 2], x[solid, 1], s=0.6, c="0.55", depthshade=False)
        sc = ax.scatter(x[fluid, 0], x[fluid, 2], x[fluid, 1], s=0.6, c=value[fluid], cmap="viridis",
                        depthshade=False)
        ax.set_xlabel("x, m")
        ax.set_ylabel("z, m")
        ax.set_zlabel("y, m")
        lo, hi = x.min(axis=0), x.max(axis=0)
        ax.set_box_aspect((hi[0] - lo[0], hi[2] - lo[2], hi[1] - lo[1]))
        ax.view_init(elev=args.elevation, azim=args.azimuth)
        for axis in (ax.xaxis, ax.yaxis, ax.zaxis):
            axis.set_major_locator(matplotlib.ticker.MaxNLocator(4))
    else:
        ax = fig.add_subplot()
        ax.scatter(x[solid, 0], x[solid, 1], s=0.4, c="0.55")
        sc = ax.scatter(x[fluid, 0], x[fluid, 1], s=0.4, c=value[fluid], cmap="viridis")
        ax.set_aspect("equal")
        ax.set_xlabel("x, m")
        ax.set_ylabel("y, m")
    fig.colorbar(sc, ax=ax, shrink=0.7, label=label)
    if args.title:
        ax.set_title(args.title)
    fig.tight_layout()
    fig.savefig(args.out)


if __name__ == "__main__":
    main()
