#!/usr/bin/env python3
"""Input CSV for kerf.fmu (one disc, R = 0.2159 m): the disc rolls along x at
`v` m/s (wy = v/R) while its tip starts `d0` below the flat face (rock.z0 = 0)
and moves with `vz` m/s (negative: plunging), rows every 1 ms for 0.2 s.
Used with z_sensitivity.py to show that kerf issue K1 (docs/hosts.md) is not
head-specific.

usage: make_plunge_csv.py OUT.csv [v=0.157] [d0=1e-4] [vz=-1e-3]
(0.157 m/s is disc 2's rim speed on the demo head at 10 rpm.)
"""
import sys

R = 0.2159
out = sys.argv[1]
v = float(sys.argv[2]) if len(sys.argv) > 2 else 0.157
d0 = float(sys.argv[3]) if len(sys.argv) > 3 else 1e-4
vz = float(sys.argv[4]) if len(sys.argv) > 4 else -1e-3
names = ["x", "y", "z", "yaw", "pitch", "roll", "vx", "vy", "vz", "wx", "wy", "wz"]
with open(out, "w") as f:
    f.write(",".join(["time"] + names) + "\n")
    for i in range(201):
        t = round(i * 1e-3, 12)
        val = {"x": v * t, "z": R - d0 + vz * t, "vx": v, "vz": vz, "wy": v / R}
        f.write(",".join(repr(x) for x in [t] + [val.get(k, 0.0) for k in names]) + "\n")
