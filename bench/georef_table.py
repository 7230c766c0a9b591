#!/usr/bin/env python3
"""Georeferencing errors against a simulation's truth (issue 9, thesis Tables 5-6).

Plain Python (no numpy). For each estimate of T_enu_world (a `taiga georef` georef.yaml, or the
fused run's summary.json) of a run's world frame:

- translation: every pose of the run's trajectory.tum is taken through the estimate into its ENU
  frame, exactly through ECEF into the ENU frame at the simulator's origin, into the simulator's
  world frame (its yaw from georef_truth.yaml) and into EPSG:3067 with georef_truth.yaml's
  T_epsg_world (the tangent plane at the origin: within 2 mm over 150 m). The truth is
  groundtruth.tum at the same time (linear interpolation) through the same T_epsg_world. Errors are
  estimate - truth per grid axis (east, north, up), RMS and mean over the trajectory. They hold the
  run's own (odometry) errors too: that is what a user of the georeferenced trajectory sees.
- rotation: the true rotation from the run's world frame to ENU (at the simulator's origin) is
  Rz(world_yaw) * R_sim_run, R_sim_run the mean over the run's poses of R_sim_body(t) *
  R_run_body(t)^T (ground-truth orientation interpolated at the pose's time; quaternion mean).
  From the orientations, not from an SE(3) alignment of positions: the harvester's track is
  nearly straight, and positions do not fix the rotation about it. The error is
  R_est * R_true^T as roll, pitch, yaw (about east, north, up; R = Rz Ry Rx), in degrees; roll and
  pitch of robust and fused are then the run's own levelling error (both keep the map's tilt).

Usage: georef_table.py --sim SIM --label NAME [--georef METHOD=DIR/georef.yaml ...]
       [--fused RUN_ON/summary.json] --traj-off RUN_OFF/trajectory.tum --eval-off E.json
       [--traj-on RUN_ON/trajectory.tum --eval-on E.json]
Prints Markdown table rows and writes nothing.
"""
import argparse
import json
import math
import re

A_WGS84 = 6378137.0
F_WGS84 = 1.0 / 298.257223563
E2 = F_WGS84 * (2.0 - F_WGS84)


def matmul(a, b):
    return [[sum(a[i][k] * b[k][j] for k in range(len(b))) for j in range(len(b[0]))]
            for i in range(len(a))]


def transpose(a):
    return [list(row) for row in zip(*a)]


def apply(r, v):
    return [sum(r[i][k] * v[k] for k in range(3)) for i in range(3)]


def rot_z(angle_rad):
    c, s = math.cos(angle_rad), math.sin(angle_rad)
    return [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]


def quat_to_matrix(x, y, z, w):
    return [[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]]


def roll_pitch_yaw_deg(r):
    """R = Rz(yaw) Ry(pitch) Rx(roll)."""
    pitch = math.asin(max(-1.0, min(1.0, -r[2][0])))
    roll = math.atan2(r[2][1], r[2][2])
    yaw = math.atan2(r[1][0], r[0][0])
    return [math.degrees(roll), math.degrees(pitch), math.degrees(yaw)]


def ecef(lat_deg, lon_deg, h):
    lat, lon = math.radians(lat_deg), math.radians(lon_deg)
    n = A_WGS84 / math.sqrt(1.0 - E2 * math.sin(lat) ** 2)
    return [(n + h) * math.cos(lat) * math.cos(lon), (n + h) * math.cos(lat) * math.sin(lon),
            (n * (1.0 - E2) + h) * math.sin(lat)]


def r_ecef_enu(lat_deg, lon_deg):
    """Columns: east, north, up in ECEF."""
    lat, lon = math.radians(lat_deg), math.radians(lon_deg)
    east = [-math.sin(lon), math.cos(lon), 0.0]
    north = [-math.sin(lat) * math.cos(lon), -math.sin(lat) * math.sin(lon), math.cos(lat)]
    up = [math.cos(lat) * math.cos(lon), math.cos(lat) * math.sin(lon), math.sin(lat)]
    return transpose([east, north, up])


