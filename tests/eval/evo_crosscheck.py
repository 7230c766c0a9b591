#!/usr/bin/python3
"""Cross-check of `taiga eval --json` against a numpy re-implementation of evo's definitions.

The numpy code below follows evo's source (evo/core/sync.py associate_trajectories,
geometry.umeyama_alignment, trajectory.align / align_origin, metrics.APE / RPE,
filters.filter_pairs_by_index / filter_pairs_by_path) line by line, with numpy's SVD instead of
Eigen's, and the KITTI devkit's calcSequenceErrors and the end-point drift likewise. It is not
evo itself (evo is not packaged for Debian); it checks that taiga's C++ computes
the same numbers as those definitions on a trajectory pair with a clock offset, time jitter,
missing poses, a scale error, random-walk drift and a global transform.

Usage: evo_crosscheck.py TAIGA_EXECUTABLE. Exit 0 when every number agrees, 1 otherwise,
77 (skipped) when numpy is missing.
"""
import json
import os
import subprocess
import sys
import tempfile

try:
    import numpy as np
except ImportError:
    print("numpy is not installed (apt install python3-numpy); skipped")
    sys.exit(77)

inv = np.linalg.inv


def exp_so3(v):
    th = np.linalg.norm(v)
    if th < 1e-12:
        return np.eye(3)
    k = v / th
    K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + np.sin(th) * K + (1 - np.cos(th)) * K @ K


def quat_xyzw(R):
    w = np.sqrt(max(0.0, 1 + np.trace(R))) / 2
    x = np.copysign(np.sqrt(max(0.0, 1 + R[0, 0] - R[1, 1] - R[2, 2])) / 2, R[2, 1] - R[1, 2])
    y = np.copysign(np.sqrt(max(0.0, 1 - R[0, 0] + R[1, 1] - R[2, 2])) / 2, R[0, 2] - R[2, 0])
    z = np.copysign(np.sqrt(max(0.0, 1 - R[0, 0] - R[1, 1] + R[2, 2])) / 2, R[1, 0] - R[0, 1])
    return x, y, z, w


def write_pair(directory):
    rng = np.random.default_rng(7)
    G_R, G_t = exp_so3(np.array([0.1, -0.2, 0.9])), np.array([100.0, -50.0, 3.0])
    drift, rdrift = np.zeros(3), np.zeros(3)
    with open(os.path.join(directory, "ref.tum"), "w") as ref, \
            open(os.path.join(directory, "est.tum"), "w") as est:
        for i in range(1500):
            t, a = 1.6e9 + 0.1 * i, 0.004 * i
            p = np.array([80 * np.cos(a), 50 * np.sin(2 * a), 3 * np.sin(5 * a)])
            R = exp_so3(np.array([0, 0, a + 1.0])) @ exp_so3(np.array([0.05 * np.sin(3 * a), 0.03, 0]))
            ref.write("%.9f %r %r %r %r %r %r %r\n" % (t, *p, *quat_xyzw(R)))
            drift += rng.normal(0, 0.01, 3)
            rdrift += rng.normal(0, 0.0005, 3)
            if i % 37 == 5:
                continue  # a missing estimate
            pe, Re = G_R @ (1.02 * p + drift) + G_t, G_R @ exp_so3(rdrift) @ R
            te = t + rng.uniform(-0.004, 0.004) - 0.25  # clock 0.25 s behind, jitter
            est.write("%.9f %r %r %r %r %r %r %r\n" % (te, *pe, *quat_xyzw(Re)))


def load(path):
    d = np.loadtxt(path)
    poses = []
    for row in d:
        x, y, z, w = row[4:8] / np.linalg.norm(row[4:8])
        T = np.eye(4)
        T[:3, :3] = [[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]]
        T[:3, 3] = row[1:4]
        poses.append(T)
    return d[:, 0], poses


