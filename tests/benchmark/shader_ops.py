#!/usr/bin/env python3
"""Floating-point operations of the compiled shaders, counted from their SPIR-V.

    python3 tests/benchmark/shader_ops.py [--build build] [--glslang glslangValidator]

Compiles each shader variant skybake embeds (the list and flags of
CMakeLists.txt's SKYBAKE_SHADERS) to SPIR-V in a temporary folder, reads it
back with spirv-dis, and counts per shader:
- its size (bytes of SPIR-V) and its functions, calls and loops;
- its floating-point operations, statically: each arithmetic instruction
  (OpFAdd, OpFSub, OpFMul, OpFDiv, OpFNegate, OpFMod, OpFRem, OpDot,
  OpVectorTimesScalar, OpMatrixTimesVector, OpFOrd*/OpFUnord* compares,
  and GLSL.std.450's Fma as 2, its min/max/clamp/mix/floor/... as 1 and its
  transcendentals (exp, exp2, log, log2, pow, sqrt, inversesqrt, sin, cos,
  tan, asin, acos, atan, atan2) as 1 each) times the width of its result
  (a vec3 multiply is 3); `--transcendental N` counts each transcendental as
  N instead (llvmpipe expands them into polynomials of about 10-20 operations);
- the operations inside loops, and the largest loop body at the outermost
  level (a march's step: what a sample costs), the loops' blocks taken as
  those between a loop header (OpLoopMerge) and its merge block.

A static count is not a count of executed operations: a branch not taken
still counts, and a loop counts once. `--steps` turns the largest outermost
loop into an estimate per invocation (outside-loop operations + steps x the
loop's), the figure docs/performance.md divides by the measured pass time.
"""
import argparse
import os
import re
import subprocess
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

ARITH = {"OpFAdd": 1, "OpFSub": 1, "OpFMul": 1, "OpFDiv": 1, "OpFNegate": 1, "OpFMod": 1, "OpFRem": 1,
         "OpVectorTimesScalar": 1}
EXT_ONE = {"FAbs", "FSign", "Floor", "Ceil", "Fract", "FMin", "FMax", "FClamp", "FMix", "Step", "SmoothStep",
           "Round", "RoundEven", "Trunc", "NMin", "NMax", "NClamp", "Normalize", "Length", "Distance", "Cross",
           "Reflect", "Ldexp", "Frexp"}
EXT_TRANSCENDENTAL = {"Exp", "Exp2", "Log", "Log2", "Pow", "Sqrt", "InverseSqrt", "Sin", "Cos", "Tan", "Asin", "Acos",
                      "Atan", "Atan2", "Sinh", "Cosh", "Tanh"}


def shaders_of_cmake():
    """(shader, define or None, array name) from CMakeLists.txt's SKYBAKE_SHADERS."""
    text = open(os.path.join(ROOT, "CMakeLists.txt")).read()
    block = text[text.index("set(SKYBAKE_SHADERS"):]
    block = block[:block.index(")")]
    return [(s, None if d == "-" else d, v) for s, d, v in re.findall(r'"(\S+) (\S+) (\S+)"', block)]


def compile_spirv(glslang, shader, define, out):
    flags = [] if define is None else [f"-D{define}", "-Os"]
    subprocess.run([glslang, "-V", "--target-env", "vulkan1.1", "--quiet", *flags, "-I" + os.path.join(ROOT, "shaders"),
                    "-I" + os.path.join(ROOT, "include"), "-o", out, os.path.join(ROOT, "shaders", shader + ".comp")],
                   check=True)


