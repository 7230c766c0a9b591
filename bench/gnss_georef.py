#!/usr/bin/python3
"""GNSS-only georeferencing against the simulator's truth and against the information limit of
its error model (issue 23, bench/BENCHMARK.md "Session 39").

For each seed: `taiga simulate` (GNSS and the true trajectory; lidar scans thinned away with
output.scan_stride, they are not used), `taiga georef --traj groundtruth.tum --gnss recording.bag`
with each binary in TAIGAS (the true trajectory isolates the georeferencing from the odometry).
Errors against georef_truth.yaml:
- east, north, up of the world origin in the fit's ENU frame and the yaw, against the 1-sigma of
  georef.yaml (how often within 1 and 2 sigma);
- horizontal: RMS over the trajectory's poses of the horizontal position error; heading: the yaw
  error; height: the up error.
The expected error ("limit") is the Cramer-Rao bound of the simulator's own error model for the
fixes the fit used (fixes.csv): each fix's true sigma (gnss_truth.csv), a Gauss-Markov process
with the simulator's correlation time, independent per axis; multipath left out. It is the bound
of an estimator that knows the true sigmas; with realism's noisy reported sigmas no estimator
does. Its horizontal figure is the RMS over the poses of the propagated covariance, like the
error. gnss_truth.csv also tells which fixes had multipath: how many the fit used, and how many
clean ones it dropped.

Usage: bench/gnss_georef.py OUT_DIR [SEEDS] [SCENARIO]
Environment: TAIGAS (space-separated binaries, default build/bin/taiga; the first must write
fixes.csv and gnss_truth.csv), DURATION (default: the scenario's), REALISM (default ideal),
OVERRIDES (a YAML file of extra scenario fields, e.g. gnss: ...).
Example: bench/gnss_georef.py /tmp/gnss_bench "1 2 3 4 5 6 7 8 9 10" handheld-loop
"""
import json, math, os, subprocess, sys
import numpy as np
import yaml

taigas = os.environ.get("TAIGAS", "build/bin/taiga").split()
out = sys.argv[1]
seeds = (sys.argv[2] if len(sys.argv) > 2 else "1 2 3").split()
scenario = sys.argv[3] if len(sys.argv) > 3 else "handheld-loop"
A, F = 6378137.0, 1 / 298.257223563
E2 = F * (2 - F)


def ecef(lat_deg, lon_deg, h):
    lat, lon = math.radians(lat_deg), math.radians(lon_deg)
    n = A / math.sqrt(1 - E2 * math.sin(lat) ** 2)
    return np.array([(n + h) * math.cos(lat) * math.cos(lon), (n + h) * math.cos(lat) * math.sin(lon),
                     (n * (1 - E2) + h) * math.sin(lat)])


def R_ecef_enu(lat_deg, lon_deg):
    lat, lon = math.radians(lat_deg), math.radians(lon_deg)
    return np.array([[-math.sin(lon), -math.sin(lat) * math.cos(lon), math.cos(lat) * math.cos(lon)],
                     [math.cos(lon), -math.sin(lat) * math.sin(lon), math.cos(lat) * math.sin(lon)],
                     [0, math.cos(lat), math.sin(lat)]])


def gm_covariance(t, sigma, tau):
    return np.outer(sigma, sigma) * np.exp(-np.abs(t[:, None] - t[None, :]) / tau)


