#!/usr/bin/env python3
"""Equal-time error of two prism binaries on every shipped scene.

Usage (from the repository root; needs numpy and OpenEXR):
    python3 benches/profile/equal_time.py OLD_BINARY NEW_BINARY [--seconds 2] [--seeds 3]

Samples per second compare the work per sample, not what a sample buys: an
estimator that costs more per sample and converges faster (light paths for
caustics, roulette that keeps glass paths alive) shows as slower there.
This measures what a user watching the image sees: the RMSE against a long
reference after the same wall time. For each scene the NEW binary renders
the reference (--reference-spp samples, 2 threads, its own seed); then the
two binaries render --seconds each on one thread, interleaved (old, new, old,
new, ...) over --seeds seeds (at least 2). Errors are over all pixels and
channels of the linear image. The noise of each binary's renders is measured
without the reference, as half the mean squared difference of two renders
with different seeds (for an unbiased estimator, its expected squared error),
so the reference's own noise, not small against 8-s renders of the fast
scenes, does not flatten the ratio; `old_over_new` is the ratio of those
RMS noises, above 1 where the new binary converges faster, and its square
the ratio of the times the two need for the same error. The RMSE against
the reference (which includes the reference's noise) and the ratio of mean
pixel values to the reference's check that both render the same image.
Prints CSV.
"""
import argparse
import pathlib
import subprocess
import tempfile

import numpy as np
import OpenEXR


def read(path):
    return np.asarray(OpenEXR.File(str(path)).parts[0].channels["RGB"].pixels, dtype=np.float64)


def noise(images):
    """RMS error of one render, from the squared differences of every pair:
    E[(a - b)^2] = 2 Var for independent unbiased renders a and b."""
    pairs = [(a, b) for i, a in enumerate(images) for b in images[i + 1:]]
    return np.sqrt(np.mean([np.mean((a - b) ** 2) / 2 for a, b in pairs]))


def render(binary, scene, output, width, height, threads, seed, extra):
    subprocess.run([binary, "render", str(scene), "--width", str(width), "--height", str(height),
                    "--threads", str(threads), "--seed", str(seed), "--quiet", "-o", str(output), *extra],
                   check=True, capture_output=True)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("old")
    parser.add_argument("new")
    parser.add_argument("--seconds", type=float, default=2.0)
    parser.add_argument("--seeds", type=int, default=3, help="renders per binary and scene (at least 2)")
    parser.add_argument("--width", type=int, default=128)
    parser.add_argument("--height", type=int, default=96)
    parser.add_argument("--reference-spp", type=int, default=4096)
    parser.add_argument("--scenes", default="", help="comma-separated scene names (default: all the old binary reads)")
    args = parser.parse_args()
    wanted = {name for name in args.scenes.split(",") if name}
    if args.seeds < 2:
        parser.error("--seeds must be at least 2: the noise is measured between renders")
    print("scene,seconds,seeds,old_rmse,new_rmse,old_noise,new_noise,old_over_new,old_mean_over_reference,"
          "new_mean_over_reference")
    with tempfile.TemporaryDirectory() as out:
        out = pathlib.Path(out)
        for scene in sorted(pathlib.Path("scenes").glob("*.toml")):
            if wanted and scene.stem not in wanted:
                continue
            if any(line.replace(" ", "").startswith('integrator="sppm"') for line in scene.read_text().splitlines()):
                continue  # SPPM's error depends on its radius schedule: measured in docs/performance.md
            probe = subprocess.run([args.old, "render", str(scene), "--width", "8", "--height", "8", "--spp", "1",
                                    "--quiet", "-o", str(out / "probe.exr")], capture_output=True)
            if probe.returncode != 0:
                print(f"# {scene.stem}: the old binary cannot read this scene; skipped", flush=True)
                continue
            reference_path = out / "reference.exr"
            render(args.new, scene, reference_path, args.width, args.height, 2, 1_000_003,
                   ["--spp", str(args.reference_spp)])
            reference = read(reference_path)
            errors = {"old": [], "new": []}
            means = {"old": [], "new": []}
            images = {"old": [], "new": []}
            for seed in range(1, args.seeds + 1):
                for which in ("old", "new"):
                    path = out / f"{which}.exr"
                    render(getattr(args, which), scene, path, args.width, args.height, 1, seed,
                           ["--time", str(args.seconds)])
                    image = read(path)
                    images[which].append(image)
                    errors[which].append(np.sqrt(np.mean((image - reference) ** 2)))
                    means[which].append(image.mean() / reference.mean())
            old_rmse, new_rmse = np.mean(errors["old"]), np.mean(errors["new"])
            old_noise, new_noise = noise(images["old"]), noise(images["new"])
            print(f"{scene.stem},{args.seconds},{args.seeds},{old_rmse:.5g},{new_rmse:.5g},{old_noise:.5g},"
                  f"{new_noise:.5g},{old_noise / new_noise:.3f},{np.mean(means['old']):.4f},"
                  f"{np.mean(means['new']):.4f}", flush=True)


if __name__ == "__main__":
    main()
