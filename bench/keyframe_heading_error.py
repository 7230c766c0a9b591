#!/usr/bin/python3
"""How much a run's keyframe headings wander against the simulator's truth.

The keyframes' poses (RUN/keyframes/poses.tum) are compared with groundtruth.tum at the same
times, after the rigid alignment of the positions (Umeyama, SE(3)); the heading error of each is
the angle about the vertical between the estimated and the true body x axis, less its mean (a
constant heading offset is the alignment's, not the map's). Its spread is what smears a far
stem's views from keyframes along the walk: 0.1 deg is 2 cm at 12 m.

  bench/keyframe_heading_error.py SIM_DIR RUN_DIR       prints std, min and max in deg
"""
import sys
import numpy as np
from scipy.spatial.transform import Rotation, Slerp


def main():
    sim, run = sys.argv[1], sys.argv[2]
    keyframes = np.loadtxt(f"{run}/keyframes/poses.tum")
    truth = np.loadtxt(f"{sim}/groundtruth.tum")
    # A rig with a clock offset can stamp its last keyframe after the truth ends: not compared.
    keyframes = keyframes[(keyframes[:, 0] >= truth[0, 0]) & (keyframes[:, 0] <= truth[-1, 0])]
    t = keyframes[:, 0]
    R_true = Slerp(truth[:, 0], Rotation.from_quat(truth[:, 4:8]))(t)
    p_true = np.stack([np.interp(t, truth[:, 0], truth[:, i]) for i in (1, 2, 3)], 1)
    p_est = keyframes[:, 1:4]
    m_est, m_true = p_est.mean(0), p_true.mean(0)
    u, _, vt = np.linalg.svd((p_est - m_est).T @ (p_true - m_true))
    R_align = u @ np.diag([1.0, 1.0, np.sign(np.linalg.det(u @ vt))]) @ vt
    x_true = (Rotation.from_matrix(R_align) * R_true).apply([1.0, 0.0, 0.0])
    x_est = Rotation.from_quat(keyframes[:, 4:8]).apply([1.0, 0.0, 0.0])
    cross = x_true[:, 0] * x_est[:, 1] - x_true[:, 1] * x_est[:, 0]
    error_deg = np.degrees(np.arctan2(cross, (x_true[:, :2] * x_est[:, :2]).sum(1)))
    error_deg -= error_deg.mean()
    print(f"keyframes {len(t)} heading error std {error_deg.std():.3f} deg, "
          f"min {error_deg.min():.3f}, max {error_deg.max():.3f}")


main()