def limit(fixes, truth, yaw_true, gnss):
    """Cramer-Rao bound over (t_e, t_n, yaw) and t_u under the simulator's error model."""
    used = fixes[fixes[:, 13] == 1]
    t = used[:, 0]
    tau = gnss["correlation_time_s"]
    s_h = np.array([truth[round(x, 3)][4] for x in t])
    s_u = np.array([truth[round(x, 3)][5] for x in t])
    Sinv_h = np.linalg.inv(gm_covariance(t, s_h, tau))
    Sinv_u = np.linalg.inv(gm_covariance(t, s_u, tau))
    c, s = math.cos(yaw_true), math.sin(yaw_true)
    Ra = np.stack([c * used[:, 7] - s * used[:, 8], s * used[:, 7] + c * used[:, 8]], axis=1)
    J_e = np.stack([np.ones(len(t)), np.zeros(len(t)), -Ra[:, 1]], axis=1)
    J_n = np.stack([np.zeros(len(t)), np.ones(len(t)), Ra[:, 0]], axis=1)
    info = J_e.T @ Sinv_h @ J_e + J_n.T @ Sinv_h @ J_n
    ones = np.ones(len(t))
    return np.linalg.inv(info), 1.0 / (ones @ Sinv_u @ ones)


def horizontal_rms(C, world_xy, yaw):
    """RMS over the poses of sqrt(trace) of the horizontal position covariance from C over
    (t_e, t_n, yaw)."""
    c, s = math.cos(yaw), math.sin(yaw)
    total = 0.0
    for x, y in world_xy:
        Ra = (c * x - s * y, s * x + c * y)
        J = np.array([[1, 0, -Ra[1]], [0, 1, Ra[0]]])
        total += np.trace(J @ C @ J.T)
    return math.sqrt(total / len(world_xy))


def run(cmd):
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)


os.makedirs(out, exist_ok=True)
stride = f"{out}/stride.yaml"
extra = yaml.safe_load(open(os.environ["OVERRIDES"])) if os.environ.get("OVERRIDES") else {}
extra.setdefault("output", {})["scan_stride"] = 1000
yaml.safe_dump(extra, open(stride, "w"))
rows = []
for seed in seeds:
    sim = f"{out}/{scenario}_{seed}"
    cmd = [taigas[0], "simulate", "--scenario", scenario, "--seed", seed, "--beams", "16", "--columns",
           "512", "--sub-rays", "1", "--overrides", stride, "--out", sim,
           "--realism", os.environ.get("REALISM", "ideal")]
    if os.environ.get("DURATION"):
        cmd += ["--duration", os.environ["DURATION"]]
    run(cmd)
    truth = yaml.safe_load(open(f"{sim}/georef_truth.yaml"))
    fix_truth = {round(r[0], 3): r for r in np.loadtxt(f"{sim}/gnss_truth.csv", delimiter=",", skiprows=1)}
    gnss = yaml.safe_load(open(f"{sim}/scenario.yaml"))["gnss"]
    gt = np.array([list(map(float, l.split())) for l in open(f"{sim}/groundtruth.tum")
                   if l.strip() and not l.startswith("#")])[::50]
    for b, taiga in enumerate(taigas):
        est = f"{sim}/georef_{b}"
        run([taiga, "georef", "--traj", f"{sim}/groundtruth.tum", "--gnss", f"{sim}/recording.bag",
             "--out", est])
        g = yaml.safe_load(open(f"{est}/georef.yaml"))
        o = g["enu_origin"]
        R_est = R_ecef_enu(o["latitude_deg"], o["longitude_deg"])
        so = truth["origin"]
        # The simulator's world origin and its x axis in the fit's ENU frame.
        p_true = R_est.T @ (ecef(so["latitude_deg"], so["longitude_deg"], so["height_ellipsoid_m"]) -
                            ecef(o["latitude_deg"], o["longitude_deg"], o["height_ellipsoid_m"]))
        w = math.radians(truth["world_yaw_from_east_deg"])
        x_true = R_est.T @ R_ecef_enu(so["latitude_deg"], so["longitude_deg"]) @ np.array(
            [math.cos(w), math.sin(w), 0])
        yaw_true = math.atan2(x_true[1], x_true[0])
        t_est = np.array(g["T_enu_world_translation_m"])
        yaw_est = math.radians(g["T_enu_world_roll_pitch_yaw_deg"][2])
        d_yaw = math.atan2(math.sin(yaw_est - yaw_true), math.cos(yaw_est - yaw_true))
        d = t_est - p_true
        # Horizontal error of every pose: R_est p + t_est - (R_true p + p_true).
        ce, se, ct, st = math.cos(yaw_est), math.sin(yaw_est), math.cos(yaw_true), math.sin(yaw_true)
        xy = gt[:, 1:3]
        err = np.stack([ce * xy[:, 0] - se * xy[:, 1] - (ct * xy[:, 0] - st * xy[:, 1]) + d[0],
                        se * xy[:, 0] + ce * xy[:, 1] - (st * xy[:, 0] + ct * xy[:, 1]) + d[1]], axis=1)
        # A binary without fixes.csv (before session 39) is judged by the first binary's fixes.
        own_fixes = os.path.exists(f"{est}/fixes.csv")
        fixes_csv = f"{est}/fixes.csv" if own_fixes else f"{sim}/georef_0/fixes.csv"
        fixes = np.loadtxt(fixes_csv, delimiter=",", skiprows=1)
        C, var_u = limit(fixes, fix_truth, yaw_true, gnss)
        multipath = np.array([fix_truth[round(x, 3)][6] for x in fixes[:, 0]]) == 1
        used = fixes[:, 13] == 1
        sig = g["sigma"]
        row = {"seed": int(seed), "binary": b, "used": g["fixes"]["used"],
               "outliers": g["fixes"]["outliers"],
               "multipath_used": int(np.sum(multipath & used)) if own_fixes else None,
               "clean_dropped": int(np.sum(~multipath & ~used)) if own_fixes else None,
               "err": [d[0], d[1], d[2], math.degrees(d_yaw)],
               "sigma": [sig["east_m"], sig["north_m"], sig["up_m"], sig["yaw_deg"]],
               "limit": [math.sqrt(C[0, 0]), math.sqrt(C[1, 1]), math.sqrt(var_u),
                         math.degrees(math.sqrt(C[2, 2]))],
               "horizontal_m": float(np.sqrt(np.mean(np.sum(err ** 2, axis=1)))),
               "horizontal_limit_m": horizontal_rms(C, xy, yaw_true),
               "error_model": g.get("error_model")}
        rows.append(row)
        print(json.dumps(row), flush=True)