class EnuChange:
    """p_enu0 = R p_enu1 + t, exact through ECEF."""

    def __init__(self, origin1, origin0):
        r1, r0 = r_ecef_enu(origin1[0], origin1[1]), r_ecef_enu(origin0[0], origin0[1])
        self.R = matmul(transpose(r0), r1)
        d = [a - b for a, b in zip(ecef(*origin1), ecef(*origin0))]
        self.t = apply(transpose(r0), d)

    def __call__(self, p):
        q = apply(self.R, p)
        return [q[i] + self.t[i] for i in range(3)]


def read_tum(path):
    poses = []
    with open(path) as f:
        for line in f:
            if not line.strip() or line.startswith('#'):
                continue
            v = [float(x) for x in line.split()]
            poses.append((v[0], v[1:4], v[4:8]))
    return poses


def interpolate_positions(poses, t):
    """Linear interpolation of positions; None outside the span."""
    lo, hi = 0, len(poses) - 1
    if t < poses[0][0] or t > poses[-1][0]:
        return None
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if poses[mid][0] <= t:
            lo = mid
        else:
            hi = mid
    t0, p0, _ = poses[lo]
    t1, p1, _ = poses[hi]
    s = 0.0 if t1 == t0 else (t - t0) / (t1 - t0)
    return [p0[i] + s * (p1[i] - p0[i]) for i in range(3)]


def quat_mul(a, b):
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return (aw * bx + ax * bw + ay * bz - az * by, aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw, aw * bw - ax * bx - ay * by - az * bz)


def quat_normalized(q):
    n = math.sqrt(sum(x * x for x in q))
    return tuple(x / n for x in q)


def interpolate_quaternion(poses, t):
    """Normalized linear interpolation (5 ms apart in groundtruth.tum); None outside."""
    if t < poses[0][0] or t > poses[-1][0]:
        return None
    lo, hi = 0, len(poses) - 1
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if poses[mid][0] <= t:
            lo = mid
        else:
            hi = mid
    t0, _, q0 = poses[lo]
    t1, _, q1 = poses[hi]
    s = 0.0 if t1 == t0 else (t - t0) / (t1 - t0)
    sign = 1.0 if sum(a * b for a, b in zip(q0, q1)) >= 0 else -1.0
    return quat_normalized([q0[i] + s * (sign * q1[i] - q0[i]) for i in range(4)])


def orientation_alignment(groundtruth, trajectory):
    """R_sim_run: mean over poses of q_sim_body * q_run_body^-1."""
    total, first = [0.0] * 4, None
    for t, _, q_run in trajectory:
        q_sim = interpolate_quaternion(groundtruth, t)
        if q_sim is None:
            continue
        x, y, z, w = q_run
        q = quat_mul(q_sim, (-x, -y, -z, w))
        if first is None:
            first = q
        sign = 1.0 if sum(a * b for a, b in zip(q, first)) >= 0 else -1.0
        total = [total[i] + sign * q[i] for i in range(4)]
    return quat_to_matrix(*quat_normalized(total))


def yaml_matrix(text, key):
    """Rows '  - [a, b, c, d]' following 'key:'."""
    lines = text.splitlines()
    for i, line in enumerate(lines):
        if line.strip().startswith(key + ':'):
            rows = []
            for row in lines[i + 1:]:
                m = re.match(r'\s*-\s*\[(.*)\]', row)
                if not m:
                    break
                rows.append([float(x) for x in m.group(1).split(',')])
            return rows
    raise SystemExit(f'no {key} in the yaml')


def yaml_number(text, key, after=None):
    start = text.find(after) if after else 0
    m = re.search(r'^\s*' + re.escape(key) + r':\s*([-+0-9.eE]+)', text[start:], re.M)
    if not m:
        raise SystemExit(f'no {key} in the yaml')
    return float(m.group(1))


class Truth:
    def __init__(self, sim):
        text = open(f'{sim}/georef_truth.yaml').read()
        self.origin = (yaml_number(text, 'latitude_deg', 'origin:'),
                       yaml_number(text, 'longitude_deg', 'origin:'),
                       yaml_number(text, 'height_ellipsoid_m', 'origin:'))
        self.world_yaw = math.radians(yaml_number(text, 'world_yaw_from_east_deg'))
        self.T_epsg_world = yaml_matrix(text, 'T_epsg_world')
        self.groundtruth = read_tum(f'{sim}/groundtruth.tum')

    def grid_of_sim(self, p_sim):
        T = self.T_epsg_world
        return [sum(T[i][k] * p_sim[k] for k in range(3)) + T[i][3] for i in range(3)]


