#!/usr/bin/env python3
"""Time two skybake binaries on the same bakes, interleaved: the default style
at a twilight sun (-3 deg) and a daylight sun (35 deg), whole process, the
sky-view LUT pass and every GPU pass of the frame together (from
timings.json). Prints medians and after/before ratios.

  python3 tests/benchmark/twilight_timing.py --before OLD/skybake --after build/skybake --runs 5
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
    ap.add_argument("--before", required=True, help="the previous build's skybake")
    ap.add_argument("--after", default=os.path.join(ROOT, "build", "skybake"))
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--suns", default="-3,35", help="sun elevations in deg, comma separated")
    args = ap.parse_args()
    bins = {"before": args.before, "after": args.after}
    suns = [float(s) for s in args.suns.split(",")]
    res = {}
    with tempfile.TemporaryDirectory() as tmp:
        for _ in range(args.runs):
            for sun in suns:
                for name, binary in bins.items():
                    out = os.path.join(tmp, f"{name}_{sun}")
                    t0 = time.perf_counter()
                    subprocess.run([binary, "bake", os.path.join(ROOT, "configs", "default.toml"), "--out", out,
                                    "--force", "-q", "--set", f"sun.elevation_deg={sun}"], check=True, cwd=ROOT)
                    seconds = time.perf_counter() - t0
                    with open(os.path.join(out, "timings.json")) as f:
                        passes = json.load(f)["frames"][0]["gpu_passes"]
                    lut_ms = sum(p["gpu_ms"] for p in passes if p["name"] == "sky-view LUT")
                    gpu_ms = sum(p["gpu_ms"] for p in passes)
                    res.setdefault((name, sun), []).append((seconds, lut_ms, gpu_ms))
    for sun in suns:
        med = {n: statistics.median(x[0] for x in res[(n, sun)]) for n in bins}
        lut = {n: statistics.median(x[1] for x in res[(n, sun)]) for n in bins}
        gpu = {n: statistics.median(x[2] for x in res[(n, sun)]) for n in bins}
        for n in bins:
            runs = [x[0] for x in res[(n, sun)]]
            print(f"sun {sun:+.0f} deg {n:6s}: whole bake median {med[n]:.3f} s ({min(runs):.3f}-{max(runs):.3f}), "
                  f"sky-view LUT pass median {lut[n]:.1f} ms, every GPU pass {gpu[n]:.1f} ms")
        print(f"sun {sun:+.0f} deg after/before: whole bake {med['after'] / med['before']:.3f}, "
              f"sky-view LUT pass {lut['after'] / lut['before']:.3f}, every GPU pass {gpu['after'] / gpu['before']:.3f}")
    print(os.popen("uptime").read().strip())


if __name__ == "__main__":
    main()
