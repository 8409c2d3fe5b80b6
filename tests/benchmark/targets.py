#!/usr/bin/env python3
"""The speed targets of docs/performance.md (issue 51), in one session.

    python3 tests/benchmark/targets.py --before OLD/skybake [--after build/skybake]
        [--reps-w1 5] [--reps-w2 1] [--reps-blender-w1 3] [--no-blender] [--work DIR]
    python3 tests/benchmark/targets.py --smoke      # CI: one W1 of one build, the report's checks, no timing target

Runs, alternated (ABBA), so that a change of the machine's load falls on
both builds alike: W1 of each build, then W2 (the 96-frame day) of each,
then Blender 3.4 Cycles' Nishita sky (1 sample) on W1 and W2
(tests/benchmark/blender_sky.py), then the after build's W1 with its
persistent pipeline cache off and warm, alternated (the pipelines stage of
timings.json). Every figure is a median over runs of whole processes (wall
and CPU: user + system of the process and its children; peak resident
memory from wait4). Prints a markdown report: the ratios the targets name,
met or not, and whether both builds wrote the same bytes.

Never a timed test: the machine is shared, and its speed drifts; the
ratios of one session are the figures to compare.
"""
import argparse
import json
import os
import shutil
import statistics
import sys
import tempfile

from ab_speed import tree_digest
from performance import ROOT, run

W1 = ["configs/benchmark/w1.toml"]
W2 = W1 + ["--schedule", "configs/benchmark/w2.toml"]


def bake(binary, args, out, env=None):
    """One bake (progress lines kept in OUT.log: the twilight probe's line names the frames it left unmarched)."""
    wall, peak, cpu = run([binary, "bake", *args, "--out", out, "--force"], env=env, log=out + ".log")
    with open(os.path.join(out, "timings.json")) as f:
        timings = json.load(f)
    return {"wall": wall, "peak": peak, "cpu": cpu, "timings": timings}


def stage(timings, name):
    return sum(s["seconds"] for s in timings["stages"] if s["stage"] == name)


def alternate(label, builds, args, reps, work, env=None):
    """Runs every build `reps` times, the order swapped each time; returns {build: [runs]}."""
    runs = {name: [] for name in builds}
    for rep in range(reps):
        order = list(builds) if rep % 2 == 0 else list(reversed(list(builds)))
        for name in order:
            r = bake(builds[name], args, os.path.join(work, f"{label}-{name}"), env)
            r["load"] = os.getloadavg()[0]
            runs[name].append(r)
            sys.stderr.write(f"{label} {name} {rep + 1}/{reps}: {r['wall']:.2f} s wall, {r['cpu']:.2f} s CPU, "
                             f"{r['peak']:.0f} MiB, load {r['load']:.1f}\n")
    return runs


def med(runs, key):
    return statistics.median(r[key] for r in runs)


def frame_costs(w2_dir):
    """Per frame of a W2 bake: (Sun elevation, render seconds, GPU ms of its passes)."""
    with open(os.path.join(w2_dir, "manifest.json")) as f:
        elevation = {fr["frame"]: fr["sun"]["elevation_deg"] for fr in json.load(f)["frames"]}
    with open(os.path.join(w2_dir, "timings.json")) as f:
        frames = json.load(f)["frames"]
    return [(elevation[f["frame"]], f["render_s"], sum(p["gpu_ms"] for p in f["gpu_passes"]), f["frame"])
            for f in frames]


def twilight_ratio(costs, marched):
    """Median GPU time of the frames in `marched` (frame numbers) over that of the day frames (Sun above 3 deg)."""
    day = [g for e, _, g, _ in costs if e >= 3.0]
    twilight = [g for _, _, g, n in costs if n in marched]
    if not day or not twilight:
        return None, None, None
    return statistics.median(twilight) / statistics.median(day), statistics.median(twilight), statistics.median(day)


