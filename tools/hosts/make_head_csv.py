#!/usr/bin/env python3
"""Input CSV for the head-drive cutterhead FMU: the head turns at `rpm` about
rock z and advances `p_rev` per revolution (boring: z decreasing, wz > 0),
from the rest pose at t = 0 (z = 0: discs at the flat face), rows every `h`
up to `stop`. Columns: time, yaw, z, wz, vz (the other inputs stay at 0).

usage: make_head_csv.py OUT.csv [stop=0.2] [h=1e-3] [rpm=10] [p_rev=0.006]
(10 rpm and 6 mm/rev are scripts/head's defaults for the 1.2 m demo head.)
"""
import math
import sys

out = sys.argv[1]
stop = float(sys.argv[2]) if len(sys.argv) > 2 else 0.2
h = float(sys.argv[3]) if len(sys.argv) > 3 else 1e-3
rpm = float(sys.argv[4]) if len(sys.argv) > 4 else 10.0
p_rev = float(sys.argv[5]) if len(sys.argv) > 5 else 0.006
w = rpm * 2 * math.pi / 60
vz = -p_rev * w / (2 * math.pi)
n = int(round(stop / h))
with open(out, "w") as f:
    names = ["x", "y", "z", "yaw", "pitch", "roll", "vx", "vy", "vz", "wx", "wy", "wz"]
    f.write(",".join(["time"] + names) + "\n")
    for i in range(n + 1):
        t = round(i * h, 12)
        val = {"yaw": w * t, "z": vz * t, "wz": w, "vz": vz}
        f.write(",".join(repr(v) for v in [t] + [val.get(k, 0.0) for k in names]) + "\n")
