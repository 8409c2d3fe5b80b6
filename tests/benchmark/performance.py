#!/usr/bin/env python3
"""The performance benchmark of docs/performance.md.

W1: one frame of configs/benchmark/w1.toml (six 512^2 faces, the strip, a
2048 x 1024 latlong; production preset; half-float ZIP EXRs), the whole
`skybake bake` process. W2: the 96-frame time-lapse of W1
(configs/benchmark/w2.toml). Both also with float32 EXRs, and W1 with the
default outputs (PNG preview, glTF scene). Each is timed as a whole process
(wall clock, peak resident memory from wait4), several times, medians
reported. Blender (Cycles, Nishita sky, 1 sample; tests/benchmark/
blender_sky.py) renders the same frames in the same run when it is installed.

    python3 tests/benchmark/performance.py [--reps 3] [--no-blender]
    python3 tests/benchmark/performance.py --only-ibl [--reps 5] [--skybake-before OLD/skybake]

Every case but one runs with Mesa's shader disk cache as a second bake on a
machine finds it; "W1 half, Mesa shader cache off" is a machine's first bake.

Prints a markdown report (stdout) with the stage times of skybake's own
timings.json and how close each stage is to its limit.
"""
import argparse
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def run(cmd, cwd=ROOT, log=None, env=None):
    """Runs cmd; returns (wall seconds, peak RSS MiB, CPU seconds of all its threads). Fails loudly."""
    start = time.monotonic()
    proc = subprocess.Popen(cmd, cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                            env=dict(os.environ, **env) if env else None)
    out = proc.stdout.read()
    _, status, usage = os.wait4(proc.pid, 0)
    wall = time.monotonic() - start
    if os.waitstatus_to_exitcode(status) != 0:
        sys.stderr.write(out.decode(errors="replace"))
        raise SystemExit(f"failed: {' '.join(cmd)}")
    if log:
        with open(log, "wb") as f:
            f.write(out)
    return wall, usage.ru_maxrss / 1024.0, usage.ru_utime + usage.ru_stime


def median_run(label, cmd, reps, before=None, env=None, after=None):
    walls, peaks, loads, cpus = [], [], [], []
    for i in range(reps):
        if before:
            before()
        wall, peak, cpu = run(cmd, env=env)
        if after:
            after()
        walls.append(wall)
        peaks.append(peak)
        cpus.append(cpu)
        loads.append(os.getloadavg()[0])  # the 1-minute load average as the run ends
        sys.stderr.write(f"{label} run {i + 1}/{reps}: {wall:.2f} s, CPU {cpu:.2f} s, peak {peak:.0f} MiB, load {loads[-1]:.1f}\n")
    return {"label": label, "wall": statistics.median(walls), "walls": walls, "peak": statistics.median(peaks),
            "peak_max": max(peaks), "loads": loads, "cpu": statistics.median(cpus)}


def cpu_peak_gflops():
    """Peak FP32 rate of llvmpipe's 256-bit code: cores x clock x 8 lanes x 2 (FMA) x 2 FMA ports."""
    cores, mhz = os.cpu_count(), 0.0
    with open("/proc/cpuinfo") as f:
        for line in f:
            if line.startswith("cpu MHz"):
                mhz = float(line.split(":")[1])
                break
    return cores * mhz * 1e-3 * 8 * 2 * 2, cores, mhz