print(f"\n{scenario}, seeds {' '.join(seeds)}")
print("| binary | horizontal RMS error / limit (m) | heading RMS / limit (deg) | height RMS / limit (m) "
      "| ratio h, yaw, up | within 1 sigma (e, n, u, yaw) | within 2 sigma | multipath fixes used "
      "| clean fixes dropped |")
print("|---|---|---|---|---|---|---|---|---|")
count = lambda key, rs: "n/a" if rs[0][key] is None else sum(r[key] for r in rs)
for b, taiga in enumerate(taigas):
    rs = [r for r in rows if r["binary"] == b]
    rms = lambda v: math.sqrt(sum(x * x for x in v) / len(v))
    h, hl = rms([r["horizontal_m"] for r in rs]), rms([r["horizontal_limit_m"] for r in rs])
    y, yl = rms([r["err"][3] for r in rs]), rms([r["limit"][3] for r in rs])
    u, ul = rms([r["err"][2] for r in rs]), rms([r["limit"][2] for r in rs])
    z = [abs(r["err"][k]) / r["sigma"][k] for r in rs for k in range(4) if r["sigma"][k] > 0]
    one = sum(v <= 1 for v in z) / len(z)
    two = sum(v <= 2 for v in z) / len(z)
    print(f"| {taiga} | {h:.2f} / {hl:.2f} | {y:.2f} / {yl:.2f} | {u:.2f} / {ul:.2f} | "
          f"{h / hl:.2f}, {y / yl:.2f}, {u / ul:.2f} | {100 * one:.0f} % | {100 * two:.0f} % | "
          f"{count('multipath_used', rs)} | {count('clean_dropped', rs)} |")
