#!/usr/bin/env python3
"""Two skybake binaries alternated on one bake: the median of each stage and pass, and whether the bytes match.

    python3 tests/benchmark/compare_stages.py BEFORE/skybake AFTER/skybake [--runs 5] [--set KEY=VALUE ...]

Each process compiles its shaders (Mesa's shader cache and skybake's pipeline cache off), so the
pipelines stage and the first dispatch of each pass are counted as a fresh farm process pays them.
Reads each bake's timings.json; prints medians and after/before ratios, then cmp of every EXR.
Run from the checkout (configs/benchmark/w1.toml by default). A benchmark, not a test: no bound.
"""
import argparse
import json
import os
import statistics
import subprocess
import tempfile


def bake(binary, style, sets, out):
    env = dict(os.environ, MESA_SHADER_CACHE_DISABLE="true", SKYBAKE_PIPELINE_CACHE="0")
    args = [binary, "bake", style, "--out", out, "--force", "-q"]
    for s in sets:
        args += ["--set", s]
    subprocess.run(args, env=env, check=True, stdout=subprocess.DEVNULL)
    t = json.load(open(os.path.join(out, "timings.json")))
    figures = {"stage " + s["stage"]: s["seconds"] for s in t["stages"]}
    for p in t["frames"][0]["gpu_passes"]:
        figures["pass " + p["name"]] = figures.get("pass " + p["name"], 0.0) + p["gpu_ms"] / 1e3
    figures["whole process"] = t["total_s"]
    return figures


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("before")
    parser.add_argument("after")
    parser.add_argument("--runs", type=int, default=5)
    parser.add_argument("--style", default="configs/benchmark/w1.toml")
    parser.add_argument("--set", action="append", default=[], dest="sets")
    args = parser.parse_args()
    work = tempfile.mkdtemp(prefix="skybake-compare-")
    runs = {"before": [], "after": []}
    for _ in range(args.runs):
        for name in ("before", "after"):
            runs[name].append(bake(getattr(args, name), args.style, args.sets, os.path.join(work, name)))
    print(f"{args.style} {' '.join(args.sets)}: medians of {args.runs} alternated runs (seconds)")
    print(f"| figure | before | after | after / before |\n| --- | ---: | ---: | ---: |")
    for key in runs["before"][0]:
        b = statistics.median(r[key] for r in runs["before"])
        a = statistics.median(r.get(key, 0.0) for r in runs["after"])
        if b > 0:
            print(f"| {key} | {b:.4f} | {a:.4f} | {a / b:.3f} |")
    exrs = sorted(f for f in os.listdir(os.path.join(work, "before")) if f.endswith(".exr"))
    same = [f for f in exrs if subprocess.run(["cmp", "-s", os.path.join(work, "before", f),
                                                os.path.join(work, "after", f)]).returncode == 0]
    print(f"EXRs identical: {len(same)} of {len(exrs)}" + ("" if len(same) == len(exrs) else
          " (differ: " + ", ".join(sorted(set(exrs) - set(same))) + ")"))


if __name__ == "__main__":
    main()
