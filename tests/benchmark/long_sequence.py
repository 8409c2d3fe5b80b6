#!/usr/bin/env python3
"""A long time-lapse at the tiniest size: the default style at --size 1 (1^2
faces, a 2 x 1 latlong, every output on), the Sun stepping from 0 to 89 deg
over N frames. Prints, per N, the wall time, the peak RSS, the memory the
frames after the first tenth added per frame (sampled from /proc while the
bake runs), the folder's size and the progress manifests' writes (from
timings.json). Out of ctest; docs/performance.md "Long sequences" quotes it.

  python3 tests/benchmark/long_sequence.py --frames 100,1000,10000
"""
import argparse
import json
import os
import subprocess
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def schedule_text(frames):
    step = 89.0 / (frames - 1)
    return ("[schedule]\nsun = { elevation_deg = { start = 0, end = 89, step = %.17g }, azimuth_deg = 135 }\n"
            % step)


def rss_kib(pid):
    try:
        with open(f"/proc/{pid}/status") as f:
            for line in f:
                if line.startswith("VmRSS:"):
                    return int(line.split()[1])
    except OSError:
        return None
    return None


def folder_bytes(path):
    return sum(os.path.getsize(os.path.join(path, n)) for n in os.listdir(path))


def frames_done(path, basename="sky_px."):
    try:
        return sum(1 for n in os.listdir(path) if n.startswith(basename) and n.endswith(".exr"))
    except OSError:
        return 0


def run(binary, frames, tmp, style):
    sched = os.path.join(tmp, f"sun_{frames}.toml")
    with open(sched, "w") as f:
        f.write(schedule_text(frames))
    out = os.path.join(tmp, f"out_{frames}")
    t0 = time.perf_counter()
    proc = subprocess.Popen([binary, "bake", style, "--schedule", sched, "--size", "1", "-q", "--out", out],
                            stdout=subprocess.DEVNULL, cwd=ROOT)
    samples = []  # (frames done, RSS KiB)
    peak = 0
    while proc.poll() is None:
        time.sleep(0.5)
        rss = rss_kib(proc.pid)
        if rss is not None:
            peak = max(peak, rss)
            samples.append((frames_done(out), rss))
    seconds = time.perf_counter() - t0
    if proc.returncode != 0:
        raise SystemExit(f"skybake exited with {proc.returncode} for {frames} frames")
    # Memory added per frame from the first tenth of the frames to the last sample.
    tenth = [s for s in samples if s[0] >= frames // 10]
    per_frame = None
    if len(tenth) >= 2 and tenth[-1][0] > tenth[0][0]:
        per_frame = (tenth[-1][1] - tenth[0][1]) / (tenth[-1][0] - tenth[0][0])
    with open(os.path.join(out, "timings.json")) as f:
        timings = json.load(f)
    manifest = os.path.getsize(os.path.join(out, "manifest.json"))
    return {"frames": frames, "seconds": seconds, "peak_mib": peak / 1024.0, "per_frame_kib": per_frame,
            "folder_mb": folder_bytes(out) / 1e6, "manifest_writes": timings["manifest_writes"],
            "manifest_ratio": timings["manifest_bytes_written"] / manifest}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--binary", default=os.path.join(ROOT, "build", "skybake"))
    ap.add_argument("--style", default=os.path.join(ROOT, "configs", "default.toml"))
    ap.add_argument("--frames", default="100,1000,10000", help="frame counts, comma separated")
    args = ap.parse_args()
    print(os.popen("uptime").read().strip())
    with tempfile.TemporaryDirectory() as tmp:
        for n in [int(x) for x in args.frames.split(",")]:
            r = run(args.binary, n, tmp, args.style)
            per = "n/a" if r["per_frame_kib"] is None else f"{r['per_frame_kib']:.1f} KiB"
            print(f"{r['frames']:>6} frames: {r['seconds']:.1f} s ({1000 * r['seconds'] / n:.1f} ms a frame), "
                  f"peak RSS {r['peak_mib']:.0f} MiB, {per} more a frame after the first tenth, "
                  f"folder {r['folder_mb']:.1f} MB, {r['manifest_writes']} progress manifests "
                  f"({r['manifest_ratio']:.1f}x the final one)", flush=True)
            subprocess.run(["rm", "-rf", os.path.join(tmp, f"out_{n}")], check=True)
    print(os.popen("uptime").read().strip())


if __name__ == "__main__":
    main()
