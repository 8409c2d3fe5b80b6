#!/usr/bin/env python3
"""What each cloud quality key costs and buys (docs/effects.md, docs/clouds.md).

W3's style (configs/benchmark/w3.toml: one production cumulus layer, sun 45 deg)
baked into one latlong of --height rows (a single view: marched texel by texel,
no cloud panorama), once per setting: production with one key changed. Each
bake is compared with a converged reference (--ref-view-steps view and
--ref-light-steps light steps, the finest noise volumes) over the upper half
of the latlong (the sky; the lower half sees the ground and no cloud):
mean |L - L_ref| / mean L_ref and the relative RMSE, on the stored half floats
divided by skybake:scale, texels brighter than 5e4 cd/m^2 (the sun disc)
clamped there. Time: the cloud passes' GPU time of the bake (lavapipe
timestamps: wall time, as loaded as the machine), median of --reps, per
megapixel of the latlong.

    python3 tests/benchmark/cloud_study.py [--height 512] [--reps 2] [--csv out.csv]
"""
import argparse, json, math, os, re, statistics, subprocess, sys, tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
PRODUCTION = {"cloud_view_steps": 48, "cloud_light_steps": 6, "cloud_octaves": 8, "cloud_shape_resolution": 64,
              "cloud_detail_resolution": 32, "cloud_weather_resolution": 256}
SWEEP = {"cloud_view_steps": [16, 24, 32, 64, 96, 192], "cloud_light_steps": [1, 2, 4, 12, 24],
         "cloud_octaves": [1, 2, 4], "cloud_shape_resolution": [32, 48, 128],
         "cloud_detail_resolution": [16, 24, 64], "cloud_weather_resolution": [128, 512]}
CLAMP = 5e4


def bake(args, out, settings):
    cmd = [args.skybake, "bake", "configs/benchmark/w3.toml", "--out", out, "--force", "--quiet",
           "--set", "output.faces=false", "--set", "output.cube_strip=false",
           "--set", f"render.latlong_height={args.height}"]
    for k, v in settings.items():
        cmd += ["--set", f"quality.{k}={v}"]
    subprocess.run(cmd, cwd=ROOT, check=True, stdout=subprocess.DEVNULL)
    t = json.load(open(os.path.join(out, "timings.json")))
    return sum(p["gpu_ms"] for p in t["frames"][0]["gpu_passes"] if p["name"] == "clouds latlong")


def stats(args):
    out = subprocess.run(["oiiotool"] + args + ["--printstats"], capture_output=True, text=True, check=True).stdout
    get = lambda k: [float(x) for x in re.search(k + r": ([-\d.e+ ]+)", out).group(1).split()[:3]]
    return get("Stats Avg"), get("Stats StdDev")


def sky(path, height):
    head = subprocess.run(["exrheader", path], capture_output=True, text=True, check=True).stdout
    scale = float(re.search(r'skybake:scale \(type string\): "([^"]+)"', head).group(1))
    return [path, "--cut", f"{2 * height}x{height // 2}+0+0", "--mulc", str(1.0 / scale), "--clamp:max=%g" % CLAMP]


def compare(a, ref, height):
    ca, cr = sky(a, height), sky(ref, height)
    mean = sum(stats(cr)[0]) / 3
    davg, dsd = stats(ca + cr + ["--sub"])
    aavg, _ = stats(ca + cr + ["--sub", "--abs"])
    rmse = math.sqrt(sum(x * x + y * y for x, y in zip(davg, dsd)) / 3)
    return sum(aavg) / 3 / mean, rmse / mean


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--skybake", default=os.path.join(ROOT, "build", "skybake"))
    p.add_argument("--height", type=int, default=512, help="latlong rows (2 x height columns)")
    p.add_argument("--reps", type=int, default=2)
    p.add_argument("--ref-view-steps", type=int, default=384)
    p.add_argument("--ref-light-steps", type=int, default=64)
    p.add_argument("--smoke", action="store_true", help="two settings at a tiny size (ctest)")
    p.add_argument("--csv")
    p.add_argument("--work")
    args = p.parse_args()
    work = args.work or tempfile.mkdtemp(prefix="skybake-cloud-study-")
    sweep = SWEEP
    if args.smoke:
        args.height, args.reps, args.ref_view_steps, args.ref_light_steps = 32, 1, 192, 24
        sweep = {"cloud_view_steps": [16]}
    mpx = 2.0 * args.height * args.height * 1e-6
    ref = dict(PRODUCTION, cloud_view_steps=args.ref_view_steps, cloud_light_steps=args.ref_light_steps,
               cloud_shape_resolution=128, cloud_detail_resolution=64, cloud_weather_resolution=512)
    ref_dir = os.path.join(work, "reference")
    ref_ms = bake(args, ref_dir, ref)
    rows = []

    def case(name, settings):
        out = os.path.join(work, re.sub(r"[^A-Za-z0-9_=.-]+", "_", name))
        ms = statistics.median([bake(args, out, settings) for _ in range(args.reps)])
        mean_rel, rmse = compare(os.path.join(out, "sky_latlong.exr"), os.path.join(ref_dir, "sky_latlong.exr"),
                                 args.height)
        rows.append((name, ms / 1e3 / mpx, mean_rel, rmse))
        sys.stderr.write(f"{name}: {ms:.0f} ms, {mean_rel:.2e}, {rmse:.2e}\n")

    case("production", PRODUCTION)
    for key, values in sweep.items():
        for v in values:
            case(f"{key}={v}", dict(PRODUCTION, **{key: v}))
    # Half the reference's steps: how far the reference itself is from converged.
    case(f"reference/2 ({args.ref_view_steps // 2}/{args.ref_light_steps // 2} steps)",
         dict(ref, cloud_view_steps=args.ref_view_steps // 2, cloud_light_steps=args.ref_light_steps // 2))
    print(f"Reference: {args.ref_view_steps} view / {args.ref_light_steps} light steps, volumes 128/64/512, "
          f"{ref_ms / 1e3 / mpx:.2f} s per megapixel; latlong {2 * args.height} x {args.height}, upper half.\n")
    print("| setting (production otherwise) | cloud pass, s per Mpx | mean rel. error | rel. RMSE |")
    print("| --- | ---: | ---: | ---: |")
    for name, s, e, r in rows:
        print(f"| {name} | {s:.2f} | {e:.2e} | {r:.2e} |")
    for name, s, e, r in rows:
        if not (math.isfinite(e) and math.isfinite(r) and s >= 0.0):
            sys.exit(f"{name}: not a finite error")
    if args.smoke and not rows[-1][2] < rows[0][2]:
        sys.exit("the reference at half its steps is further from it than production: not converged")
    if args.csv:
        with open(args.csv, "w") as f:
            f.write("setting,seconds_per_megapixel,mean_relative_error,relative_rmse\n")
            for name, s, e, r in rows:
                f.write(f"{name},{s:.4f},{e:.4e},{r:.4e}\n")


if __name__ == "__main__":
    main()
