#!/usr/bin/env python3
"""Where the Cornell box's equal-time error lies: inside the mirror ball, inside
the glass ball, or elsewhere.

Usage (from the repository root, after `cargo build --release`):
    python3 benches/profile/error_regions.py [--prism target/release/prism]
        [--seconds 8] [--threads 2] [-- extra prism render arguments]

Renders scenes/cornell.toml twice (seeds 1 and 2) at the size of
references/cornell.exr and prints, per region, its share of the squared error
against the reference and of the run-to-run noise (the squared difference of
the two renders over 2), each divided by the image's sample count so that the
regions add up to the whole image's mean squared error. The balls' regions
are the pixels whose centre's pinhole ray meets the ball (the camera and
spheres of scenes/cornell.toml). Needs numpy and OpenEXR (pip).
"""

import argparse
import math
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
import OpenEXR

# scenes/cornell.toml: camera, vertical field of view, and the two balls.
CAMERA = np.array([278.0, 273.0, -800.0])
FOV_Y_DEGREES = 39.3
MIRROR_BALL = (np.array([380.0, 100.0, 380.0]), 100.0)
GLASS_BALL = (np.array([180.0, 100.0, 200.0]), 100.0)


def read_exr(path):
    with OpenEXR.File(str(path)) as exr:
        channels = exr.channels()
        if "RGB" in channels:
            return np.asarray(channels["RGB"].pixels, dtype=np.float64)
        return np.stack([np.asarray(channels[c].pixels, dtype=np.float64) for c in "RGB"], -1)


def ball_mask(height, width, ball):
    """Pixels whose centre's ray from the pinhole meets the ball. The camera
    looks along +z with +x on the image's left (the scene's convention)."""
    center, radius = ball
    tan_half = math.tan(math.radians(FOV_Y_DEGREES) / 2)
    ys, xs = np.mgrid[0:height, 0:width]
    dx = -((xs + 0.5) / width * 2 - 1) * tan_half * width / height
    dy = -((ys + 0.5) / height * 2 - 1) * tan_half
    d = np.stack([dx, dy, np.ones_like(dx)], -1)
    d /= np.linalg.norm(d, axis=-1, keepdims=True)
    oc = CAMERA - center
    b = (d * oc).sum(-1)
    return b * b - (oc @ oc - radius * radius) > 0


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--prism", default="target/release/prism")
    parser.add_argument("--seconds", default="8")
    parser.add_argument("--threads", default="2")
    parser.add_argument("extra", nargs="*", help="further `prism render` arguments (after --)")
    args = parser.parse_args()
    reference = read_exr("references/cornell.exr")
    height, width, _ = reference.shape
    mirror = ball_mask(height, width, MIRROR_BALL)
    glass = ball_mask(height, width, GLASS_BALL)
    images = []
    with tempfile.TemporaryDirectory() as folder:
        for seed in (1, 2):
            out = Path(folder) / f"cornell-{seed}.exr"
            command = [args.prism, "render", "scenes/cornell.toml", "--time", args.seconds, "--threads", args.threads,
                       "--seed", str(seed), "--width", str(width), "--height", str(height), "-o", str(out), "--quiet"]
            subprocess.run(command + args.extra, check=True)
            images.append(read_exr(out))
    print("region,pixel_fraction,squared_error,run_to_run_noise")
    for name, mask in [("mirror ball", mirror), ("glass ball", glass), ("elsewhere", ~(mirror | glass))]:
        error = np.mean([((image - reference) ** 2)[mask].sum() / reference.size for image in images])
        noise = ((images[0] - images[1]) ** 2)[mask].sum() / reference.size / 2
        print(f"{name},{mask.mean():.3f},{error:.3e},{noise:.3e}")
    rmse = [math.sqrt(((image - reference) ** 2).mean()) for image in images]
    print(f"# RMSE of the two renders: {rmse[0]:.4f}, {rmse[1]:.4f}", file=sys.stderr)


if __name__ == "__main__":
    main()