# FLOPs estimated by counting the operations of the shaders (shaders/
# atmosphere.glsl), one per add, multiply or compare, a transcendental (exp,
# sqrt, atan, sin, asin) as ~15, the length of llvmpipe's polynomial
# expansions: a sky-view LUT sample (medium densities, two transmittance
# and one multiple-scattering LUT reads, phases, the analytic step) ~250; an
# output texel (mapping, two atan, the LUT read and its unpacking) ~100; the
# sun disc is a pass of its own over the few texels near the Sun.
FLOPS_PER_SKYVIEW_SAMPLE = 250
FLOPS_PER_TEXEL = 100


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--skybake", default=os.path.join(ROOT, "build", "skybake"))
    parser.add_argument("--reps", type=int, default=3, help="runs of each case (medians reported)")
    parser.add_argument("--reps-w1", type=int, default=5)
    parser.add_argument("--reps-w2-float", type=int, default=1, help="runs of W2 with float32 files (slow)")
    parser.add_argument("--no-blender", action="store_true")
    parser.add_argument("--blender", default=shutil.which("blender"))
    parser.add_argument("--work", default=None, help="scratch folder (default: a temporary one)")
    parser.add_argument("--reps-w3", type=int, default=1, help="runs of W3 (W1 with one cumulus layer)")
    parser.add_argument("--w3-sequence", action="store_true", help="also W3's 96-frame time-lapse (slow)")
    parser.add_argument("--only-clouds", action="store_true", help="W1 and W3 single frames only (no W2, no Blender)")
    parser.add_argument("--only-ibl", action="store_true",
                        help="the IBL prefilter's share of a bake: default.toml with a 512 specular cube, float files")
    parser.add_argument("--skybake-before", default=None,
                        help="--only-ibl: a second skybake build, run alternately with --skybake (before / after)")
    args = parser.parse_args()
    work = args.work or tempfile.mkdtemp(prefix="skybake-bench-")
    os.makedirs(work, exist_ok=True)
    w1 = ["configs/benchmark/w1.toml"]
    w2 = w1 + ["--schedule", "configs/benchmark/w2.toml"]
    floats = ["--set", 'output.pixel_type="float"']

    def bake(extra, out):
        return [args.skybake, "bake", *extra, "--out", os.path.join(work, out), "--force", "--quiet"]

    if args.only_ibl:
        print_ibl(args, work)
        return

    results = {}
    w1_stage_runs = []  # stage seconds of each W1 run, from its timings.json
    results["w1_half"] = median_run(
        "W1 half", bake(w1, "w1"), args.reps_w1,
        after=lambda: w1_stage_runs.append(
            {s["stage"]: s["seconds"] for s in json.load(open(os.path.join(work, "w1", "timings.json")))["stages"]}))
    # Mesa keeps the machine code of every shader it compiled in a disk cache
    # (~/.cache/mesa_shader_cache): every bake but a machine's first finds it.
    # W3 (issue 15): W1 with one production cumulus layer; the render stage
    # beside W1's, and the cloud passes' GPU time.
    w3 = ["configs/benchmark/w3.toml"]
    w3_stage_runs = []
    results["w3_half"] = median_run(
        "W3 half (W1 + cumulus layer)", bake(w3, "w3"), args.reps_w3,
        after=lambda: w3_stage_runs.append(json.load(open(os.path.join(work, "w3", "timings.json")))))
    # W3 with every view marching its own texels (no cloud panorama): the
    # speed of the panorama, and the reference its images are compared with.
    w3m_stage_runs = []
    results["w3_marched"] = median_run(
        "W3 half, every view marched (cloud_panorama_scale = 0)",
        bake(w3 + ["--set", "quality.cloud_panorama_scale=0"], "w3m"), args.reps_w3,
        after=lambda: w3m_stage_runs.append(json.load(open(os.path.join(work, "w3m", "timings.json")))))
    if args.w3_sequence:
        results["w3_sequence"] = median_run("W3 96 frames", bake(w3 + ["--schedule", "configs/benchmark/w2.toml"],
                                                                 "w3s"), 1)
    if args.only_clouds:
        print_clouds(results, w1_stage_runs, w3_stage_runs, w3m_stage_runs)
        return
    results["w1_cold"] = median_run("W1 half, Mesa shader cache off", bake(w1, "w1c"), args.reps_w1,
                                    env={"MESA_SHADER_CACHE_DISABLE": "true"})
    results["w1_float"] = median_run("W1 float", bake(w1 + floats, "w1f"), args.reps_w1)
    results["w1_default"] = median_run("W1 + preview + glTF", bake(
        w1 + ["--set", "output.preview=true", "--set", "gltf.enabled=true"], "w1d"), args.reps_w1)
    results["w2_half"] = median_run("W2 half", bake(w2, "w2"), args.reps)
    w2_manifest = os.path.join(work, "w2", "manifest.json")
    w2_timings = json.load(open(os.path.join(work, "w2", "timings.json")))
    w2_bytes = sum(f["bytes"] for fr in json.load(open(w2_manifest))["frames"] for f in fr["files"])
    # The default's neighbour, side by side: what ZIP level 2 (the default) saves over level 1.
    results["w2_level1"] = median_run("W2 half, ZIP level 1", bake(w2 + ["--set", "output.zip_level=1"], "w2l1"),
                                      args.reps)
    results["w2_float"] = median_run("W2 float", bake(w2 + floats, "w2f"), args.reps_w2_float)

    blender = None
    if args.blender and not args.no_blender:
        script = os.path.join(ROOT, "tests", "benchmark", "blender_sky.py")
        out = os.path.join(work, "blender")

        def clean():
            shutil.rmtree(out, ignore_errors=True)
            os.makedirs(out)
        base = [args.blender, "-b", "--factory-startup", "--python", script, "--", w2_manifest, out]
        blender = {"w1": median_run("Blender W1", base + ["1"], args.reps, clean),
                   "w2": median_run("Blender W2", base, 1, clean)}

    # Stages of the last W2 run: medians over frames.
    frames = w2_timings["frames"]
    render_s = statistics.median(f["render_s"] for f in frames)
    write_s = statistics.median(f["write_s"] for f in frames)
    pass_ms = {}
    for f in frames:
        for p in f["gpu_passes"]:
            pass_ms.setdefault(p["name"], []).append(p["gpu_ms"])
    lut_ms = statistics.median(pass_ms.get("sky-view LUT", [0.0]))
    view_names = ["face +X", "face -X", "face +Y", "face -Y", "face +Z", "face -Z", "cube strip", "latlong"]
    # The first six "face" entries per frame are the output faces, the last six the 64^2 SH faces.
    view_ms = 0.0
    for f in frames:
        per = {}
        for p in f["gpu_passes"]:
            per.setdefault(p["name"], []).append(p["gpu_ms"])
        view_ms += sum(per[n][0] for n in view_names if n in per) + sum(per.get("sun disc", []))
    view_ms /= len(frames)
    peak, cores, mhz = cpu_peak_gflops()
    skyview_samples = 256 * 144 * 33
    texels = 6 * 512 * 512 + 512 * 3072 + 2048 * 1024
    lut_gflops = skyview_samples * FLOPS_PER_SKYVIEW_SAMPLE / (lut_ms * 1e-3) * 1e-9
    view_gflops = texels * FLOPS_PER_TEXEL / (view_ms * 1e-3) * 1e-9
    frame_mb = w2_bytes / len(frames) / 1e6
    raw_mb = texels * 3 * 2 / 1e6

    print("## Results\n")
    print(f"Machine: {cores} cores at {mhz:.0f} MHz (/proc/cpuinfo), lavapipe; medians of {args.reps_w1} (W1) "
          f"and {args.reps} (W2) runs in one run of this script.\n")
    print("| case | target | wall (median) | runs | peak memory |")
    print("| --- | --- | ---: | --- | ---: |")
    targets = {"w1_half": "<= 0.5 s", "w2_half": "<= 30 s, <= 1 GiB"}
    for key, r in results.items():
        print(f"| {r['label']} | {targets.get(key, '')} | {r['wall']:.2f} s | "
              f"{', '.join(f'{w:.2f}' for w in r['walls'])} | {r['peak_max']:.0f} MiB |")
    if blender:
        for key in ("w1", "w2"):
            r = blender[key]
            print(f"| {r['label']} (Cycles, 1 sample, half ZIP) | | {r['wall']:.2f} s | "
                  f"{', '.join(f'{w:.2f}' for w in r['walls'])} | {r['peak_max']:.0f} MiB |")
        print(f"\nskybake is {blender['w1']['wall'] / results['w1_half']['wall']:.1f}x faster than Blender on W1 "
              f"and {blender['w2']['wall'] / results['w2_half']['wall']:.1f}x on W2 (target: 8x on W2).")
    print("\n## Stages\n")
    print(f"W1, stages of timings.json: medians over its {len(w1_stage_runs)} runs, and the whole process:\n")
    print("| stage | seconds (median) | runs |")
    print("| --- | ---: | --- |")
    for stage in w1_stage_runs[0]:
        values = [r[stage] for r in w1_stage_runs]
        print(f"| {stage} | {statistics.median(values):.3f} | {', '.join(f'{v:.3f}' for v in values)} |")
    walls = results["w1_half"]["walls"]
    print(f"| sum of the stages | {statistics.median([sum(r.values()) for r in w1_stage_runs]):.3f} | |")
    print(f"| whole process (wall, incl. loading and exit) | {statistics.median(walls):.3f} | "
          f"{', '.join(f'{v:.3f}' for v in walls)} |")
    print(f"\nW2, medians over its {len(frames)} frames (files of a frame are written while the next renders):\n")
    print("| stage | per frame | limit | how close |")
    print("| --- | ---: | --- | --- |")
    print(f"| sky-view LUT (GPU) | {lut_ms:.0f} ms | {skyview_samples / 1e6:.2f} M samples x ~{FLOPS_PER_SKYVIEW_SAMPLE} "
          f"FLOP = {skyview_samples * FLOPS_PER_SKYVIEW_SAMPLE / 1e9:.2f} GFLOP; peak {peak:.0f} GFLOP/s | "
          f"{lut_gflops:.1f} GFLOP/s, {100 * lut_gflops / peak:.0f}% of peak |")
    print(f"| views incl. sun disc (GPU, {texels / 1e6:.2f} Mtexels) | {view_ms:.0f} ms | ~{FLOPS_PER_TEXEL} FLOP per texel = "
          f"{texels * FLOPS_PER_TEXEL / 1e9:.2f} GFLOP | {view_gflops:.1f} GFLOP/s, {100 * view_gflops / peak:.0f}% "
          f"of peak |")
    print(f"| render incl. SH (wall) | {render_s * 1e3:.0f} ms | | |")
    print(f"| encode + write + checksum 8 EXRs | {write_s * 1e3:.0f} ms | {raw_mb:.1f} MB of half RGB in, "
          f"{frame_mb:.2f} MB written | {raw_mb / write_s:.0f} MB/s in, {frame_mb / write_s:.1f} MB/s out |")
    print_clouds(results, w1_stage_runs, w3_stage_runs, w3m_stage_runs)


