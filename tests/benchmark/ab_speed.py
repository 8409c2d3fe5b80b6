#!/usr/bin/env python3
"""Two skybake builds, run alternately on W1 and W2 (docs/performance.md).

    python3 tests/benchmark/ab_speed.py --before OLD/skybake --after build/skybake \
        [--reps-w1 9] [--reps-w2 3]

Each repetition runs both builds back to back, the order swapped every
time (ABBA), so that a change of the machine's load falls on both alike.
Reported per workload: the median wall and CPU seconds (user + system of
the bake process) of each build, the median of the per-pair ratios
after/before, the load average before and after the runs, and whether the
two builds wrote the same bytes (the last run of each).
"""
import argparse
import hashlib
import os
import statistics
import sys
import tempfile

from performance import ROOT, run as run_process


def run(cmd):
    """Runs cmd from the project root; returns (wall s, CPU s of the process). Fails loudly."""
    wall, _, cpu = run_process(cmd)
    return wall, cpu


def tree_digest(folder):
    """SHA-256 over the image files of a bake (names and bytes; not timings or manifests)."""
    digest = hashlib.sha256()
    for dirpath, _, files in sorted(os.walk(folder)):
        for name in sorted(files):
            if name.endswith((".exr", ".png")):
                path = os.path.join(dirpath, name)
                digest.update(os.path.relpath(path, folder).encode())
                with open(path, "rb") as f:
                    digest.update(f.read())
    return digest.hexdigest()


def compare(label, args_of, builds, reps, work):
    samples = {name: [] for name in builds}
    for rep in range(reps):
        order = list(builds) if rep % 2 == 0 else list(reversed(builds))
        for name in order:
            out = os.path.join(work, f"{label}-{name}")
            wall, cpu = run([builds[name], "bake", *args_of, "--out", out, "--force", "--quiet"])
            samples[name].append((wall, cpu))
            sys.stderr.write(f"{label} {name} run {rep + 1}/{reps}: {wall:.2f} s wall, {cpu:.2f} s CPU\n")
    same = tree_digest(os.path.join(work, f"{label}-before")) == tree_digest(os.path.join(work, f"{label}-after"))
    row = {"label": label, "same_bytes": same}
    for i, kind in enumerate(("wall", "cpu")):
        for name in builds:
            row[f"{name}_{kind}"] = statistics.median(s[i] for s in samples[name])
        row[f"ratio_{kind}"] = statistics.median(a[i] / b[i] for a, b in zip(samples["after"], samples["before"]))
    return row


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--before", required=True, help="the skybake binary to compare against")
    parser.add_argument("--after", default=os.path.join(ROOT, "build", "skybake"), help="the skybake binary under test")
    parser.add_argument("--reps-w1", type=int, default=9, help="repetitions of W1 per build")
    parser.add_argument("--reps-w2", type=int, default=3, help="repetitions of W2 (96 frames) per build")
    parser.add_argument("--work", default=None, help="scratch folder (default: a new temporary one)")
    args = parser.parse_args()
    work = args.work or tempfile.mkdtemp(prefix="skybake-ab-")
    builds = {"before": os.path.abspath(args.before), "after": os.path.abspath(args.after)}
    w1 = ["configs/benchmark/w1.toml"]
    w2 = w1 + ["--schedule", "configs/benchmark/w2.toml"]
    load_start = os.getloadavg()
    rows = [compare("W1", w1, builds, args.reps_w1, work)]
    if args.reps_w2 > 0:
        rows.append(compare("W2", w2, builds, args.reps_w2, work))
    load_end = os.getloadavg()
    print(f"load average (1/5/15 min): {load_start[0]:.2f}/{load_start[1]:.2f}/{load_start[2]:.2f} before, "
          f"{load_end[0]:.2f}/{load_end[1]:.2f}/{load_end[2]:.2f} after")
    print("| workload | before wall | after wall | after/before wall | before CPU | after CPU | after/before CPU "
          "| same bytes |")
    print("|---|---:|---:|---:|---:|---:|---:|---|")
    for r in rows:
        print(f"| {r['label']} | {r['before_wall']:.2f} s | {r['after_wall']:.2f} s | {r['ratio_wall']:.3f} "
              f"| {r['before_cpu']:.2f} s | {r['after_cpu']:.2f} s | {r['ratio_cpu']:.3f} "
              f"| {'yes' if r['same_bytes'] else 'NO'} |")


if __name__ == "__main__":
    main()