def count(spv, transcendental):
    dis = subprocess.run(["spirv-dis", "--raw-id", spv], capture_output=True, text=True, check=True).stdout
    lines = dis.splitlines()
    width = {}  # result type id -> component count
    types = {}  # value id -> type id
    for line in lines:
        m = re.match(r"\s*(%\d+) = OpTypeVector %\d+ (\d+)", line)
        if m:
            width[m.group(1)] = int(m.group(2))
        m = re.match(r"\s*(%\d+) = OpTypeMatrix (%\d+) (\d+)", line)
        if m:
            width[m.group(1)] = width.get(m.group(2), 1) * int(m.group(3))
    ops_of_line = []
    for line in lines:
        m = re.match(r"\s*%\d+ = (Op\w+) (%\d+)(.*)", line)
        ops = 0
        if m:
            op, rtype, rest = m.groups()
            w = width.get(rtype, 1)
            if op in ARITH:
                ops = w
            elif op == "OpDot":
                ops = 2 * 3 - 1  # a vec3 dot: 3 multiplies, 2 adds (the vectors here are vec3 or vec4)
            elif op == "OpMatrixTimesVector":
                ops = 2 * w * w
            elif op.startswith("OpFOrd") or op.startswith("OpFUnord"):
                ops = w
            elif op == "OpExtInst":
                name = rest.split()[1] if len(rest.split()) > 1 else ""
                if name == "Fma":
                    ops = 2 * w
                elif name in EXT_TRANSCENDENTAL:
                    ops = transcendental * w
                elif name in EXT_ONE:
                    ops = w
        ops_of_line.append(ops)
    # Loops: from a header's label to its merge block's label (glslang lays constructs out contiguously).
    label_line = {}
    for i, line in enumerate(lines):
        m = re.match(r"\s*(%\d+) = OpLabel", line)
        if m:
            label_line[m.group(1)] = i
    loops = []  # (first line, end line)
    current_label = None
    for i, line in enumerate(lines):
        m = re.match(r"\s*(%\d+) = OpLabel", line)
        if m:
            current_label = i
        m = re.match(r"\s*OpLoopMerge (%\d+)", line)
        if m and m.group(1) in label_line:
            loops.append((current_label, label_line[m.group(1)]))
    in_loop = [False] * len(lines)
    for a, b in loops:
        for i in range(a, b):
            in_loop[i] = True
    outermost = [(a, b) for a, b in loops if not any(c < a and b <= d for c, d in loops if (c, d) != (a, b))]
    biggest = max((sum(ops_of_line[a:b]) for a, b in outermost), default=0)
    total = sum(ops_of_line)
    looped = sum(o for o, l in zip(ops_of_line, in_loop) if l)
    return {"bytes": os.path.getsize(spv), "functions": dis.count(" = OpFunction "),
            "calls": dis.count("OpFunctionCall"), "loops": len(loops), "total": total, "outside": total - looped,
            "looped": looped, "biggest_loop": biggest}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--glslang", default="glslangValidator")
    ap.add_argument("--transcendental", type=int, default=1)
    ap.add_argument("--steps", type=int, default=32, help="steps of the largest loop per invocation (view_steps)")
    ap.add_argument("--only", default=None, help="one array name (kSkyviewLutAnalyticSpv, ...)")
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        print(f"transcendental = {args.transcendental} operation(s); per invocation = outside loops + "
              f"{args.steps} x the largest outermost loop\n")
        print("| shader (array) | SPIR-V bytes | functions | calls | loops | FP ops (static) | outside loops | "
              "in loops | largest outermost loop body | per invocation |")
        print("| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |")
        for shader, define, var in shaders_of_cmake():
            if args.only and var != args.only:
                continue
            spv = os.path.join(tmp, var + ".spv")
            compile_spirv(args.glslang, shader, define, spv)
            c = count(spv, args.transcendental)
            per = c["outside"] + args.steps * c["biggest_loop"]
            print(f"| {shader} ({var}) | {c['bytes']} | {c['functions']} | {c['calls']} | {c['loops']} | "
                  f"{c['total']} | {c['outside']} | {c['looped']} | {c['biggest_loop']} | {per} |")


if __name__ == "__main__":
    main()