def marched_frames(w2_dir):
    """Frame numbers the twilight march ran in: the Sun between -21 and 3 deg (pass_plan.h, for W2's atmosphere),
    less the frames the bake's twilight probe left unmarched (its progress line, "no twilight march in frames")."""
    marched = {n for e, _, _, n in frame_costs(w2_dir) if -21.0 < e < 3.0}
    with open(w2_dir + ".log", errors="replace") as f:
        for line in f:
            if "no twilight march in frames " in line:
                runs = line.split("no twilight march in frames ")[1].split(" (")[0]
                for part in runs.split(", "):
                    a, _, b = part.partition("-")
                    marched -= set(range(int(a), int(b or a) + 1))
    return marched


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--before", help="the skybake to compare with (main's build)")
    ap.add_argument("--after", default=os.path.join(ROOT, "build", "skybake"))
    ap.add_argument("--reps-w1", type=int, default=5)
    ap.add_argument("--reps-w2", type=int, default=1)
    ap.add_argument("--reps-blender-w1", type=int, default=3)
    ap.add_argument("--reps-cache", type=int, default=5, help="W1 with the pipeline cache off / warm, each")
    ap.add_argument("--no-blender", action="store_true")
    ap.add_argument("--blender", default=shutil.which("blender"))
    ap.add_argument("--work", default=None)
    ap.add_argument("--smoke", action="store_true", help="one W1 of --after alone, no targets checked (CI)")
    args = ap.parse_args()
    work = args.work or tempfile.mkdtemp(prefix="skybake-targets-")
    os.makedirs(work, exist_ok=True)
    if args.smoke:
        cache = os.path.join(work, "cache")
        shutil.rmtree(cache, ignore_errors=True)  # a fresh cache: the first bake fills it
        for i in range(2):  # the second finds the first's pipeline cache
            r = bake(args.after, W1, os.path.join(work, "smoke"), env={"XDG_CACHE_HOME": cache})
            print(f"smoke W1 {i + 1}: {r['wall']:.2f} s wall, pipelines stage {stage(r['timings'], 'pipelines'):.3f} s")
        files = [f for f in os.listdir(os.path.join(cache, "skybake")) if f.startswith("pipelines-")]
        if len(files) != 1:
            raise SystemExit(f"expected one pipeline cache file in {cache}/skybake, found {files}")
        with open(os.path.join(work, "smoke.log"), errors="replace") as f:
            if "pipeline cache hit" not in f.read():
                raise SystemExit(f"the second bake did not report a pipeline cache hit ({work}/smoke.log)")
        return
    if not args.before:
        raise SystemExit("--before OLD/skybake is needed (or --smoke)")
    builds = {"before": os.path.abspath(args.before), "after": os.path.abspath(args.after)}
    load_start = os.getloadavg()
    w1 = alternate("W1", builds, W1, args.reps_w1, work)
    w2 = alternate("W2", builds, W2, args.reps_w2, work)
    same = {label: tree_digest(os.path.join(work, f"{label}-before")) == tree_digest(os.path.join(work, f"{label}-after"))
            for label in ("W1", "W2")}
    blender = {}
    if args.blender and not args.no_blender:
        script = os.path.join(ROOT, "tests", "benchmark", "blender_sky.py")
        out = os.path.join(work, "blender")
        base = [args.blender, "-b", "--factory-startup", "--python", script, "--",
                os.path.join(work, "W2-after", "manifest.json"), out]
        for key, extra, reps in (("W1", ["1"], args.reps_blender_w1), ("W2", [], 1)):
            blender[key] = []
            for i in range(reps):
                shutil.rmtree(out, ignore_errors=True)
                os.makedirs(out)
                wall, peak, cpu = run(base + extra)
                blender[key].append({"wall": wall, "peak": peak, "cpu": cpu, "load": os.getloadavg()[0]})
                sys.stderr.write(f"Blender {key} {i + 1}/{reps}: {wall:.2f} s wall, {cpu:.2f} s CPU\n")
    # The pipeline cache: W1 of the after build with it off, and warm (a cache folder a first run filled).
    cache_env = {"XDG_CACHE_HOME": os.path.join(work, "xdg-cache")}
    bake(builds["after"], W1, os.path.join(work, "cache-fill"), cache_env)
    cache_runs = {"off": [], "warm": []}
    for rep in range(args.reps_cache):
        for key in (("off", "warm") if rep % 2 == 0 else ("warm", "off")):
            env = {"SKYBAKE_PIPELINE_CACHE": "0"} if key == "off" else cache_env
            r = bake(builds["after"], W1, os.path.join(work, "cache-" + key), env)
            cache_runs[key].append(stage(r["timings"], "pipelines"))
    load_end = os.getloadavg()

    print(f"load average (1 min): {load_start[0]:.1f} before the runs, {load_end[0]:.1f} after; "
          f"{args.reps_w1} W1 and {args.reps_w2} W2 runs per build, alternated\n")
    print("| workload | build | wall (median) | CPU (median) | peak memory (max) | pipelines stage (median) |")
    print("| --- | --- | ---: | ---: | ---: | ---: |")
    for label, runs in (("W1", w1), ("W2", w2)):
        for name in builds:
            r = runs[name]
            print(f"| {label} | {name} | {med(r, 'wall'):.2f} s | {med(r, 'cpu'):.2f} s | "
                  f"{max(x['peak'] for x in r):.0f} MiB | "
                  f"{statistics.median(stage(x['timings'], 'pipelines') for x in r):.3f} s |")
    for key, r in blender.items():
        print(f"| {key} | Blender 3.4 Cycles Nishita, 1 sample | {med(r, 'wall'):.2f} s | {med(r, 'cpu'):.2f} s | "
              f"{max(x['peak'] for x in r):.0f} MiB | |")
    print(f"\nsame bytes, before and after: W1 {'yes' if same['W1'] else 'NO'}, W2 {'yes' if same['W2'] else 'NO'}\n")
    print("| target | measured | met |")
    print("| --- | --- | --- |")
    if blender:
        for key, want in (("W2", 12.0), ("W1", 6.0)):
            runs = w1 if key == "W1" else w2
            ratio = med(blender[key], "cpu") / med(runs["after"], "cpu")
            before = med(blender[key], "cpu") / med(runs["before"], "cpu")
            print(f"| {key}: >= {want:g}x faster than Blender in CPU time | {ratio:.1f}x (before: {before:.1f}x; "
                  f"wall {med(blender[key], 'wall') / med(runs['after'], 'wall'):.1f}x) | "
                  f"{'yes' if ratio >= want else 'no'} |")
    w2_wall = med(w2["after"], "wall") / med(w2["before"], "wall")
    print(f"| W2 faster than before in wall time | after / before {w2_wall:.3f} | {'yes' if w2_wall < 1 else 'no'} |")
    pipelines = (statistics.median(stage(x["timings"], "pipelines") for x in w1["after"]) /
                 statistics.median(stage(x["timings"], "pipelines") for x in w1["before"]))
    print(f"| W1 pipelines stage, after / before | {pipelines:.2f} | |")
    for name in builds:
        ratio, twilight, day = twilight_ratio(frame_costs(os.path.join(work, f"W2-{name}")),
                                              marched_frames(os.path.join(work, f"W2-{name}")))
        if ratio:
            print(f"| twilight frame (Sun -21 to 3 deg) <= 1.5x a day frame, GPU time, {name} | {ratio:.2f}x "
                  f"({twilight:.0f} ms against {day:.0f} ms, medians) | {'yes' if ratio <= 1.5 else 'no'} |")
    print(f"| W2 peak memory no higher than before | {max(x['peak'] for x in w2['after']):.0f} MiB against "
          f"{max(x['peak'] for x in w2['before']):.0f} MiB | "
          f"{'yes' if max(x['peak'] for x in w2['after']) <= max(x['peak'] for x in w2['before']) * 1.02 else 'no'} |")
    print(f"| pipeline cache: W1 pipelines stage warm / off (after build) | "
          f"{statistics.median(cache_runs['warm']) / statistics.median(cache_runs['off']):.2f} "
          f"({statistics.median(cache_runs['warm']):.3f} s against {statistics.median(cache_runs['off']):.3f} s) | |")


if __name__ == "__main__":
    main()