def score(truth, trajectory, T_enu_world, enu_origin):
    """Per-axis translation errors (RMS, mean) and roll/pitch/yaw errors of one estimate."""
    to_enu0 = EnuChange(enu_origin, truth.origin)
    R_sim_enu0 = rot_z(-truth.world_yaw)
    errors = []
    for t, p_run, _ in trajectory:
        p_true_sim = interpolate_positions(truth.groundtruth, t)
        if p_true_sim is None:
            continue
        p_enu1 = [sum(T_enu_world[i][k] * p_run[k] for k in range(3)) + T_enu_world[i][3]
                  for i in range(3)]
        p_sim = apply(R_sim_enu0, to_enu0(p_enu1))
        est, ref = truth.grid_of_sim(p_sim), truth.grid_of_sim(p_true_sim)
        errors.append([est[i] - ref[i] for i in range(3)])
    n = len(errors)
    rms = [math.sqrt(sum(e[i] ** 2 for e in errors) / n) for i in range(3)]
    mean = [sum(e[i] for e in errors) / n for i in range(3)]
    horizontal = math.sqrt(sum(e[0] ** 2 + e[1] ** 2 for e in errors) / n)

    R_sim_run = orientation_alignment(truth.groundtruth, trajectory)
    R_true = matmul(rot_z(truth.world_yaw), R_sim_run)  # run world -> ENU at the sim origin
    R_est = matmul(to_enu0.R, [row[:3] for row in T_enu_world[:3]])
    rotation = roll_pitch_yaw_deg(matmul(R_est, transpose(R_true)))
    return {'rms': rms, 'mean': mean, 'horizontal': horizontal, 'rotation': rotation, 'poses': n}


def georef_estimate(path):
    text = open(path).read()
    origin = (yaml_number(text, 'latitude_deg', 'enu_origin:'),
              yaml_number(text, 'longitude_deg', 'enu_origin:'),
              yaml_number(text, 'height_ellipsoid_m', 'enu_origin:'))
    return yaml_matrix(text, 'T_enu_world'), origin


def fused_estimate(summary_path):
    fusion = json.load(open(summary_path)).get('gnss_fusion')
    if not fusion or fusion.get('T_enu_world') is None:
        return None
    o = fusion['enu_origin']
    return fusion['T_enu_world'], (o['latitude_deg'], o['longitude_deg'], o['height_ellipsoid_m'])


def row(label, method, s, ate_m):
    e, m, r = s['rms'], s['mean'], s['rotation']
    ate = f'{ate_m * 100:.1f}' if ate_m is not None else ''
    return (f'| {label} | {method} | {e[0]:.2f} | {e[1]:.2f} | {e[2]:.2f} | {s["horizontal"]:.2f} | '
            f'{m[0]:+.2f} / {m[1]:+.2f} / {m[2]:+.2f} | {r[0]:+.3f} | {r[1]:+.3f} | {r[2]:+.3f} | {ate} |')


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--sim', required=True)
    parser.add_argument('--label', required=True)
    parser.add_argument('--georef', action='append', default=[], help='METHOD=georef.yaml')
    parser.add_argument('--traj-off', required=True)
    parser.add_argument('--eval-off', required=True)
    parser.add_argument('--fused', help='summary.json of the fused run')
    parser.add_argument('--traj-on')
    parser.add_argument('--eval-on')
    args = parser.parse_args()

    truth = Truth(args.sim)
    off = read_tum(args.traj_off)
    ate_off = json.load(open(args.eval_off))['ape']['translation_m']['rmse']
    for item in args.georef:
        method, path = item.split('=', 1)
        T, origin = georef_estimate(path)
        print(row(args.label, method, score(truth, off, T, origin), ate_off))
    if args.fused:
        estimate = fused_estimate(args.fused)
        ate_on = json.load(open(args.eval_on))['ape']['translation_m']['rmse']
        if estimate is None:
            print(f'| {args.label} | fused | (no estimate in {args.fused}) | | | | | | | | '
                  f'{ate_on * 100:.1f} |')
        else:
            T, origin = estimate
            print(row(args.label, 'fused', score(truth, read_tum(args.traj_on), T, origin), ate_on))


if __name__ == '__main__':
    main()
