#!/usr/bin/python3
"""ALS georeferencing against the simulator's truth (issue 23, bench/BENCHMARK.md "Session 38").

For each scenario and seed: `taiga simulate --als` (5 pulses per m^2), `taiga run` with the
rig.yaml a user would write, then `taiga georef --als` twice: from a start 5 m and 5 deg off the
true pose of the map (searching 8 m / 8 deg, as from GNSS) and from one 20 m and 20 deg off
(searching 25 m / 25 deg, without GNSS). The true pose of the map in the grid is the simulator's
T_epsg_world times the run's map frame aligned to the ground truth (Kabsch on positions).
Prints one JSON line per run and a Markdown table: mean errors of the grid trajectory (horizontal,
height, heading), and how often the reported 1-sigma covered the transform's error (east, north,
up, yaw) within 1 and 2 sigma.

Usage: bench/als_georef.py OUT_DIR [SEEDS] [SCENARIOS]   (environment: TAIGA, DURATION, BEAMS,
REALISM: ideal (default), typical or harsh)
Example: bench/als_georef.py /tmp/als_bench "21 22 23" "handheld-loop harvester"
"""
import json, math, os, subprocess, sys, time
import numpy as np
import yaml

taiga = os.environ.get("TAIGA", "build/bin/taiga")
duration = os.environ.get("DURATION", "60")
beams = os.environ.get("BEAMS", "32")
realism = os.environ.get("REALISM", "ideal")
out = sys.argv[1]
seeds = (sys.argv[2] if len(sys.argv) > 2 else "21 22 23").split()
scenarios = (sys.argv[3] if len(sys.argv) > 3 else "handheld-loop harvester").split()


def tum(path):
    rows = [list(map(float, l.split())) for l in open(path) if l.strip() and not l.startswith("#")]
    return {round(r[0], 3): np.array(r[1:4]) for r in rows}, rows  # ms keys: scan ends are 0.1 ms off the truth's 5 ms grid


def yaw_of(q):  # x y z w
    x, y, z, w = q
    return math.atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))


def rotation(q):  # x y z w
    x, y, z, w = q
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def true_grid_pose(sim, run):
    """T_grid_map of the run's map frame: the truth's T_epsg_world times T_world_map. The rotation
    from the orientations (the chordal mean of R_world_body(t) R_map_body(t)^T over the run's
    poses), not from the positions: a harvester's nearly straight track does not fix the heading
    (a Kabsch fit of its positions was off by tenths of a degree); the translation then from the
    positions."""
    truth = yaml.safe_load(open(f"{sim}/georef_truth.yaml"))
    T_gw = np.array(truth["T_epsg_world"])
    _, gt_rows = tum(f"{sim}/groundtruth.tum")
    _, est_rows = tum(f"{run}/trajectory.tum")
    gt_t = np.array([r[0] for r in gt_rows])
    gt = np.array([r[1:8] for r in gt_rows])
    A, B, M = [], [], np.zeros((3, 3))
    for r in est_rows:
        if not gt_t[0] <= r[0] <= gt_t[-1]:
            continue
        i = min(max(int(np.searchsorted(gt_t, r[0])), 1), len(gt_t) - 1)
        f = (r[0] - gt_t[i - 1]) / (gt_t[i] - gt_t[i - 1])
        A.append(np.array(r[1:4]))
        B.append(gt[i - 1, :3] + f * (gt[i, :3] - gt[i - 1, :3]))
        nearest = i if f > 0.5 else i - 1  # 200 Hz truth: within 2.5 ms of the pose
        M += rotation(gt[nearest, 3:7]) @ rotation(r[4:8]).T
    U, _, Vt = np.linalg.svd(M)
    R = U @ np.diag([1, 1, np.sign(np.linalg.det(U @ Vt))]) @ Vt
    A, B = np.array(A), np.array(B)
    T_wm = np.eye(4); T_wm[:3, :3] = R; T_wm[:3, 3] = (B - A @ R.T).mean(0)
    return T_gw @ T_wm


