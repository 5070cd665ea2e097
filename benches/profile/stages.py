#!/usr/bin/env python3
"""Where one sample's instructions go, by stage, from a callgrind profile.

Usage (from the repository root):
    cargo build --profile profiling
    PRISM_KERNEL=portable valgrind --tool=callgrind --callgrind-out-file=cg.out \
        target/profiling/prism render scenes/cornell.toml \
        --width 64 --height 64 --spp 16 --threads 1 --quiet -o /tmp/x.exr
    python3 benches/profile/stages.py cg.out --samples 65536

The profiling build keeps line tables, so callgrind attributes inlined code to
the source file it came from; each (file, function) cost is put in a stage by
its source file, or by its function when the file is a library's (glam, core,
libm). Instruction counts are stable on a busy machine, unlike times.
PRISM_KERNEL=portable runs the baseline copies of the ray queries and path
loop: Valgrind 3.19 cannot decode every instruction of the AVX2 copies.
"""
import argparse
import collections
import re
import subprocess

# (stage, test on the source file, test on the function), first match wins.
STAGES = [
    ("camera ray", lambda f: "/src/camera" in f, lambda n: "Camera::" in n),
    ("sampler", lambda f: "/src/sampler" in f, lambda n: "Sampler::" in n),
    ("light sampling", lambda f: "/src/light" in f or "/geometry/sampling" in f or "/math/warp" in f,
     lambda n: "Lights::" in n or "sample_from" in n or "sample_area" in n or "Shape::area" in n),
    ("shadow rays", lambda f: False, lambda n: "occluded" in n),
    ("intersection", lambda f: "/src/accel/" in f or "/src/geometry/" in f or "/src/scene/" in f or "/math/ray" in f,
     lambda n: "Scene::intersect" in n or "hit_distance" in n or "::intersect" in n or "surface_hit" in n
     or "offset_ray_origin" in n or "BallOptics" in n),
    ("BSDF", lambda f: "/src/material/" in f, lambda n: "Material::" in n or "Texture::" in n),
    ("shading frame", lambda f: "/math/frame" in f, lambda n: "Frame::" in n),
    ("film", lambda f: "/src/film" in f, lambda n: "PixelAccumulator" in n or "Film::" in n),
    ("integrator", lambda f: "/src/integrator/" in f,
     lambda n: "PathIntegrator" in n or "PathTracer" in n or "Sppm" in n or "photon" in n),
]


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("profile")
    parser.add_argument("--samples", type=float, default=0, help="samples rendered, for instructions per sample")
    args = parser.parse_args()
    out = subprocess.run(["callgrind_annotate", "--inclusive=no", "--threshold=100", args.profile],
                         capture_output=True, text=True, check=True).stdout
    out = out.split("Auto-annotated source")[0]
    stages = collections.Counter()
    total = 0
    for line in out.splitlines():
        m = re.match(r"\s*([\d,]+)\s+\(\s*[\d.]+%\)\s+(.*)", line)
        if not m:
            continue
        cost = int(m.group(1).replace(",", ""))
        name = m.group(2)
        if "PROGRAM TOTALS" in name:
            total = cost
            continue
        file, _, function = name.partition(":")
        # callgrind_annotate prints files under the current folder relatively
        # ("src/…" when run from the repository root): anchor them so the
        # "/src/…" tests match either way.
        if not file.startswith("/"):
            file = "/" + file
        function = re.sub(r"\s*\[.*\]$", "", function)
        stage = next((s for s, by_file, _ in STAGES if by_file(file)), None)
        if stage is None:
            stage = next((s for s, _, by_function in STAGES if by_function(function)), "other (start-up, output, libm)")
        stages[stage] += cost
    print(f"{'stage':<32} {'share':>7} {'instructions':>15}" + ("  per sample" if args.samples else ""))
    for stage, cost in stages.most_common():
        per = f"  {cost / args.samples:10.0f}" if args.samples else ""
        print(f"{stage:<32} {cost / total * 100:6.1f}% {cost:>15,}{per}")
    per = f"  {total / args.samples:10.0f}" if args.samples else ""
    print(f"{'total':<32} {100:6.1f}% {total:>15,}{per}")


if __name__ == "__main__":
    main()