def matching_time_indices(stamps_1, stamps_2, max_diff, offset_2):
    stamps_2 = stamps_2 + offset_2
    indices = []
    for stamp in stamps_1:
        diffs = np.abs(stamps_2 - stamp)
        k = int(np.argmin(diffs))
        if diffs[k] <= max_diff:
            indices.append(k)
    return indices


def associate(t1, p1, t2, p2, max_diff, offset_2):  # traj_1 = reference, traj_2 = estimate
    snd_longer = len(t2) > len(t1)
    tl, pl = (t2, p2) if snd_longer else (t1, p1)
    ts, ps = (t1, p1) if snd_longer else (t2, p2)
    ids = matching_time_indices(ts, tl, max_diff, offset_2 if snd_longer else -offset_2)
    tl, pl = tl[ids], [pl[i] for i in ids]
    ids = matching_time_indices(tl, ts, max_diff, -offset_2 if snd_longer else offset_2)
    ps = [ps[i] for i in ids]
    return (ps, pl) if snd_longer else (pl, ps)  # (reference, estimate)


def umeyama(x, y, with_scale):
    m, n = x.shape
    mean_x, mean_y = x.mean(axis=1), y.mean(axis=1)
    sigma_x = 1.0 / n * (np.linalg.norm(x - mean_x[:, np.newaxis]) ** 2)
    cov = sum(np.outer(y[:, i] - mean_y, x[:, i] - mean_x) for i in range(n)) / n
    u, d, v = np.linalg.svd(cov)
    s = np.eye(m)
    if np.linalg.det(u) * np.linalg.det(v) < 0.0:
        s[m - 1, m - 1] = -1
    r = u @ s @ v
    c = 1 / sigma_x * np.trace(np.diag(d) @ s) if with_scale else 1.0
    return r, mean_y - c * r @ mean_x, c


def angle_deg(R):
    return np.degrees(np.arccos(np.clip((np.trace(R) - 1) / 2, -1, 1)))


def stats(e):
    e = np.asarray(e)
    return {"rmse": np.sqrt(np.mean(e ** 2)), "mean": np.mean(e), "median": np.median(e),
            "std": np.std(e), "min": np.min(e), "max": np.max(e), "count": len(e)}


def evo_numbers(directory, align, offset, delta_m):
    tr, pr = load(os.path.join(directory, "ref.tum"))
    te, pe = load(os.path.join(directory, "est.tum"))
    pr, pe = associate(tr, pr, te, pe, 0.01, offset)
    pe_raw = pe
    if align in ("se3", "sim3"):
        r, t, c = umeyama(np.array([p[:3, 3] for p in pe]).T, np.array([p[:3, 3] for p in pr]).T,
                          align == "sim3")
        S = np.eye(4)
        S[:3, :3], S[:3, 3] = r, t
        scaled = []
        for p in pe:
            q = p.copy()
            q[:3, 3] *= c
            scaled.append(S @ q)
        pe = scaled
    elif align == "origin":
        S = pr[0] @ inv(pe[0])
        pe = [S @ p for p in pe]
    out = {"pairs": len(pe),
           "ape_t": stats([np.linalg.norm(a[:3, 3] - b[:3, 3]) for a, b in zip(pe, pr)]),
           "ape_r": stats([angle_deg((inv(a) @ b)[:3, :3]) for a, b in zip(pe, pr)])}

    def rpe(pairs):
        E = [inv(inv(pr[i]) @ pr[j]) @ (inv(pe[i]) @ pe[j]) for i, j in pairs]
        return (stats([np.linalg.norm(e[:3, 3]) for e in E]), stats([angle_deg(e[:3, :3]) for e in E]))

    # KITTI devkit calcSequenceErrors (double instead of float) and end-point drift.
    dist = [0.0]
    for a, b in zip(pr, pr[1:]):
        dist.append(dist[-1] + np.linalg.norm(b[:3, 3] - a[:3, 3]))
    t_err, r_err = [], []
    for first in range(0, len(pr), 10):
        for length in range(100, 900, 100):
            last = next((i for i in range(first, len(pr)) if dist[i] > dist[first] + length), -1)
            if last == -1:
                continue
            E = inv(inv(pe[first]) @ pe[last]) @ (inv(pr[first]) @ pr[last])
            t_err.append(np.linalg.norm(E[:3, 3]) / length)
            r_err.append(np.arccos(max(min(0.5 * (np.trace(E[:3, :3]) - 1), 1.0), -1.0)) / length)
    out["kitti"] = {"translation_error_percent": np.mean(t_err) * 100,
                    "rotation_error_deg_per_100m": np.mean(r_err) * 180 / np.pi * 100,
                    "segments": len(t_err)}
    out["drift"] = {"drift_m": np.linalg.norm((pr[0] @ inv(pe_raw[0]) @ pe_raw[-1])[:3, 3] - pr[-1][:3, 3]),
                    "reference_path_length_m": dist[-1]}
    ids = np.arange(0, len(pe), 1)
    out["rpe_f_t"], out["rpe_f_r"] = rpe(list(zip(ids, ids[1:])))
    ids, previous, path = [], pe[0], 0.0
    for i, p in enumerate(pe):
        path += np.linalg.norm(p[:3, 3] - previous[:3, 3])
        previous = p
        if path >= delta_m:
            ids.append(i)
            path = 0.0
    out["rpe_m_t"], out["rpe_m_r"] = rpe(list(zip(ids, ids[1:])))
    return out