def georef(sim, run, dest, T_true, shift_m, turn_deg, search, seed):
    rng = np.random.default_rng(seed)
    direction = rng.uniform(0, 2 * math.pi)
    e = T_true[0, 3] + shift_m * math.cos(direction)
    n = T_true[1, 3] + shift_m * math.sin(direction)
    yaw = math.degrees(math.atan2(T_true[1, 0], T_true[0, 0])) + turn_deg * rng.choice([-1, 1])
    cmd = [taiga, "georef", "--als", f"{sim}/als.las", "--run", run, "--guess",
           f"{e:.3f},{n:.3f},{yaw:.3f}", "--search-m", str(search), "--search-deg", str(search),
           "--out", dest]
    start_s = time.monotonic()
    done = subprocess.run(cmd, capture_output=True, text=True)
    seconds = time.monotonic() - start_s
    if not os.path.exists(f"{dest}/georef_als.yaml"):  # refused before registering (exit 2)
        lines = (done.stderr or done.stdout).strip().splitlines()
        return {"ok": False, "reason": lines[-1] if lines else f"exit {done.returncode}",
                "seconds": round(seconds, 1)}
    report = yaml.safe_load(open(f"{dest}/georef_als.yaml"))
    result = {"ok": report["ok"], "reason": report.get("reason", ""), "seconds": round(seconds, 1),
              "map_points_used": report["map_points"], "als_points": report["als_points"]}
    if not report["ok"]:
        return result
    errors = json.loads(subprocess.run(["python3", "bench/georef_error.py", sim,
                                        f"{dest}/trajectory_epsg3067.csv"],
                                       capture_output=True, text=True).stdout)
    T = np.array(report["T_epsg_world"])
    d = T[:3, 3] - T_true[:3, 3]
    dyaw = math.degrees(math.atan2(T[1, 0], T[0, 0]) - math.atan2(T_true[1, 0], T_true[0, 0]))
    dyaw = (dyaw + 180) % 360 - 180
    sigma = report["sigma"]
    result.update(errors)
    result["transform_error"] = [d[0], d[1], d[2], dyaw]
    result["sigma"] = [sigma[0], sigma[1], sigma[2], sigma[5]]
    return result


results = []
for scenario in scenarios:
    for seed in seeds:
        base = f"{out}/{scenario}_{seed}"
        sim, run = f"{base}/sim", f"{base}/run"
        if not os.path.exists(f"{sim}/als.las"):
            subprocess.run([taiga, "simulate", "--scenario", scenario, "--duration", duration,
                            "--beams", beams, "--seed", seed, "--realism", realism, "--als",
                            "--out", sim],
                           check=True, capture_output=True)
        if not os.path.exists(f"{run}/map.las"):
            subprocess.run([taiga, "run", f"{sim}/recording.bag", "--config", f"{sim}/rig.yaml",
                            "--out", run], capture_output=True)
        T_true = true_grid_pose(sim, run)
        for start, shift, turn, search in [("5 m / 5 deg", 5.0, 5.0, 8), ("20 m / 20 deg", 20.0, 20.0, 25)]:
            r = georef(sim, run, f"{base}/als_{int(shift)}", T_true, shift, turn, search, int(seed))
            r.update({"scenario": scenario, "seed": seed, "start": start})
            print(json.dumps(r), flush=True)
            results.append(r)

print("\n| scenario | start | runs ok | horizontal mean (max) m | height mean abs m | heading mean abs deg | within 1 sigma | within 2 sigma | seconds (max) |")
print("|---|---|---|---|---|---|---|---|---|")
for scenario in scenarios:
    for start in ["5 m / 5 deg", "20 m / 20 deg"]:
        rows = [r for r in results if r["scenario"] == scenario and r["start"] == start]
        ok = [r for r in rows if r["ok"]]
        if not ok:
            print(f"| {scenario} | {start} | 0 of {len(rows)} | | | | | | |")
            continue
        h = [r["horizontal_mean_m"] for r in ok]
        z = [abs(r["height_mean_m"]) for r in ok]
        y = [abs(r["heading_mean_deg"]) for r in ok]
        ratios = [abs(e) / s for r in ok for e, s in zip(r["transform_error"], r["sigma"]) if s > 0]
        within1 = sum(x <= 1 for x in ratios) / len(ratios)
        within2 = sum(x <= 2 for x in ratios) / len(ratios)
        print(f"| {scenario} | {start} | {len(ok)} of {len(rows)} | {np.mean(h):.3f} ({max(h):.3f}) | "
              f"{np.mean(z):.3f} | {np.mean(y):.3f} | {100 * within1:.0f} % | {100 * within2:.0f} % | "
              f"{max(r.get('seconds', 0) for r in ok):.1f} |")
