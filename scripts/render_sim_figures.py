#!/usr/bin/python3
"""Figures of a simulated forest plot for docs/simulator.md, from the files of bench/sim_render.

    build/bin/sim_render /tmp/sim_render 60 mixed 1 100
    /usr/bin/python3 scripts/render_sim_figures.py /tmp/sim_render docs/images

Writes sim_plot_top.png (top view, material colours shaded by the surface normal, ground-truth
trajectory on top), sim_plot_side.png (a 12 m slab seen from the south) and sim_scan.png (one
simulated OS0-128 scan in the world frame, top and side, points coloured by height above the
sensor).
"""
import csv
import json
import sys
from pathlib import Path

import io

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

# taiga::sim::Material order: ground, bark, branch, foliage, rock, dead wood, machine.
MATERIAL_RGB = np.array(
    [
        [0.55, 0.50, 0.38],  # ground (moss, litter)
        [0.45, 0.30, 0.20],  # bark
        [0.50, 0.38, 0.26],  # branch
        [0.20, 0.45, 0.18],  # foliage
        [0.60, 0.60, 0.60],  # rock
        [0.62, 0.52, 0.38],  # dead wood
        [0.85, 0.70, 0.10],  # machine
    ]
)
NOTHING_RGB = np.array([0.85, 0.92, 1.0])  # sky


def shaded(material, shade):
    rgb = np.empty(material.shape + (3,))
    hit = material != 255
    rgb[~hit] = NOTHING_RGB
    rgb[hit] = MATERIAL_RGB[material[hit]] * (0.35 + 0.65 * shade[hit])[:, None]
    return np.clip(rgb, 0, 1)


def save_small(fig, path, colours=192):
    """PNG with an adaptive palette: the shaded textures compress badly in full colour."""
    from PIL import Image

    buffer = io.BytesIO()
    fig.savefig(buffer, format="png")
    plt.close(fig)
    buffer.seek(0)
    image = Image.open(buffer).convert("RGB")
    image.quantize(colors=colours, method=Image.Quantize.FASTOCTREE).save(path, optimize=True)


def read_csv(path):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    return {k: np.array([float(r[k]) for r in rows]) for k in rows[0]}


def main(src, dst):
    src, dst = Path(src), Path(dst)
    dst.mkdir(parents=True, exist_ok=True)
    views = json.loads((src / "views.json").read_text())
    traj = read_csv(src / "trajectory.csv")
    title = f"'{views['scenario']}' seed {views['seed']}, {views['duration_s']:.0f} s walk"

    # Top view with the trajectory.
    top = views["top"]
    rgb = shaded(np.load(src / "top_material.npy"), np.load(src / "top_shade.npy"))
    fig, ax = plt.subplots(figsize=(6.4, 6.0), dpi=110)
    ax.imshow(rgb, extent=(top["x_min"], top["x_max"], top["y_min"], top["y_max"]),
              interpolation="bilinear")
    ax.plot(traj["x_m"], traj["y_m"], color="red", lw=1.2, label="ground-truth trajectory")
    ax.plot(traj["x_m"][0], traj["y_m"][0], "o", color="red", ms=5, label="start")
    side = views["side"]
    for y in (side["y_from"], side["y_to"]):
        ax.axhline(y, color="white", lw=0.8, ls="--")
    ax.set_xlabel("x (east), m")
    ax.set_ylabel("y (north), m")
    ax.set_title(f"Top view: {title}, {views['trees']} trees\n(dashed: the slab of the side view)",
                 fontsize=9)
    ax.legend(loc="lower right", fontsize=8)
    fig.tight_layout()
    save_small(fig, dst / "sim_plot_top.png")

    # Side view of the slab, with the trajectory's x-z trace where it passes through the slab.
    rgb = shaded(np.load(src / "side_material.npy"), np.load(src / "side_shade.npy"))
    fig, ax = plt.subplots(figsize=(9.0, 4.2), dpi=100)
    ax.imshow(rgb, extent=(side["x_min"], side["x_max"], side["z_min"], side["z_max"]),
              interpolation="bilinear")
    inside = (traj["y_m"] >= side["y_from"]) & (traj["y_m"] <= side["y_to"])
    ax.plot(np.where(inside, traj["x_m"], np.nan), traj["z_m"], color="red", lw=1.5,
            label="trajectory inside the slab")
    ax.set_xlabel("x (east), m")
    ax.set_ylabel("z (up), m")
    ax.set_title(f"Side view from the south: {title}; slab y = {side['y_from']:.0f} .. "
                 f"{side['y_to']:.0f} m", fontsize=9)
    ax.legend(loc="upper right", fontsize=8)
    fig.tight_layout()
    save_small(fig, dst / "sim_plot_side.png")

    # One scan in the world frame: top (30 m around the sensor) and side (a 4 m slice).
    scan = read_csv(src / "scan.csv")
    t_scan = 0.1 * views["scan"]
    k = int(np.argmin(np.abs(traj["t_s"] - t_scan)))
    cx, cy, cz = traj["x_m"][k], traj["y_m"][k], traj["z_m"][k]
    dz = scan["z_m"] - cz
    fig, (ax0, ax1) = plt.subplots(1, 2, figsize=(10.0, 4.0), dpi=100, layout="constrained",
                                   gridspec_kw={"width_ratios": [1.0, 1.6]})
    near = (np.abs(scan["x_m"] - cx) < 30) & (np.abs(scan["y_m"] - cy) < 30)
    sc = ax0.scatter(scan["x_m"][near] - cx, scan["y_m"][near] - cy, c=dz[near], s=0.15,
                     cmap="viridis", vmin=-4, vmax=14, linewidths=0, rasterized=True)
    ax0.plot(0, 0, "r^", ms=6)
    ax0.set_aspect("equal")
    ax0.set_xlabel("x - sensor, m")
    ax0.set_ylabel("y - sensor, m")
    ax0.set_title(f"Scan {views['scan']}: {len(scan['x_m'])} points, top", fontsize=9)
    band = np.abs(scan["y_m"] - cy) < 2.0
    ax1.scatter(scan["x_m"][band] - cx, dz[band], c=dz[band], s=0.3, cmap="viridis", vmin=-4,
                vmax=14, linewidths=0, rasterized=True)
    ax1.plot(0, 0, "r^", ms=6)
    ax1.set_aspect("equal")
    ax1.set_xlim(-30, 30)
    ax1.set_xlabel("x - sensor, m")
    ax1.set_ylabel("z - sensor, m")
    ax1.set_title("side: the points within 2 m of the sensor's y", fontsize=9)
    fig.colorbar(sc, ax=[ax0, ax1], label="height above the sensor, m", shrink=0.7)
    save_small(fig, dst / "sim_scan.png", colours=128)
    for name in ("sim_plot_top.png", "sim_plot_side.png", "sim_scan.png"):
        print(dst / name, (dst / name).stat().st_size // 1024, "KB")


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2])
