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
    python3 tests/benchmark/performance.py --blender-clouds --work DIR [--reps-w3 3] [--sun-elevation 45] [--reuse-blender]

--blender-clouds: W3 against Blender Cycles (docs/performance_history.md, "W3
against Blender Cycles"): skybake's W3 as a 2048 x 1024 float latlong alone
and with its usual outputs, then tests/benchmark/blender_clouds.py at 16 and
64 samples (two 16-sample renders with different seeds), the noise of each
and the cloud cover of both. Results go to DIR/blender_clouds.json as each
run ends; --reuse-blender keeps the Blender runs found there (re-times
skybake alone against them), --report-only runs nothing and reports them.

Every case but one runs with Mesa's shader disk cache as a second bake on a
machine finds it; "W1 half, Mesa shader cache off" is a machine's first bake.

Prints a markdown report (stdout) with the stage times of skybake's own
timings.json and how close each stage is to its limit.
"""
import argparse
import array
import hashlib
import json
import math
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def run(cmd, cwd=ROOT, log=None, env=None):
    """Runs cmd; returns (wall seconds, peak RSS MiB, CPU seconds: user +
    system of the process and the children it waited for). Fails loudly."""
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
    walls, peaks, cpus, loads = [], [], [], []
    for i in range(reps):
        if before:
            before()
        wall, peak, cpu = run(cmd, env=env)
        loads.append(os.getloadavg()[0])
        if after:
            after()
        walls.append(wall)
        peaks.append(peak)
        cpus.append(cpu)
        sys.stderr.write(f"{label} run {i + 1}/{reps}: {wall:.2f} s, CPU {cpu:.2f} s, peak {peak:.0f} MiB, "
                         f"load {loads[-1]:.1f}\n")
    return {"label": label, "wall": statistics.median(walls), "walls": walls, "peak": statistics.median(peaks),
            "peak_max": max(peaks), "cpu": statistics.median(cpus), "cpus": cpus, "loads": loads}


def cpu_peak_gflops():
    """Peak FP32 rate of llvmpipe's 256-bit code: cores x clock x 8 lanes x 2 (FMA) x 2 FMA ports."""
    cores, mhz = os.cpu_count(), 0.0
    with open("/proc/cpuinfo") as f:
        for line in f:
            if line.startswith("cpu MHz"):
                mhz = float(line.split(":")[1])
                break
    return cores * mhz * 1e-3 * 8 * 2 * 2, cores, mhz


# FLOPs counted from the compiled shaders by tests/benchmark/shader_ops.py
# (2026-12-07; static counts of the -Os variants, a transcendental as one
# operation, so an upper bound of what a texel executes): a sky-view LUT
# sample (one step of its march) 859 plus 1374 per texel outside the march,
# about 902 per sample at 32 steps; an output texel of the sky-view
# sky_render variant 1039. The hand counts before them were 250 and 100.
FLOPS_PER_SKYVIEW_SAMPLE = 902
FLOPS_PER_TEXEL = 1039


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
    parser.add_argument("--pairs", type=int, default=7,
                        help="W1 then W3, one after the other, this many times: the render stages' ratio per pair")
    parser.add_argument("--w3-sequence", action="store_true", help="also W3's 96-frame time-lapse (slow)")
    parser.add_argument("--only-clouds", action="store_true", help="W1 and W3 single frames only (no W2, no Blender)")
    parser.add_argument("--only-ibl", action="store_true",
                        help="the IBL prefilter's share of a bake: default.toml with a 512 specular cube, float files")
    parser.add_argument("--skybake-before", default=None,
                        help="--only-ibl: a second skybake build, run alternately with --skybake (before / after)")
    parser.add_argument("--blender-clouds", action="store_true",
                        help="W3 against Blender Cycles at 16 and 64 samples (2048 x 1024; slow: about an hour)")
    parser.add_argument("--reuse-blender", action="store_true",
                        help="--blender-clouds: keep the Blender runs already in WORK/blender_clouds.json")
    parser.add_argument("--sun-elevation", type=float, default=45.0,
                        help="--blender-clouds: the Sun's elevation in both scenes, deg (W3's: 45)")
    parser.add_argument("--full-64", action="store_true",
                        help="--blender-clouds: also the whole 2048 x 1024 render at 64 samples (slow)")
    parser.add_argument("--report-only", action="store_true",
                        help="--blender-clouds: run nothing, report the runs in WORK/blender_clouds.json")
    args = parser.parse_args()
    work = args.work or tempfile.mkdtemp(prefix="skybake-bench-")
    os.makedirs(work, exist_ok=True)
    w1 = ["configs/benchmark/w1.toml"]
    w2 = w1 + ["--schedule", "configs/benchmark/w2.toml"]
    floats = ["--set", 'output.pixel_type="float"']

    def bake(extra, out):
        return bake_command(args.skybake, extra, os.path.join(work, out))

    if args.only_ibl:
        print_ibl(args, work)
        return
    if args.blender_clouds:
        print_blender_clouds(args, work)
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
    # The 8x target as pairs: W1's render stage moves by a third between
    # runs a minute apart on a shared machine, so each W3 run is set beside
    # the W1 run just before it.
    pair_ratios = []
    for i in range(args.pairs):
        stages = []
        for config, out in ((w1, "w1p"), (w3, "w3p")):
            run(bake(config, out))
            timings = json.load(open(os.path.join(work, out, "timings.json")))
            stages.append({s["stage"]: s["seconds"] for s in timings["stages"]}["render"])
        pair_ratios.append((stages[0], stages[1]))
        sys.stderr.write(f"W1/W3 pair {i + 1}/{args.pairs}: render {stages[0]:.3f} s, {stages[1]:.3f} s, "
                         f"{stages[1] / stages[0]:.2f}x\n")
    results["w3_pairs"] = pair_ratios
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
              f"and {blender['w2']['wall'] / results['w2_half']['wall']:.1f}x on W2 in wall time (issue 51's targets, "
              f"in CPU time: 12x on W2, 6x on W1: tests/benchmark/targets.py).")
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


