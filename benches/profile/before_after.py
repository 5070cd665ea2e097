#!/usr/bin/env python3
"""Samples per second of two prism binaries on every shipped scene.

Usage (from the repository root):
    python3 benches/profile/before_after.py OLD_BINARY NEW_BINARY [--threads 2] [--spp 64]

Runs are interleaved (old, new, old, new) so machine load falls on both alike,
and each binary's faster run is kept. Each render is 256×192 at --spp samples
(SPPM scenes: --spp/4 iterations) with a fixed seed; the time is the whole
process's (scene load and BVH build included, small against the render here).
Prints CSV.
"""
import argparse
import pathlib
import subprocess
import tempfile
import time


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("old")
    parser.add_argument("new")
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--spp", type=int, default=64)
    parser.add_argument("--rounds", type=int, default=2)
    args = parser.parse_args()
    print("scene,integrator,threads,samples,old_seconds,new_seconds,old_samples_per_s,new_samples_per_s,speedup")
    with tempfile.TemporaryDirectory() as out:
        for scene in sorted(pathlib.Path("scenes").glob("*.toml")):
            sppm = any(line.replace(" ", "").startswith('integrator="sppm"') for line in scene.read_text().splitlines())
            integrator, count = ("sppm", max(1, args.spp // 4)) if sppm else ("pt", args.spp)
            best = {"old": float("inf"), "new": float("inf")}
            unreadable = False
            for _ in range(args.rounds):
                for which in ("old", "new"):
                    start = time.perf_counter()
                    run = subprocess.run([getattr(args, which), "render", str(scene), "--width", "256", "--height", "192",
                                          "--spp", str(count), "--threads", str(args.threads), "--seed", "7",
                                          "--integrator", integrator, "--quiet", "-o", f"{out}/{which}.exr"],
                                         capture_output=True)
                    if run.returncode != 0:
                        # A scene newer than the old binary (a key it does not know): nothing to compare.
                        if which == "old":
                            unreadable = True
                            break
                        raise SystemExit(f"{scene}: the new binary failed: {run.stderr.decode(errors='replace')}")
                    best[which] = min(best[which], time.perf_counter() - start)
                if unreadable:
                    break
            if unreadable:
                print(f"# {scene.stem}: the old binary cannot read this scene; skipped", flush=True)
                continue
            samples = 256 * 192 * count
            print(f"{scene.stem},{integrator},{args.threads},{samples},{best['old']:.3f},{best['new']:.3f},"
                  f"{samples / best['old']:.0f},{samples / best['new']:.0f},{best['old'] / best['new']:.2f}", flush=True)


if __name__ == "__main__":
    main()
