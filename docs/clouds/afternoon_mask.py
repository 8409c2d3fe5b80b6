#!/usr/bin/env python3
"""Writes configs/styles/afternoon_buildup_mask.png, the density mask of
configs/styles/afternoon_buildup.toml: 4 layers of 64 x 64 cells stacked top
to bottom (64 x 256 texels), from almost clear (layer 0) to very cloudy
(layer 3). R = humidity, G = readiness for phase transition, B = extinction
probability (cloud_formation.h). The same tiling pattern of warm, humid
patches in every layer (where thermals would rise), its humidity and
readiness growing and its extinction falling from layer to layer.

    python3 docs/clouds/afternoon_mask.py   # needs oiiotool (OpenImageIO) for the PNG
"""
import math
import os
import random
import subprocess
import tempfile

N, LAYERS = 64, 4
random.seed(5)
# Patch centres (cell units) and radii on the tiling 64 x 64 lattice.
patches = [(random.uniform(0, N), random.uniform(0, N), random.uniform(4, 9)) for _ in range(14)]


def patchiness(x, y):
    v = 0.0
    for cx, cy, r in patches:
        dx = min(abs(x - cx), N - abs(x - cx))  # wrapping distance: the mask tiles
        dy = min(abs(y - cy), N - abs(y - cy))
        v = max(v, math.exp(-(dx * dx + dy * dy) / (2 * r * r)))
    return v


rows = []
for layer in range(LAYERS):
    wet = (layer + 1) / LAYERS  # 0.25, 0.5, 0.75, 1
    for y in range(N):
        row = bytearray()
        for x in range(N):
            p = patchiness(x + 0.5, y + 0.5)
            r = min(1.0, wet * (0.15 + 0.85 * p))
            g = min(1.0, wet * p)
            b = max(0.0, 1.0 - wet * (0.4 + 0.6 * p))
            row += bytes(int(round(255 * c)) for c in (r, g, b))
        rows.append(bytes(row))
out = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "configs", "styles",
                   "afternoon_buildup_mask.png")
with tempfile.TemporaryDirectory() as tmp:
    ppm = os.path.join(tmp, "mask.ppm")
    with open(ppm, "wb") as f:
        f.write(b"P6\n%d %d\n255\n" % (N, N * LAYERS))
        for row in rows:
            f.write(row)
    subprocess.run(["oiiotool", ppm, "-o", os.path.normpath(out)], check=True)
print(os.path.normpath(out))