def bake_command(skybake, extra, out_dir):
    return [skybake, "bake", *extra, "--out", out_dir, "--force", "--quiet"]


def sha256(path):
    with open(path, "rb") as f:
        return hashlib.sha256(f.read()).hexdigest()


def latlong_luminance(exr, rows=None):
    """Rec.709 luminance of the first `rows` rows of a latlong EXR (default
    its upper half: row 0 the zenith, row h/2 - 1 just above the horizon), as
    (width, rows, values row by row from the top); read through
    `oiiotool --dumpdata`."""
    info = subprocess.run(["oiiotool", "--info", exr], capture_output=True, text=True, check=True).stdout
    size = info.split(":", 1)[1].split(",")[0].split("x")  # "NAME : W x H, 3 channel, float openexr"
    width, height = int(size[0]), int(size[1])
    rows = rows or height // 2
    top = exr + ".top.exr"  # the rows alone: half the text to read
    subprocess.run(["oiiotool", exr, "--ch", "R,G,B", "--crop", f"{width}x{rows}+0+0", "-o", top], check=True)
    proc = subprocess.Popen(["oiiotool", "--dumpdata", top], stdout=subprocess.PIPE, text=True)
    proc.stdout.readline()
    y = array.array("f", bytes(4 * width * rows))
    for line in proc.stdout:  # "    Pixel (x, y): r g b"
        position, values = line.split(":")
        px, py = (int(v) for v in position.strip()[7:-1].split(","))
        if py >= rows:
            continue
        r, g, b = (float(v) for v in values.split()[:3])
        y[py * width + px] = 0.2126 * r + 0.7152 * g + 0.0722 * b
    if proc.wait() != 0:
        raise SystemExit(f"oiiotool --dumpdata {top} failed")
    os.remove(top)
    return width, rows, y


def solid_angle_weights(width, rows, sun_index, sun_box_px, min_elevation_deg=0.0, first_row=0):
    """Per texel of `rows` rows of a latlong (width x width / 2) from
    `first_row`: its solid angle (cos latitude), 0 below min_elevation_deg and
    within sun_box_px texels of the Sun (sun_index: in the whole latlong)."""
    w = array.array("f", bytes(4 * width * rows))
    sx, sy = sun_index % width, sun_index // width - first_row
    for r in range(rows):
        elevation = 90.0 - (first_row + r + 0.5) * 360.0 / width
        if elevation < min_elevation_deg:
            continue
        c = math.cos(math.radians(elevation))
        for x in range(width):
            dx = min(abs(x - sx), width - abs(x - sx))
            if dx <= sun_box_px and abs(r - sy) <= sun_box_px:
                continue
            w[r * width + x] = c
    return w