def print_ibl(args, work):
    """The specular prefilter (GPU timestamps of its passes) against the whole
    bake (timings.json total_s) in each run, for one build or two run
    alternately (so that both see the same load); medians of --reps runs."""
    ibl = ["configs/default.toml", "--size", "512", "--set", 'output.pixel_type="float"', "--set",
           "ibl.specular=true", "--set", "ibl.size=512"]
    builds = [("after", args.skybake)] + ([("before", args.skybake_before)] if args.skybake_before else [])
    runs = {label: [] for label, _ in builds}
    for i in range(args.reps):
        for label, binary in builds:
            out = os.path.join(work, "ibl_" + label)
            wall, _, _ = run([binary, "bake", *ibl, "--out", out, "--force", "--quiet"])
            t = json.load(open(os.path.join(out, "timings.json")))
            spec = sum(p["gpu_ms"] for f in t["frames"] for p in f["gpu_passes"] if p["name"] == "IBL specular") / 1e3
            stages = {st["stage"]: st["seconds"] for st in t["stages"]}
            runs[label].append({"spec": spec, "ibl": stages.get("IBL", 0.0), "render": stages.get("render", 0.0),
                                "write": stages.get("write EXR", 0.0), "total": t["total_s"], "wall": wall,
                                "load": os.getloadavg()[0]})
            sys.stderr.write(f"IBL {label} run {i + 1}/{args.reps}: specular {spec:.2f} s of {t['total_s']:.2f} s\n")
    print("| build | specular pass (s) | IBL stage (s) | render (s) | write EXR (s) | whole bake total_s (s) | "
          "specular / whole (median of the runs' ratios) | load average (1 min) |")
    print("| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |")
    med = lambda label, key: statistics.median(r[key] for r in runs[label])
    for label, binary in builds:
        ratio = statistics.median(r["spec"] / r["total"] for r in runs[label])
        print(f"| {label} ({binary}) | {med(label, 'spec'):.2f} | {med(label, 'ibl'):.2f} | {med(label, 'render'):.2f} | "
              f"{med(label, 'write'):.2f} | {med(label, 'total'):.2f} | {100 * ratio:.0f}% | "
              f"{min(r['load'] for r in runs[label]):.1f}-{max(r['load'] for r in runs[label]):.1f} |")


