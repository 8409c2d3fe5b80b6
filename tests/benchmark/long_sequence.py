#!/usr/bin/env python3
"""A long time-lapse at the tiniest size: the default style at --size 1 (1^2
faces, a 2 x 1 latlong, every output on), the Sun stepping from 0 to 89 deg
over N frames. Prints, per N, the wall time, the peak RSS, the memory the
frames after the first tenth added per frame (sampled from /proc while the
bake runs: to its end, and while frames are baked), the folder's size and
the progress manifests' writes (from timings.json). Out of ctest;
docs/performance_history.md "Long sequences" quotes it.

  python3 tests/benchmark/long_sequence.py --frames 100,1000,10000 \
      --set quality.sky_view_lut=false

--set passes settings to every bake (the same for each frame count, so the
lines compare); --schedule bakes that schedule instead of the Sun's ramp
(its frame count is the schedule's), e.g. drifting clouds:

  python3 tests/benchmark/long_sequence.py --style configs/benchmark/w3.toml \
      --schedule configs/schedules/day.toml --size 8
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


def run(args, frames, tmp):
    sched = args.schedule
    if not sched:
        sched = os.path.join(tmp, f"sun_{frames}.toml")
        with open(sched, "w") as f:
            f.write(schedule_text(frames))
    out = os.path.join(tmp, f"out_{frames}")
    command = [args.binary, "bake", args.style, "--schedule", sched, "--size", str(args.size), "-q", "--out", out]
    for setting in args.set:
        command += ["--set", setting]
    t0 = time.perf_counter()
    proc = subprocess.Popen(command, stdout=subprocess.DEVNULL, cwd=ROOT)
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
    with open(os.path.join(out, "timings.json")) as f:
        timings = json.load(f)
    frames = len(timings["frames"])
    # Memory added per frame from the first tenth of the frames to the last
    # sample (the bake's end, its glTF scene, included), and to the last
    # sample before the last frame's files (the frames alone).
    tenth = [s for s in samples if s[0] >= frames // 10]
    per_frame = during = None
    if len(tenth) >= 2 and tenth[-1][0] > tenth[0][0]:
        per_frame = (tenth[-1][1] - tenth[0][1]) / (tenth[-1][0] - tenth[0][0])
    before_end = [s for s in tenth if s[0] < frames]
    if len(before_end) >= 2 and before_end[-1][0] > before_end[0][0]:
        during = (before_end[-1][1] - before_end[0][1]) / (before_end[-1][0] - before_end[0][0])
    manifest = os.path.getsize(os.path.join(out, "manifest.json"))
    return {"frames": frames, "seconds": seconds, "peak_mib": peak / 1024.0, "per_frame_kib": per_frame, "during_kib": during,
            "folder_mb": folder_bytes(out) / 1e6, "manifest_writes": timings["manifest_writes"],
            "manifest_ratio": timings["manifest_bytes_written"] / manifest}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--binary", default=os.path.join(ROOT, "build", "skybake"))
    ap.add_argument("--style", default=os.path.join(ROOT, "configs", "default.toml"))
    ap.add_argument("--frames", default="100,1000,10000", help="frame counts, comma separated")
    ap.add_argument("--size", type=int, default=1, help="--size of the bakes (cube face edge, texels)")
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE", help="a setting for every bake")
    ap.add_argument("--schedule", default="", help="bake this schedule (once) instead of the Sun's ramp")
    args = ap.parse_args()
    print(os.popen("uptime").read().strip())
    print(" ".join(["settings: --size", str(args.size)] + [f"--set {x}" for x in args.set]), flush=True)
    with tempfile.TemporaryDirectory() as tmp:
        for n in [int(x) for x in args.frames.split(",")] if not args.schedule else [0]:
            r = run(args, n, tmp)
            per = "n/a" if r["per_frame_kib"] is None else f"{r['per_frame_kib']:.1f} KiB"
            during = "n/a" if r["during_kib"] is None else f"{r['during_kib']:.1f} KiB"
            print(f"{r['frames']:>6} frames: {r['seconds']:.1f} s ({1000 * r['seconds'] / r['frames']:.1f} ms a frame), "
                  f"peak RSS {r['peak_mib']:.0f} MiB, {per} more a frame after the first tenth ({during} while frames "
                  f"are baked), "
                  f"folder {r['folder_mb']:.1f} MB, {r['manifest_writes']} progress manifests "
                  f"({r['manifest_ratio']:.1f}x the final one)", flush=True)
            subprocess.run(["rm", "-rf", os.path.join(tmp, f"out_{n}")], check=True)
    print(os.popen("uptime").read().strip())


if __name__ == "__main__":
    main()