def argmax(values):
    return max(range(len(values)), key=values.__getitem__)


def cloud_cover(cloudy, clear, weights):
    """Solid-angle fraction of the weighted texels where the layer changes
    the sky's luminance by more than 10%, that mask, and the weighted mean of
    cloudy / clear over the texels it marks (how bright the clouds are
    against the sky they hide)."""
    covered = total = ratio_sum = 0.0
    mask = array.array("b", bytes(len(weights)))
    for i, w in enumerate(weights):
        if w <= 0.0 or clear[i] <= 0.0:
            continue
        total += w
        ratio = cloudy[i] / clear[i]
        if abs(ratio - 1.0) > 0.1:
            covered += w
            ratio_sum += w * ratio
            mask[i] = 1
    return covered / total, mask, ratio_sum / max(covered, 1e-30)


def noise_of(a, b, weights, mask, reference=None):
    """The RMS noise of one render over its weighted mean luminance, from
    independent renders: with reference None, a and b have the same samples
    (variance = mean (a - b)^2 / 2); else a is a render of N samples and b
    the mean of two renders of N/4 (its variance, `reference`, known):
    variance = mean (a - b)^2 - reference. Over all weighted texels and over
    those `mask` marks. Returns ((relative, variance) all, (relative,
    variance) masked)."""
    out = []
    for use_mask in (False, True):
        sw = sy = sd = 0.0
        for i, w in enumerate(weights):
            if w <= 0.0 or (use_mask and not mask[i]):
                continue
            d = a[i] - b[i]
            sw += w
            sy += w * 0.5 * (a[i] + b[i])
            sd += w * d * d
        variance = sd / sw / 2.0 if reference is None else sd / sw - reference[len(out)]
        out.append((math.sqrt(max(variance, 0.0)) / (sy / sw), variance))
    return out


STRIP_ROWS = (224, 256)  # of a 2048 x 1024 latlong: elevation 50.6 to 45 deg


