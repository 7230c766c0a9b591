#!/usr/bin/python3
"""The errors of a `taiga calibrate` result against the simulator's true rig.

Usage: self_calibration_errors.py CALIBRATION.json RIG_TRUTH.yaml
Prints: offset error (ms), offset 1-sigma (ms), rotation error (deg), largest rotation 1-sigma
(deg), comma separated. The true offset is rig_truth.yaml's (it holds at the recording's start;
the clock drift moves it by at most drift x stretch).
"""
import json
import sys

import numpy as np
import yaml
from scipy.spatial.transform import Rotation


def main(calibration_path, truth_path):
    c = json.load(open(calibration_path))
    truth = yaml.safe_load(open(truth_path))["rig"]
    offset_error_ms = 1e3 * (c["time_offset"]["estimated_s"] - truth["lidar_time_offset_s"])
    R_est = Rotation.from_quat(c["rotation"]["estimated_quaternion_xyzw"])
    R_true = Rotation.from_quat(truth["T_body_lidar"]["quaternion_xyzw"])
    rotation_error_deg = np.degrees((R_true.inv() * R_est).magnitude())
    print(f"{offset_error_ms:.3f},{1e3 * c['time_offset']['sigma_s']:.3f},"
          f"{rotation_error_deg:.4f},{max(c['rotation']['sigma_deg']):.4f}")


if __name__ == "__main__":
    main(*sys.argv[1:3])
