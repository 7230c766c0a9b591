#!/usr/bin/env python3
"""Error of a georeferenced trajectory against the simulator's truth: each pose of
trajectory_epsgNNNN.csv (`taiga georef`, `taiga georef --als`, or RUN/georef/) against the true
body pose in the grid (SIM/groundtruth.tum through SIM/georef_truth.yaml's T_epsg_world), matched
by time (the truth interpolated). Prints JSON: mean and max horizontal error, mean height error, mean heading error (deg).
The run's own odometry error is included (centimetres).
Usage: bench/georef_error.py SIM_DIR TRAJECTORY_EPSG.csv"""
import bisect, csv, json, math, sys
import yaml

sim, estimate = sys.argv[1], sys.argv[2]
truth = yaml.safe_load(open(f"{sim}/georef_truth.yaml"))
T = truth["T_epsg_world"]
rows = [list(map(float, l.split())) for l in open(f"{sim}/groundtruth.tum") if l.strip() and not l.startswith("#")]
times = [r[0] for r in rows]

def grid_pose(r):
    x, y, z, qx, qy, qz, qw = r[1:]
    e = T[0][0] * x + T[0][1] * y + T[0][3]
    n = T[1][0] * x + T[1][1] * y + T[1][3]
    h = z + T[2][3]
    yaw_world = math.atan2(2 * (qw * qz + qx * qy), 1 - 2 * (qy * qy + qz * qz))
    yaw_grid = yaw_world + math.atan2(T[1][0], T[0][0])
    return e, n, h, yaw_grid

horizontal, height, heading = [], [], []
for r in csv.DictReader(open(estimate)):
    t = float(r["t_s"])
    # The truth linearly between its samples (200 Hz): a run's times need not fall on them.
    i = bisect.bisect_left(times, t)
    if i == 0 or i >= len(times):
        continue
    a, b = grid_pose(rows[i - 1]), grid_pose(rows[i])
    f = (t - times[i - 1]) / (times[i] - times[i - 1])
    dyaw = math.atan2(math.sin(b[3] - a[3]), math.cos(b[3] - a[3]))
    e, n, h, yaw = (a[0] + f * (b[0] - a[0]), a[1] + f * (b[1] - a[1]), a[2] + f * (b[2] - a[2]),
                    a[3] + f * dyaw)
    horizontal.append(math.hypot(float(r["easting_m"]) - e, float(r["northing_m"]) - n))
    height.append(float(r["height_m"]) - h)
    d = math.radians(float(r["yaw_grid_deg"])) - yaw
    heading.append(math.degrees(math.atan2(math.sin(d), math.cos(d))))
mean = lambda v: sum(v) / len(v)
print(json.dumps({"poses": len(horizontal), "horizontal_mean_m": round(mean(horizontal), 4),
                  "horizontal_max_m": round(max(horizontal), 4), "height_mean_m": round(mean(height), 4),
                  "heading_mean_deg": round(mean(heading), 4)}))