def print_blender_clouds(args, work):
    """W3 against Blender Cycles: whole-process wall and CPU time of skybake
    (W3 as a float latlong alone, and W3 as it is) and of Blender's Cycles
    at 16 and 64 samples, in one run; each render's noise, and the cloud
    cover of both against their clear skies."""
    if not args.blender:
        raise SystemExit("--blender-clouds needs Blender (--blender PATH)")
    script = os.path.join(ROOT, "tests", "benchmark", "blender_clouds.py")
    stored_path = os.path.join(work, "blender_clouds.json")
    reuse = args.reuse_blender or args.report_only
    stored = json.load(open(stored_path)) if reuse and os.path.exists(stored_path) else {}
    if stored.get("sun_elevation_deg", args.sun_elevation) != args.sun_elevation:
        raise SystemExit(f"{stored_path}: its runs have the Sun at {stored['sun_elevation_deg']} deg, not "
                         f"{args.sun_elevation}")
    results = stored if args.report_only else {key: value for key, value in stored.items() if key.startswith("blender")}
    results["sun_elevation_deg"] = args.sun_elevation

    def save():
        with open(stored_path, "w") as f:
            json.dump(results, f, indent=1)

    w3, w1 = ["configs/benchmark/w3.toml"], ["configs/benchmark/w1.toml"]
    sun = ["--set", f"sun.elevation_deg={args.sun_elevation}"]
    w3, w1 = w3 + sun, w1 + sun
    latlong_only = ["--set", "output.faces=false", "--set", "output.cube_strip=false", "--set",
                    'output.pixel_type="float"']
    hashes = {"w3_latlong": [], "w3": []}

    def keep_hash(out):
        return lambda: hashes[out].append(sha256(os.path.join(work, out, "sky_latlong.exr")))
    def time_skybake():
        git = subprocess.run(["git", "-C", ROOT, "log", "-1", "--format=%h %cI"], capture_output=True, text=True)
        results["skybake_commit"] = git.stdout.strip()
        results["skybake_w1_latlong"] = median_run(
            "skybake W1 latlong (the clear sky)", bake_command(args.skybake, w1 + latlong_only,
                                                               os.path.join(work, "w1_latlong")), 1)
        results["skybake_w3_latlong"] = median_run(
            "skybake W3 latlong", bake_command(args.skybake, w3 + latlong_only, os.path.join(work, "w3_latlong")),
            args.reps_w3, after=keep_hash("w3_latlong"))
        results["skybake_w3"] = median_run(
            "skybake W3 (faces, strip, latlong; half)", bake_command(args.skybake, w3, os.path.join(work, "w3")),
            args.reps_w3, after=keep_hash("w3"))
        for out in hashes:
            results["skybake_" + out]["identical_bytes"] = len(set(hashes[out])) == 1
        save()

    # In this order, so that the 16-sample render and skybake share one
    # spell of the machine's load. The noise is measured on a strip of 32
    # rows (elevation 50.6 to 45 deg) rendered again with other seeds: the
    # 16-sample render's strip against a second 16-sample strip, and a
    # 64-sample strip against their mean; --full-64 adds the whole 64-sample
    # render (4 times the 16-sample one's time; an hour or more here).
    base = [args.blender, "-b", "--factory-startup", "--python", script, "--"]
    extra_all = ["--sun-elevation", str(args.sun_elevation)]
    strip = ["--rows", str(STRIP_ROWS[0]), str(STRIP_ROWS[1])]
    blender_runs = [("blender_clear", "Blender clear sky", 1, ["--clear"]),
                    ("blender_16a", "Blender 16 samples", 16, ["--seed", "1"]),
                    ("skybake", None, None, None),
                    ("blender_16b_strip", "Blender 16 samples, strip, second seed", 16, ["--seed", "2"] + strip),
                    ("blender_64_strip", "Blender 64 samples, strip", 64, ["--seed", "3"] + strip)]
    if args.full_64:
        blender_runs.append(("blender_64", "Blender 64 samples", 64, ["--seed", "3"]))
    for key, label, samples, extra in [] if args.report_only else blender_runs:
        if key == "skybake":
            time_skybake()
            continue
        image = os.path.join(work, key + ".exr")
        if key in results and os.path.exists(image):
            sys.stderr.write(f"{label}: kept from {stored_path}\n")
            continue
        results[key] = median_run(label, base + [image, str(samples)] + extra + extra_all, 1)
        results[key]["samples"] = samples
        save()

    # Cloud cover over the sky above 30 deg and noise over the strip, the
    # Sun's box left out.
    width, rows, sky_clear = latlong_luminance(os.path.join(work, "w1_latlong", "sky_latlong.exr"))
    _, _, sky_cloudy = latlong_luminance(os.path.join(work, "w3_latlong", "sky_latlong.exr"))
    lum = {key: latlong_luminance(os.path.join(work, key + ".exr"))[2] for key in ("blender_clear", "blender_16a")}
    box = 20  # texels: 3.5 deg around the Sun's texel
    cap = 30.0  # cloud cover: above 30 deg elevation, where both layers are seen through the same air
    sky_cover = cloud_cover(sky_cloudy, sky_clear, solid_angle_weights(width, rows, argmax(sky_clear), box, cap))
    blender_sun = argmax(lum["blender_clear"])
    blender_cover = cloud_cover(lum["blender_16a"], lum["blender_clear"],
                                solid_angle_weights(width, rows, blender_sun, box, cap))
    first, end = STRIP_ROWS
    n = end - first
    # The first seed's strip: the whole render's rows (a strip rendered with
    # the same seed has the same pixels: `oiiotool --diff` passes).
    strip = {key: latlong_luminance(os.path.join(work, f"blender_{key}_strip.exr"), n)[2] for key in ("16b", "64")}
    strip["16a"] = lum["blender_16a"][first * width:end * width]
    strip_clear = lum["blender_clear"][first * width:end * width]
    strip_w = solid_angle_weights(width, n, blender_sun, box, 0.0, first)
    _, strip_mask, _ = cloud_cover(strip["16a"], strip_clear, strip_w)
    n16 = noise_of(strip["16a"], strip["16b"], strip_w, strip_mask)
    mean32 = array.array("f", (0.5 * (p + q) for p, q in zip(strip["16a"], strip["16b"])))
    n64 = noise_of(strip["64"], mean32, strip_w, strip_mask, reference=[v / 2.0 for _, v in n16])
    results["noise"] = {"blender_16": [r for r, _ in n16], "blender_64": [r for r, _ in n64],
                        "strip_cloud_fraction": sum(w for w, m in zip(strip_w, strip_mask) if m) / sum(strip_w)}
    results["cover"] = {"skybake": [sky_cover[0], sky_cover[2]], "blender": [blender_cover[0], blender_cover[2]]}
    save()

    b16 = results["blender_16a"]
    print("| case | samples per texel | wall | process CPU | peak memory | load (1 min) | noise, strip | "
          "noise, strip's cloud texels | Blender 16 / this, wall | Blender 16 / this, CPU |")
    print("| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |")
    rows_out = [("skybake_w3_latlong", "skybake W3, 2048 x 1024 float latlong alone", "march", None),
                ("skybake_w3", "skybake W3 (six 512^2 faces, strip, latlong; half)", "march", None),
                ("blender_16a", "Blender Cycles, 2048 x 1024", "16", "blender_16"),
                ("blender_64", "Blender Cycles, 2048 x 1024", "64", "blender_64"),
                ("blender_clear", "Blender Cycles, clear sky (no layer)", "1", None),
                ("blender_16b_strip", f"Blender Cycles, rows {first}-{end - 1} alone, second seed", "16", "blender_16"),
                ("blender_64_strip", f"Blender Cycles, rows {first}-{end - 1} alone", "64", "blender_64")]
    for key, label, samples, noise in rows_out:
        if key not in results:
            continue
        r = results[key]
        if noise:
            noise_cells = f"{100 * results['noise'][noise][0]:.1f}% | {100 * results['noise'][noise][1]:.1f}%"
        elif key.startswith("skybake_w3"):
            noise_cells = {True: "0 | 0", False: "runs differ | ", None: "not checked | "}[r.get("identical_bytes")]
        else:
            noise_cells = " | "
        print(f"| {label} | {samples} | {r['wall']:.1f} s | {r['cpu']:.1f} s | {r['peak_max']:.0f} MiB | "
              f"{min(r['loads']):.1f}-{max(r['loads']):.1f} | {noise_cells} | {b16['wall'] / r['wall']:.1f}x | "
              f"{b16['cpu'] / r['cpu']:.1f}x |")
    latlong = results["skybake_w3_latlong"]
    print(f"\nThe Sun at {results['sun_elevation_deg']:g} deg in both. skybake: {results['skybake_commit']}; {len(latlong['walls'])} runs of each case (medians); noise 0: "
          f"the latlong's bytes were the same in every run of the case.")
    print(f"Cloud cover above 30 deg (texels the layer changes by more than 10%): skybake "
          f"{100 * results['cover']['skybake'][0]:.0f}%, Blender {100 * results['cover']['blender'][0]:.0f}% "
          f"(16 samples); mean cloudy / clear luminance there: skybake {results['cover']['skybake'][1]:.2f}, "
          f"Blender {results['cover']['blender'][1]:.2f}.")
    print(f"Noise: over rows {first}-{end - 1} (elevation 50.6-45 deg; cloud texels "
          f"{100 * results['noise']['strip_cloud_fraction']:.0f}% of them).")


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
    pairs = results.get("w3_pairs", [])
    if pairs:
        ratios = sorted(w3 / w1 for w1, w3 in pairs)
        print(f"| W3 / W1, in pairs run one after the other | median {statistics.median(ratios):.2f}x "
              f"({ratios[0]:.2f}-{ratios[-1]:.2f}x; W1 {min(p[0] for p in pairs):.3f}-{max(p[0] for p in pairs):.3f} s, "
              f"W3 {min(p[1] for p in pairs):.3f}-{max(p[1] for p in pairs):.3f} s) | {len(pairs)} |")
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
