#!/usr/bin/env python3
"""What the spectral mode costs per wavelength bin: W1 (configs/benchmark/w1.toml)
baked with quality.wavelengths = 3 (the 680/550/440 nm path) and 4, 8, 16, 48
bins, interleaved, whole process by wall clock and the GPU passes' sum (from
timings.json). Prints medians, the ratio to 3 wavelengths, and the cost per bin
from a least-squares line through the spectral counts.

  python3 tests/benchmark/spectral_timing.py --runs 3
"""
import argparse
import json
import os
import statistics
import subprocess
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--binary", default=os.path.join(ROOT, "build", "skybake"))
    ap.add_argument("--style", default=os.path.join(ROOT, "configs", "benchmark", "w1.toml"))
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--counts", default="3,4,8,16,48")
    args = ap.parse_args()
    counts = [int(c) for c in args.counts.split(",")]
    res = {}
    print(os.popen("uptime").read().strip())
    with tempfile.TemporaryDirectory() as tmp:
        for _ in range(args.runs):
            for n in counts:
                out = os.path.join(tmp, f"n{n}")
                t0 = time.perf_counter()
                subprocess.run([args.binary, "bake", args.style, "--out", out, "--force", "-q",
                                "--set", f"quality.wavelengths={n}"], check=True, cwd=ROOT)
                seconds = time.perf_counter() - t0
                with open(os.path.join(out, "timings.json")) as f:
                    t = json.load(f)
                gpu_ms = sum(p["gpu_ms"] for p in t["frames"][0]["gpu_passes"])
                gpu_ms += sum(p["gpu_ms"] for p in t.get("gpu_passes", []))
                res.setdefault(n, []).append((seconds, gpu_ms))
    med = {n: statistics.median(x[0] for x in res[n]) for n in counts}
    gpu = {n: statistics.median(x[1] for x in res[n]) for n in counts}
    base = counts[0]
    print("| wavelengths | renders (groups of 3) | whole bake s (median) | x 3 wavelengths | GPU passes ms |")
    print("| ---: | ---: | ---: | ---: | ---: |")
    for n in counts:
        groups = 1 if n == 3 else (n + 2) // 3
        print(f"| {n} | {groups} | {med[n]:.2f} | {med[n] / med[base]:.2f} | {gpu[n]:.0f} |")
    spectral = [n for n in counts if n > 3]
    if len(spectral) >= 2:
        xs = [(n + 2) // 3 for n in spectral]
        ys = [med[n] for n in spectral]
        mx, my = statistics.mean(xs), statistics.mean(ys)
        slope = sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sum((x - mx) ** 2 for x in xs)
        print(f"per group of 3 bins: {slope:.3f} s, per bin {slope / 3:.3f} s, intercept {my - slope * mx:.2f} s")
    print(os.popen("uptime").read().strip())


if __name__ == "__main__":
    main()
