#!/usr/bin/env python3
"""Writes the shipped cutterhead layouts (layouts/*.json) from the numbers
that layouts/README.md explains. Re-run after changing a number here:

    python3 tools/head_layouts.py
"""
import json
import math
import os

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
GOLDEN = 180.0 * (3.0 - math.sqrt(5.0))  # 137.507... deg


def angle(k):
    """Disc k's angle on the head: successive tracks a golden angle apart,
    so no two neighbouring tracks sit side by side and the radial loads
    spread round the head."""
    return round((k * GOLDEN) % 360.0, 3)


def gauge(n, first, last, theta0, theta1):
    """n gauge discs, tips evenly from track `first` to `last` (m) in the
    face plane (setback 0: the corner profile is flattened so that a run from
    flat rock engages every disc at once), tilt rising from theta0 to theta1
    (deg); returns (track, tilt, setback, spacing)."""
    step = (last - first) / (n - 1)
    return [(round(first + step * k, 4), round(theta0 + (theta1 - theta0) * k / (n - 1), 2),
             0.0, round(step, 4)) for k in range(n)]


def write(name, layout):
    path = os.path.join(ROOT, "layouts", name + ".json")
    with open(path, "w") as f:
        json.dump(layout, f, indent=1)
        f.write("\n")
    print(path, len(layout["cutters"]), "cutters")


def reference():
    # 9.72 m bore, 56 x 19 in discs, 85 mm face spacing (the numbers)
    bore_r = 9.72 / 2
    cutters = []
    face = 48
    for k in range(face):
        cutters.append({"track": round(0.06 + 0.085 * k, 4), "angleDeg": angle(k),
                        "tiltDeg": 0, "setback": 0.0, "spacing": 0.085})
    last_face = cutters[-1]["track"]
    for j, (tr, tilt, sb, step) in enumerate(gauge(8, last_face + 0.1, bore_r - 0.03, 8.0, 60.0)):
        cutters.append({"track": tr, "angleDeg": angle(face + j), "tiltDeg": tilt,
                        "setback": sb, "spacing": step})
    write("reference-9.72m", {
        "name": "reference_972",
        "description": "9.72 m hard-rock TBM head: 56 x 19 in (483 mm) discs, 48 face discs at 85 mm, "
                       "8 gauge discs tilted 8-60 deg (corner flattened into the face plane); bored at ~3 rpm. See layouts/README.md.",
        "disc": {"radius": 0.2413, "tipWidth": 0.019, "tipRadius": 0.0127},
        "cutters": cutters,
    })


def demo():
    cutters = []
    tracks = [0.07, 0.15, 0.23, 0.31, 0.39, 0.47]
    for k, t in enumerate(tracks):
        cutters.append({"track": t, "angleDeg": angle(k), "tiltDeg": 0, "setback": 0.0, "spacing": 0.08})
    for j, (t, tilt, sb) in enumerate([(0.535, 20.0, 0.0), (0.575, 45.0, 0.0)]):
        cutters.append({"track": t, "angleDeg": angle(6 + j), "tiltDeg": tilt, "setback": sb,
                        "spacing": 0.06})
    write("demo-1.2m", {
        "name": "head_demo",
        "description": "Small demo head for quick runs: 1.2 m bore, 8 x 17 in discs (6 face at 80 mm, "
                       "2 tilted gauge). Not a real machine.",
        "disc": {"radius": 0.2159, "tipWidth": 0.013, "tipRadius": 0.0127},
        "cutters": cutters,
    })


if __name__ == "__main__":
    reference()
    demo()
