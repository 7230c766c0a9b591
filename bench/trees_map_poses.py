#!/usr/bin/python3
"""How much of a run's DBH error is the map's placement of its keyframes, not the stem fit.

Rebuilds the map of a run made by bench/trees_table.sh twice: from the simulator's true poses
(SE(3)-aligned to the run's map frame on the keyframe positions) and from the run's own poses
scaled about their centroid by the trajectory's Sim(3) scale against the truth. Then `taiga trees`
and `taiga eval --trees` on each, and one Markdown row per map.

  bench/trees_map_poses.py SIM_DIR [RADIUS_M]     (TAIGA=path/to/taiga; SIM_DIR/run is the run)
"""
import json, os, shutil, subprocess, sys
import numpy as np
from scipy.spatial.transform import Rotation, Slerp

TAIGA = os.environ.get("TAIGA", "build/bin/taiga")


def write_poses(run_out, t, positions, quaternions):
    for path in (f"{run_out}/keyframes/poses.tum", f"{run_out}/keyframes.tum"):
        with open(path, "w") as f:
            f.write("# t x y z qx qy qz qw\n")
            for i in range(len(t)):
                f.write(" ".join(repr(float(v)) for v in [t[i], *positions[i], *quaternions[i]]) + "\n")


def true_poses(keyframes, truth):
    """The truth at the keyframes' times in the run's map frame (Umeyama SE(3) on positions)."""
    t = keyframes[:, 0]
    world = np.stack([np.interp(t, truth[:, 0], truth[:, i]) for i in (1, 2, 3)], 1)
    rotations = Slerp(truth[:, 0], Rotation.from_quat(truth[:, 4:8]))(t)
    mapped = keyframes[:, 1:4]
    mw, mm = world.mean(0), mapped.mean(0)
    u, _, vt = np.linalg.svd((mapped - mm).T @ (world - mw))
    d = np.diag([1.0, 1.0, np.sign(np.linalg.det(u @ vt))])
    R = u @ d @ vt
    return world @ R.T + (mm - R @ mw), (Rotation.from_matrix(R) * rotations).as_quat()


def evaluate(sim, run_dir, trees_dir, radius):
    subprocess.run([TAIGA, "export-map", f"{run_dir}/keyframes", "--out", f"{run_dir}/map.las"],
                   check=True, capture_output=True)
    subprocess.run([TAIGA, "trees", run_dir, "--out", trees_dir], check=True, capture_output=True)
    report = subprocess.run([TAIGA, "eval", "--est", f"{sim}/run/trajectory.tum", "--ref",
                             f"{sim}/groundtruth.tum", "--trees", f"{trees_dir}/trees.csv",
                             "--ref-trees", f"{sim}/trees.csv", "--trees-radius", str(radius),
                             "--json"], check=True, capture_output=True, text=True).stdout
    with open(f"{trees_dir}/eval.json", "w") as f:
        f.write(report)
    return json.loads(report)["trees"]


def main():
    sim = sys.argv[1]
    radius = float(sys.argv[2]) if len(sys.argv) > 2 else 15.0
    sim3 = json.loads(subprocess.run([TAIGA, "eval", "--est", f"{sim}/run/trajectory.tum", "--ref",
                                      f"{sim}/groundtruth.tum", "--align", "sim3", "--json"],
                                     check=True, capture_output=True, text=True).stdout)
    scale = sim3["alignment"]["scale"]
    keyframes = np.loadtxt(f"{sim}/run/keyframes/poses.tum")
    truth = np.loadtxt(f"{sim}/groundtruth.tum")
    centroid = keyframes[:, 1:4].mean(0)
    variants = {
        "true poses": true_poses(keyframes, truth),
        f"run's poses scaled by {scale:.6f}": (centroid + scale * (keyframes[:, 1:4] - centroid),
                                               keyframes[:, 4:8]),
    }
    rows = [("run's poses", json.load(open(f"{sim}/trees/eval.json"))["trees"])]
    for name, (positions, quaternions) in variants.items():
        run_out = f"{sim}/run_{len(rows)}"
        shutil.rmtree(run_out, ignore_errors=True)
        shutil.copytree(f"{sim}/run", run_out)
        write_poses(run_out, keyframes[:, 0], positions, quaternions)
        rows.append((name, evaluate(sim, run_out, f"{sim}/trees_{len(rows)}", radius)))
    print("| case | map from | detected % | commission % | DBH RMSE cm | DBH bias cm | position RMSE cm |")
    print("|---|---|---|---|---|---|---|")
    for name, t in rows:
        print(f"| {os.path.basename(sim.rstrip('/'))} | {name} | {100 * t['recall']:.1f} | "
              f"{100 * t['commission']:.1f} | {100 * t['dbh_rmse_m']:.2f} | "
              f"{100 * t['dbh_bias_m']:+.2f} | {100 * t['position_rmse_m']:.2f} |")


main()
