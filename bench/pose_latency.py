#!/usr/bin/env python3
"""Latency of taiga's pose stream (live.pose_udp) on a replayed capture, end to end: the time a
pose datagram was received minus the time `taiga replay` sent the packet that completed it (a
scan's last lidar packet, or the IMU sample's packet), from the capture time the pose carries and
the replay's start (its "first datagram sent at Unix time ..." line).

The scans before the odom frame is levelled are held by the SLAM system and published together
once it is (docs/architecture.md); they are left out: the scans that end before the first
IMU-rate pose (which begin only then), less a scan period.

Usage: bench/pose_latency.py POSES.txt REPLAY.log [RATE]
  POSES.txt: one line per datagram, "RECEIVE_UNIX_S JSON" (bench/live.sh writes it).
Valid for captures whose packets were sent at their stamps (taiga simulate with ideal realism:
no lidar time offset, no IMU stamp jitter)."""
import json
import statistics
import sys

poses, replay_log = sys.argv[1], sys.argv[2]
rate = float(sys.argv[3]) if len(sys.argv) > 3 else 1.0
words = [l for l in open(replay_log) if l.startswith("first datagram")][0].split()
start_unix, first_capture = float(words[6]), float(words[11])
received_poses = [(float(r), json.loads(t)) for r, t in (l.split(" ", 1) for l in open(poses))]
first_imu_s = min(p["t_s"] for _, p in received_poses if p["type"] == "imu")
latency = {"imu": [], "scan": []}
for received, pose in received_poses:
    if pose["t_s"] < first_imu_s - 0.1:
        continue
    sent = start_unix + (pose["t_s"] - first_capture) / rate
    latency[pose["type"]].append(1000.0 * (received - sent))
for kind, values in latency.items():
    values.sort()
    if values:
        p99 = values[min(len(values) - 1, round(0.99 * (len(values) - 1)))]
        print(f"{kind}: {len(values)} poses, latency ms p50 {statistics.median(values):.2f} "
              f"p99 {p99:.2f} max {values[-1]:.2f}")
