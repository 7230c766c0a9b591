#!/usr/bin/env python3
"""Receives taiga's pose stream (live.pose_udp) and writes one line per datagram,
"RECEIVE_UNIX_S JSON", until no datagram came for IDLE_S seconds.
Usage: bench/pose_listener.py PORT OUT.txt [IDLE_S]"""
import socket
import sys
import time

port, out = int(sys.argv[1]), sys.argv[2]
idle_s = float(sys.argv[3]) if len(sys.argv) > 3 else 10.0
receiver = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
receiver.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 8 << 20)
receiver.bind(("127.0.0.1", port))
receiver.settimeout(idle_s)
with open(out, "w") as f:
    try:
        while True:
            data = receiver.recv(65536)
            f.write(f"{time.time():.6f} {data.decode()}")
    except socket.timeout:
        pass
