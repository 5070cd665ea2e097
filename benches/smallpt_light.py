#!/usr/bin/env python3
"""The literal smallpt light against the disc it shows the room (docs/performance.md,
"The literal smallpt light"): RMSE at equal sample counts against each scene's own long
reference, and instructions per sample under callgrind, combined into an equal-time ratio.

usage: benches/smallpt_light.py OUT_DIR BINARY [BEFORE_BINARY]
       [--width 128] [--height 96] [--reference-spp 8192] [--spp 16,64,256] [--seeds 4]
       [--max-depth N] [--exclude-top-rows K]
       [--callgrind] [--callgrind-size 64x48] [--callgrind-spp 8,24]

Run from the repository root. References are rendered by BINARY (seed 1000, 2 threads);
each test render uses seeds 1..N. With BEFORE_BINARY the literal scene is also rendered
(and costed) by it. RMSE is over every pixel and channel of the linear EXR; MSE is averaged
over seeds before the square root. Instructions per sample are the difference of two
callgrind runs (--threads 1) at two sample counts divided by the extra samples, so start-up
and scene building cancel. Equal-time error ratio = RMSE ratio × sqrt(cost ratio), since
RMSE falls as 1/sqrt(samples) and samples per second as 1/cost. Images already in OUT_DIR
are reused, so a second run with other options only recomputes the errors.

--exclude-top-rows K leaves the image's top K rows out of the RMSE: in smallpt's view the
top row's camera rays start (at the near clip) above the ceiling and see the outside of
the room, where the literal light sphere is and the disc is not.
"""
import argparse, os, re, subprocess, sys
import numpy as np
import OpenEXR

LITERAL = "scenes/smallpt.toml"
DISC = "tests/scenes/smallpt-disk.toml"


def depth_flags(max_depth):
    return ["--max-depth", str(max_depth)] if max_depth else []


def render(binary, scene, out, width, height, spp, seed, max_depth, threads=2):
    subprocess.run([binary, "render", scene, "--width", str(width), "--height", str(height),
                    "--spp", str(spp), "--seed", str(seed), "--threads", str(threads),
                    "--quiet", "-o", out] + depth_flags(max_depth), check=True)


def pixels(path):
    with OpenEXR.File(path) as f:
        channels = f.channels()
        if "RGB" in channels:
            return channels["RGB"].pixels.astype(np.float64)
        return np.stack([channels[c].pixels.astype(np.float64) for c in "RGB"], axis=-1)


def instructions(binary, scene, width, height, spp, max_depth, out):
    # The baseline copies of the ray queries and path loop: Valgrind 3.19
    # cannot decode every instruction of the AVX2 copies (SIGILL).
    environment = dict(os.environ, PRISM_KERNEL="portable")
    result = subprocess.run(["valgrind", "--tool=callgrind", "--callgrind-out-file=/dev/null",
                             binary, "render", scene, "--width", str(width), "--height", str(height),
                             "--spp", str(spp), "--seed", "1", "--threads", "1", "--quiet",
                             "-o", os.path.join(out, "callgrind.exr")] + depth_flags(max_depth),
                            capture_output=True, text=True, env=environment)
    found = re.search(r"Collected : (\d+)", result.stderr)
    if not found:
        sys.exit(f"callgrind gave no count:\n{result.stderr[-2000:]}")
    return int(found.group(1))


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("out")
    parser.add_argument("binary")
    parser.add_argument("before", nargs="?")
    parser.add_argument("--width", type=int, default=128)
    parser.add_argument("--height", type=int, default=96)
    parser.add_argument("--reference-spp", type=int, default=8192)
    parser.add_argument("--spp", default="16,64,256")
    parser.add_argument("--seeds", type=int, default=4)
    parser.add_argument("--max-depth", type=int, help="bounces (default: the scenes' 32)")
    parser.add_argument("--exclude-top-rows", type=int, default=0)
    parser.add_argument("--callgrind", action="store_true")
    parser.add_argument("--callgrind-size", default="64x48")
    parser.add_argument("--callgrind-spp", default="8,24")
    args = parser.parse_args()
    os.makedirs(args.out, exist_ok=True)
    size = (args.width, args.height)

    runs = [("disc", args.binary, DISC), ("literal", args.binary, LITERAL)]
    if args.before:
        runs.append(("literal-before", args.before, LITERAL))
    references = {}
    for scene in (DISC, LITERAL):
        path = os.path.join(args.out, f"reference-{os.path.basename(scene)[:-5]}.exr")
        if not os.path.exists(path):
            render(args.binary, scene, path, *size, args.reference_spp, 1000, args.max_depth)
        references[scene] = pixels(path)[args.exclude_top_rows:]

    print(f"RMSE at {args.width}x{args.height} (top {args.exclude_top_rows} rows left out), mean of "
          f"MSE over seeds 1..{args.seeds}, against {args.reference_spp}-spp references")
    rmse = {}
    for spp in [int(s) for s in args.spp.split(",")]:
        for name, binary, scene in runs:
            errors = []
            for seed in range(1, args.seeds + 1):
                path = os.path.join(args.out, f"{name}-{spp}-{seed}.exr")
                if not os.path.exists(path):
                    render(binary, scene, path, *size, spp, seed, args.max_depth)
                errors.append(np.mean((pixels(path)[args.exclude_top_rows:] - references[scene]) ** 2))
            rmse[name, spp] = float(np.sqrt(np.mean(errors)))
        line = "  ".join(f"{name} {rmse[name, spp]:.5f}" for name, _, _ in runs)
        ratios = "  ".join(f"{name}/disc {rmse[name, spp] / rmse['disc', spp]:.3f}" for name, _, _ in runs[1:])
        print(f"spp {spp:5}: {line}   {ratios}")

    if args.callgrind:
        width, height = (int(v) for v in args.callgrind_size.split("x"))
        low, high = (int(v) for v in args.callgrind_spp.split(","))
        cost = {}
        for name, binary, scene in runs:
            counts = [instructions(binary, scene, width, height, spp, args.max_depth, args.out) for spp in (low, high)]
            cost[name] = (counts[1] - counts[0]) / (width * height * (high - low))
            print(f"{name}: {counts[0]} and {counts[1]} instructions at {low} and {high} spp: "
                  f"{cost[name]:.0f} per sample")
        for name, _, _ in runs[1:]:
            spp = max(s for (n, s) in rmse if n == name)
            ratio = rmse[name, spp] / rmse["disc", spp]
            cost_ratio = cost[name] / cost["disc"]
            print(f"{name}: RMSE ratio {ratio:.3f} at {spp} spp, cost ratio {cost_ratio:.3f}, "
                  f"equal-time error ratio {ratio * cost_ratio ** 0.5:.3f}")


if __name__ == "__main__":
    main()