def print_clouds(results, w1_stage_runs, w3_stage_runs, w3m_stage_runs):
    """W3 beside W1: the render stage, and the cloud passes of W3's first frame."""
    def median_stage(runs, name):
        return statistics.median([r[name] for r in runs])
    def render(runs):
        return statistics.median([{s["stage"]: s["seconds"] for s in t["stages"]}["render"] for t in runs])
    w1_render = median_stage(w1_stage_runs, "render")
    w3_render = render(w3_stage_runs)
    passes = w3_stage_runs[-1]["frames"][0]["gpu_passes"]
    cloud_ms = sum(p["gpu_ms"] for p in passes if p["name"].startswith("cloud"))
    print("\n## Clouds (W3)\n")
    print("| case | render stage (median) | runs |")
    print("| --- | ---: | ---: |")
    print(f"| W1 | {w1_render:.3f} s | {len(w1_stage_runs)} |")
    print(f"| W3 | {w3_render:.3f} s ({w3_render / w1_render:.1f}x W1; target 8x) | {len(w3_stage_runs)} |")
    w3m_render = render(w3m_stage_runs)
    print(f"| W3, every view marched | {w3m_render:.3f} s ({w3m_render / w1_render:.1f}x W1) | {len(w3m_stage_runs)} |")
    for key in ("w1_half", "w3_half", "w3_marched", "w3_sequence"):
        if key in results:
            r = results[key]
            print(f"| {r['label']}, whole process | {r['wall']:.2f} s wall, {r['cpu']:.2f} s CPU, "
                  f"{r['peak_max']:.0f} MiB peak, load "
                  f"{min(r['loads']):.1f}-{max(r['loads']):.1f} | {len(r['walls'])} |")
    print(f"\nW3's cloud passes (GPU, last run, frame and SH views): {cloud_ms:.0f} ms")
    for p in passes:
        if p["name"].startswith("cloud"):
            print(f"- {p['name']}: {p['gpu_ms']:.1f} ms")


if __name__ == "__main__":
    main()