def taiga_numbers(executable, directory, align, offset, delta_m):
    result = subprocess.run(
        [executable, "eval", "--est", os.path.join(directory, "est.tum"), "--ref",
         os.path.join(directory, "ref.tum"), "--align", align, "--t-offset", str(offset),
         "--rotation", "--rpe-delta-m", str(delta_m), "--json"],
        check=True, capture_output=True, text=True)
    j = json.loads(result.stdout)
    return {"pairs": j["association"]["pairs"],
            "ape_t": j["ape"]["translation_m"], "ape_r": j["ape"]["rotation_deg"],
            "rpe_f_t": j["rpe"][0]["translation_m"], "rpe_f_r": j["rpe"][0]["rotation_deg"],
            "rpe_m_t": j["rpe"][1]["translation_m"], "rpe_m_r": j["rpe"][1]["rotation_deg"],
            "kitti": j["kitti"], "drift": j["drift"]}


def main():
    executable = sys.argv[1]
    failures = 0
    with tempfile.TemporaryDirectory() as directory:
        write_pair(directory)
        for align in ("se3", "sim3", "origin", "none"):
            expected = evo_numbers(directory, align, 0.25, 10.0)
            actual = taiga_numbers(executable, directory, align, 0.25, 10.0)
            if expected["pairs"] != actual["pairs"]:
                print(f"{align}: pairs {actual['pairs']} != {expected['pairs']}")
                failures += 1
            for key in expected:
                if key == "pairs":
                    continue
                # Angles: arccos here vs the rotation's log in taiga; 1e-7 deg covers arccos'
                # conditioning near 0. Translations agree to 1e-9 relative.
                tolerance_abs = 1e-7 if key.endswith("_r") or key == "kitti" else 1e-12
                for stat, value in expected[key].items():
                    got = actual[key][stat]
                    if not np.isclose(got, value, rtol=1e-9, atol=tolerance_abs):
                        print(f"{align} {key} {stat}: taiga {got!r}, evo definition {value!r}")
                        failures += 1
            print(f"{align}: {expected['pairs']} pairs, APE rmse {expected['ape_t']['rmse']:.6f} m, "
                  f"RPE(10 m) pairs {expected['rpe_m_t']['count']}, "
                  f"KITTI {expected['kitti']['translation_error_percent']:.4f} % over "
                  f"{expected['kitti']['segments']} segments: "
                  + ("agree" if failures == 0 else "DISAGREE"))
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
