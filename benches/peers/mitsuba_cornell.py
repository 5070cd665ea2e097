#!/usr/bin/env python3
"""Mitsuba 3 against Prism on the same scenes: paths per second and
equal-time error.

The Prism scene files (default scenes/cornell.toml, scenes/bunny.toml and
benches/peers/cornell_box_mitsuba.toml, Mitsuba's own `mitsuba.cornell_box()`
written as a Prism scene) are translated into Mitsuba scene dictionaries here
(`translate`), so both renderers see the same geometry, camera, materials and
lights:

- camera: `perspective`, vertical field of view (`fov_axis = "y"`), look-at
  frame from position, look_at and up; a box pixel filter one pixel wide, as
  Prism's uniform sampling of each pixel's square;
- diffuse: `diffuse` inside `twosided` (Prism's Lambertian reflects on both
  faces; Mitsuba's is one-sided); mirror: `conductor` with `material = "none"`
  (a perfect mirror) times the tint; glass: `dielectric` with
  `int_ior = ior`, `ext_ior = 1` (Mitsuba's default outside is air, 1.000277);
  emissive: an `area` emitter (one-sided, like Prism's default) on a shape
  that reflects nothing; a non-black background: a `constant` emitter;
- quads: `rectangle` mapped onto corner + a·edge_u + b·edge_v (its normal
  edge_u × edge_v, as Prism's); OBJ meshes: `obj` with the same
  scale → rotate x, y, z → translate transform, and face normals when the
  file has no `vn` lines (Mitsuba would otherwise invent smooth normals that
  Prism does not use);
- depth: Prism's `max_depth` counts bounces: emission is gathered at up to
  max_depth + 1 path segments (the camera ray plus max_depth bounces, by a
  BSDF sample or by next-event estimation from the last bounce). Mitsuba's
  `path` integrator's `max_depth` counts segments (1: emitters seen
  directly; 2: direct lighting), so Mitsuba gets max_depth + 1. Checked on
  cornell.toml at 64×64: Prism with max_depth 1 and 2 (1024 spp) against
  Mitsuba with 1 to 4 (1024 spp): the image means agree (|z| ≤ 0.2 per
  channel) only for Mitsuba's max_depth = Prism's + 1 (|z| ≥ 14 otherwise).

Known differences that do not change the expected image but do change noise
and cost (the equal-time error is the measure that accounts for them):
Russian roulette (Prism from the 4th segment, survival the square root of
max(throughput), capped at 0.95; Mitsuba's `rr_depth`, default 5, `--rr-depth`), light selection
(Prism by power, Mitsuba uniform), the background (Prism finds it only
through BSDF samples; Mitsuba also samples it as a light, with MIS), and
samplers (Prism: Owen-scrambled Sobol'; Mitsuba: `--sampler`, default its
own default, `independent`). Hence two Mitsuba configurations
(`--configurations`): `defaults`, and `no-background-nee`, which gives the
background a light-sampling weight of 0 as in Prism (in a scene without a
background the two are the same and only `defaults` runs). On bunny.toml at
256×192 and 64 spp the latter's RMSE (0.0072) matched Prism's with its
independent sampler (`--sampler random`: 0.0073), while Mitsuba's defaults
gave 0.018: half its shadow rays go to the dim sky.

Measurements:

1. paths per second (camera samples per second) at the scene's own
   resolution and `--spp`, on 1 and 2 threads: Mitsuba renders once untimed
   (JIT compilation) and then the timed render; Prism is `prism render
   --spp N --threads T`, whose EXR records its render seconds (scene loading
   and BVH build excluded, as Mitsuba's `load_dict` is);
2. equal-time RMSE against the scene's reference in references/ (a 600-s
   Prism render, 256 pixels wide; `--reference-dir`), at the reference's
   size on 2 threads: Prism is `prism render --time T --seed S`; Mitsuba
   renders passes of `--pass-spp` samples per pixel, each with its own seed
   (Mitsuba's seeds start at 1 + S·2²⁰, so no pass reuses the warm-up's),
   until T seconds of rendering have passed (the rule Prism's --time follows:
   passes until the limit is reached), after one untimed pass for JIT
   compilation, and averages them. Both report the seconds they actually
   took; `efficiency` = 1 / (RMSE² × seconds) does not depend on how far a
   last pass ran over T. The per-channel mean difference from the reference
   and its z-score (difference / (RMSE / √pixels)) check that the two
   renderers agree in the mean: |z| well above 4 means a bias.

Usage (from the repository root, after `cargo build --release`):

    pip install mitsuba            # Mitsuba 3 and Dr.Jit; not a Prism dependency
    apt-get install -y libllvm19   # Dr.Jit's LLVM backend (llvm_ad_rgb)
    python3 benches/peers/mitsuba_cornell.py --output-dir docs

Writes `mitsuba_paths.csv`, `mitsuba_equal_time.csv` and `mitsuba.md` (tables
for docs/performance.md). A quick check of the script itself:
`--spp 1 --width 64 --times 0.5 --threads 1,2`. Without libLLVM the script
falls back to the `scalar_rgb` variant and says so in its CSVs (`--variant`).
Dr.Jit's threads are set with `dr.set_thread_count(T)` (the calling thread
counts as one of them).
"""

import argparse
import csv
import math
import os
import subprocess
import sys
import tempfile
import time
import tomllib
from pathlib import Path


def find_libllvm():
    """Dr.Jit looks for libLLVM.so by a few names; Debian installs the
    versioned libLLVM-19.so, which it may not find. Prefer the newest."""
    candidates = []
    for folder in ("/usr/lib/x86_64-linux-gnu", "/usr/lib/aarch64-linux-gnu", "/usr/lib"):
        for path in Path(folder).glob("libLLVM-*.so"):
            try:
                candidates.append((int(path.name[len("libLLVM-") : -len(".so")].split(".")[0]), str(path)))
            except ValueError:
                pass
    return max(candidates)[1] if candidates else None


# ---------------------------------------------------------------- translation


class Unsupported(Exception):
    pass


def rgb(value):
    return {"type": "rgb", "value": [float(c) for c in value]}


def is_colour(value):
    return isinstance(value, list) and len(value) == 3 and all(isinstance(c, (int, float)) for c in value)


def translate_material(name, material):
    """A Prism material as a Mitsuba BSDF, plus its emitter (or None)."""
    kind = material["type"]
    if kind == "diffuse":
        if not is_colour(material["albedo"]):
            raise Unsupported(f"materials.{name}: textured albedo")
        return {"type": "twosided", "bsdf": {"type": "diffuse", "reflectance": rgb(material["albedo"])}}, None
    if kind == "mirror":
        tint = material.get("tint", [1, 1, 1])
        if not is_colour(tint):
            raise Unsupported(f"materials.{name}: textured tint")
        return {"type": "conductor", "material": "none", "specular_reflectance": rgb(tint)}, None
    if kind == "glass":
        tint = material.get("tint", [1, 1, 1])
        return {
            "type": "dielectric",
            "int_ior": float(material.get("ior", 1.5)),
            "ext_ior": 1.0,
            "specular_transmittance": rgb(tint),
        }, None
    if kind == "emissive":
        if material.get("two_sided", False):
            raise Unsupported(f"materials.{name}: two-sided emitters")
        black = {"type": "diffuse", "reflectance": rgb([0, 0, 0])}
        return black, {"type": "area", "radiance": rgb(material["radiance"])}
    raise Unsupported(f"materials.{name}: type {kind}")


def euler_transform(mi, transform):
    """Prism's object transform: scale, then rotation about x, y, z, then translation."""
    T = mi.ScalarTransform4f
    scale = transform.get("scale", 1.0)
    scale = [scale] * 3 if isinstance(scale, (int, float)) else scale
    rx, ry, rz = transform.get("rotate_degrees", [0, 0, 0])
    return (
        T().translate(transform.get("translate", [0, 0, 0]))
        @ T().rotate([0, 0, 1], rz)
        @ T().rotate([0, 1, 0], ry)
        @ T().rotate([1, 0, 0], rx)
        @ T().scale(scale)
    )


def translate(mi, scene_path, width=None, height=None, sampler="independent", rr_depth=5, background_nee=True):
    """A Prism scene file as a Mitsuba scene dictionary and its settings.
    `background_nee = False` takes the background out of light sampling
    (Mitsuba's emitter `sampling_weight` 0), which is what Prism's path
    tracer does: it then finds the background only by BSDF sampling."""
    scene_path = Path(scene_path)
    with open(scene_path, "rb") as f:
        description = tomllib.load(f)
    render = description.get("render", {})
    scene_width, scene_height = render.get("width", 640), render.get("height", 480)
    if width and not height:
        height = max(1, round(width * scene_height / scene_width))
    width, height = width or scene_width, height or scene_height
    max_depth = render.get("max_depth", 16)

    camera = description["camera"]
    if camera.get("aperture_radius", 0) != 0:
        raise Unsupported("camera.aperture_radius: thin lens")
    T = mi.ScalarTransform4f
    position, look_at = camera["position"], camera["look_at"]
    distance = math.dist(position, look_at)
    sensor = {
        "type": "perspective",
        "fov_axis": "y",
        "fov": float(camera.get("fov_y_degrees", 40)),
        "to_world": T().look_at(origin=position, target=look_at, up=camera.get("up", [0, 1, 0])),
        "near_clip": float(camera.get("near_clip", 0)) or 1e-4 * distance,
        "far_clip": 1e4 * distance,
        "film": {
            "type": "hdrfilm",
            "width": width,
            "height": height,
            "pixel_format": "rgb",
            "rfilter": {"type": "box"},
        },
        "sampler": {"type": sampler, "sample_count": 1},
    }
    scene = {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": max_depth + 1, "rr_depth": rr_depth},
        "sensor": sensor,
    }
    background = description.get("background", [0, 0, 0])
    if any(c > 0 for c in background):
        scene["background"] = {"type": "constant", "radiance": rgb(background)}
        if not background_nee:
            scene["background"]["sampling_weight"] = 0.0

    materials = {name: translate_material(name, m) for name, m in description.get("materials", {}).items()}
    for index, obj in enumerate(description.get("objects", [])):
        kind = obj["type"]
        if "material" not in obj:
            raise Unsupported(f"objects[{index}]: OBJ materials")
        bsdf, emitter = materials[obj["material"]]
        if kind == "sphere":
            shape = {"type": "sphere", "center": obj["center"], "radius": float(obj["radius"])}
        elif kind == "quad":
            corner, u, v = ([float(c) for c in obj[k]] for k in ("corner", "edge_u", "edge_v"))
            normal = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]]
            length = math.sqrt(sum(c * c for c in normal))
            # Mitsuba's rectangle spans [-1, 1]² in z = 0 with normal +z: map
            # x to edge_u / 2, y to edge_v / 2 and the origin to the centre.
            columns = [[c / 2 for c in u], [c / 2 for c in v], [c / length for c in normal],
                       [corner[i] + (u[i] + v[i]) / 2 for i in range(3)]]
            matrix = [[columns[c][r] for c in range(4)] for r in range(3)] + [[0.0, 0.0, 0.0, 1.0]]
            shape = {"type": "rectangle", "to_world": T(matrix)}
        elif kind == "box":
            lo, hi = obj["min"], obj["max"]
            shape = {
                "type": "cube",
                "to_world": T().translate([(a + b) / 2 for a, b in zip(lo, hi)]) @ T().scale([(b - a) / 2 for a, b in zip(lo, hi)]),
            }
        elif kind == "mesh":
            path = (scene_path.parent / obj["file"]).resolve()
            with open(path) as f:
                has_normals = any(line.startswith("vn ") for line in f)
            shape = {
                "type": "obj",
                "filename": str(path),
                "face_normals": not has_normals,
                "to_world": euler_transform(mi, obj.get("transform", {})),
            }
        else:
            raise Unsupported(f"objects[{index}]: type {kind}")
        shape["bsdf"] = bsdf
        if emitter:
            shape["emitter"] = emitter
        scene[f"object{index:03}"] = shape
    settings = {"width": width, "height": height, "max_depth": max_depth, "has_background": "background" in scene}
    return scene, settings


# ---------------------------------------------------------------- measurement


def read_exr(path):
    """Linear RGB pixels (height × width × 3, float64) and the header."""
    import numpy as np
    import OpenEXR

    with OpenEXR.File(str(path)) as exr:
        header = dict(exr.header())
        channels = exr.channels()
        if "RGB" in channels:
            pixels = channels["RGB"].pixels[..., :3]
        elif "RGBA" in channels:
            pixels = channels["RGBA"].pixels[..., :3]
        else:
            pixels = np.stack([channels[c].pixels for c in "RGB"], axis=-1)
    return np.asarray(pixels, dtype=np.float64), header


def error_against(image, reference):
    """RMSE over pixels and channels (as Prism's metrics.rs), per-channel
    mean difference and its z-score, and the RMSE of 8×8-block means
    (noise falls 8-fold there, a bias does not)."""
    import numpy as np

    difference = image - reference
    rmse = float(np.sqrt(np.mean(difference**2)))
    pixels = difference.shape[0] * difference.shape[1]
    bias = difference.reshape(-1, 3).mean(axis=0)
    standard_error = difference.reshape(-1, 3).std(axis=0) / math.sqrt(pixels)
    h, w = (difference.shape[0] // 8) * 8, (difference.shape[1] // 8) * 8
    blocks = difference[:h, :w].reshape(h // 8, 8, w // 8, 8, 3).mean(axis=(1, 3))
    return {
        "rmse": rmse,
        "bias": [float(b) for b in bias],
        "z": [float(b / s) if s > 0 else 0.0 for b, s in zip(bias, standard_error)],
        "block_rmse": float(np.sqrt(np.mean(blocks**2))),
        "mean_ratio": float(image.mean() / reference.mean()),
    }


class Mitsuba:
    def __init__(self, variant):
        if variant.startswith("llvm") and "DRJIT_LIBLLVM_PATH" not in os.environ:
            found = find_libllvm()
            if found:
                os.environ["DRJIT_LIBLLVM_PATH"] = found
        if not self.usable(variant):
            print(f"warning: Mitsuba variant {variant} unusable here; falling back to scalar_rgb", file=sys.stderr)
            variant = "scalar_rgb"
        import drjit as dr
        import mitsuba as mi

        self.dr, self.mi = dr, mi
        self.variant = variant
        mi.set_variant(variant)

    @staticmethod
    def usable(variant):
        """Renders a tiny Cornell box in a child process: an LLVM too old for
        Dr.Jit's code aborts the process ("LLVM ERROR: Cannot select"), which
        no exception handler would catch."""
        probe = (
            "import mitsuba as mi; mi.set_variant(%r); "
            "d = mi.cornell_box(); d['sensor']['film'].update(width=8, height=8); "
            "mi.render(mi.load_dict(d), spp=1).numpy()" % variant
        )
        done = subprocess.run([sys.executable, "-c", probe], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
        if done.returncode != 0:
            lines = done.stderr.strip().splitlines() or [f"exit status {done.returncode}"]
            print(f"{variant}: {next((l for l in lines if 'ERROR' in l or 'Error' in l), lines[-1])}", file=sys.stderr)
        return done.returncode == 0

    def set_threads(self, threads):
        # Dr.Jit's nanothread pool runs the LLVM kernels, and Mitsuba's
        # scalar variants render their image blocks on it too.
        self.dr.set_thread_count(threads)

    def load(self, scene_dict):
        return self.mi.load_dict(scene_dict)

    def render(self, scene, spp, seed):
        import numpy as np

        image = self.mi.render(scene, spp=spp, seed=seed)
        return np.asarray(image, dtype=np.float64)

    def version(self):
        return f"Mitsuba {self.mi.__version__} ({self.variant}), Dr.Jit {self.dr.__version__}"


PRISM_EXTRA_ARGS = []


def prism_render(prism, scene_path, out, threads, seed, spp=None, seconds=None, width=None, height=None):
    command = [prism, "render", str(scene_path), "-o", str(out), "--threads", str(threads), "--seed", str(seed), "--quiet"]
    command += PRISM_EXTRA_ARGS
    command += ["--spp", str(spp)] if spp else ["--time", str(seconds)]
    if width:
        command += ["--width", str(width)]
    if height:
        command += ["--height", str(height)]
    subprocess.run(command, check=True, stdout=subprocess.DEVNULL)
    image, header = read_exr(out)
    return image, float(header["RenderSeconds"]), int(header["Passes"])


# Mitsuba configurations: its defaults, and the same but with the background
# left out of light sampling, as Prism's path tracer does (the same estimator
# then, up to light selection and Russian roulette; only differs from the
# defaults in scenes with a background).
CONFIGURATIONS = {"defaults": True, "no-background-nee": False}


def configurations(args, scene_path, mi):
    """The configurations that differ on this scene."""
    _, settings = translate(mi, scene_path)
    return [c for c in args.configurations if settings["has_background"] or CONFIGURATIONS[c]]


def paths_per_second(args, mitsuba, scene_path, rows):
    for threads in args.threads:
        mitsuba.set_threads(threads)
        for configuration in configurations(args, scene_path, mitsuba.mi):
            scene_dict, settings = translate(mitsuba.mi, scene_path, args.width, None, args.sampler, args.rr_depth,
                                             CONFIGURATIONS[configuration])
            scene = mitsuba.load(scene_dict)
            width, height = settings["width"], settings["height"]
            start = time.perf_counter()
            mitsuba.render(scene, args.spp, seed=0)
            first = time.perf_counter() - start
            start = time.perf_counter()
            mitsuba.render(scene, args.spp, seed=1)
            seconds = time.perf_counter() - start
            paths = width * height * args.spp
            rows.append({"scene": scene_path.stem, "renderer": "mitsuba", "configuration": configuration, "threads": threads,
                         "width": width, "height": height, "spp": args.spp, "seconds": seconds,
                         "first_render_seconds": first, "paths_per_second": paths / seconds})
            print(f"  mitsuba {configuration} {scene_path.stem} {threads} thread(s): {paths / seconds / 1e6:.3f} Mpaths/s "
                  f"({seconds:.2f} s; first render with JIT {first:.2f} s)", file=sys.stderr, flush=True)
        with tempfile.TemporaryDirectory() as folder:
            _, seconds, passes = prism_render(args.prism, scene_path, Path(folder) / "p.exr", threads, 1, spp=args.spp,
                                              width=width, height=height)
        paths = width * height * passes
        rows.append({"scene": scene_path.stem, "renderer": "prism", "configuration": "defaults", "threads": threads,
                     "width": width, "height": height, "spp": passes, "seconds": seconds, "first_render_seconds": "",
                     "paths_per_second": paths / seconds})
        print(f"  prism   {scene_path.stem} {threads} thread(s): {paths / seconds / 1e6:.3f} Mpaths/s ({seconds:.2f} s)",
              file=sys.stderr, flush=True)


def mitsuba_for(mitsuba, scene, limit, pass_spp, seed):
    """Passes of `pass_spp` samples, each with its own seed, until `limit`
    seconds have passed; their mean, the seconds taken and the samples per pixel."""
    total, passes = None, 0
    start = time.perf_counter()
    while time.perf_counter() - start < limit:
        image = mitsuba.render(scene, pass_spp, seed=seed + passes)
        total = image if total is None else total + image
        passes += 1
    return total / passes, time.perf_counter() - start, passes * pass_spp


def equal_time(args, mitsuba, scene_path, rows):
    reference_path = Path(args.reference_dir) / f"{scene_path.stem}.exr"
    reference, _ = read_exr(reference_path)
    height, width = reference.shape[:2]
    threads = args.equal_time_threads
    mitsuba.set_threads(threads)
    scenes = {}
    for configuration in configurations(args, scene_path, mitsuba.mi):
        scene_dict, _ = translate(mitsuba.mi, scene_path, width, height, args.sampler, args.rr_depth, CONFIGURATIONS[configuration])
        scenes[configuration] = mitsuba.load(scene_dict)
        mitsuba.render(scenes[configuration], args.pass_spp, seed=0)  # JIT compilation, untimed
    for limit in args.times:
        results = {}
        for configuration, scene in scenes.items():
            # Seeds from 1 + the Prism seed × 2^20: apart from the warm-up's 0 and from other runs' seeds.
            results[("mitsuba", configuration)] = mitsuba_for(mitsuba, scene, limit, args.pass_spp, 1 + (args.seed << 20))
        with tempfile.TemporaryDirectory() as folder:
            image, seconds, prism_passes = prism_render(args.prism, scene_path, Path(folder) / "p.exr", threads, args.seed,
                                                        seconds=limit, width=width, height=height)
        results[("prism", "defaults")] = (image, seconds, prism_passes)
        for (renderer, configuration), (image, seconds, spp) in results.items():
            if args.keep_images:
                import numpy as np

                Path(args.keep_images).mkdir(parents=True, exist_ok=True)
                name = f"{scene_path.stem}-{limit:g}s-{renderer}-{configuration}.npy"
                np.save(Path(args.keep_images) / name, image.astype(np.float32))
            e = error_against(image, reference)
            rows.append({
                "scene": scene_path.stem, "renderer": renderer, "configuration": configuration, "threads": threads,
                "width": width, "height": height, "time_limit": limit, "seconds": seconds, "spp": spp, "rmse": e["rmse"],
                "efficiency": 1.0 / (e["rmse"] ** 2 * seconds), "block_rmse": e["block_rmse"], "mean_ratio": e["mean_ratio"],
                "bias_r": e["bias"][0], "bias_g": e["bias"][1], "bias_b": e["bias"][2],
                "z_r": e["z"][0], "z_g": e["z"][1], "z_b": e["z"][2],
            })
            print(f"  {renderer} {configuration} {scene_path.stem} {limit:g} s: RMSE {e['rmse']:.4f} after {seconds:.2f} s, "
                  f"{spp} spp; mean ratio {e['mean_ratio']:.4f}, z {', '.join(f'{z:+.1f}' for z in e['z'])}, "
                  f"8x8-block RMSE {e['block_rmse']:.4f}", file=sys.stderr, flush=True)


def write_csv(path, header, rows, comments):
    path.parent.mkdir(parents=True, exist_ok=True)
    with open(path, "w", newline="") as f:
        for comment in comments:
            f.write(f"# {comment}\n")
        writer = csv.writer(f, lineterminator="\n")
        writer.writerow(header)
        for row in rows:
            writer.writerow([f"{row[c]:.6g}" if isinstance(row.get(c), float) else row.get(c, "") for c in header])


def markdown(path_rows, time_rows, comments):
    lines = [f"<!-- {c} -->" for c in comments]
    if path_rows:
        lines += ["Paths (camera samples) per second:", "",
                  "| scene | size | spp | threads | Prism Mpaths/s | Mitsuba configuration | Mitsuba Mpaths/s | Prism ÷ Mitsuba |",
                  "|---|---|---|---|---|---|---|---|"]
        prism = {(r["scene"], r["threads"]): r for r in path_rows if r["renderer"] == "prism"}
        for m in (r for r in path_rows if r["renderer"] == "mitsuba"):
            p = prism[(m["scene"], m["threads"])]
            lines.append(f"| {m['scene']} | {m['width']}×{m['height']} | {m['spp']} | {m['threads']} | "
                         f"{p['paths_per_second'] / 1e6:.3f} | {m['configuration']} | {m['paths_per_second'] / 1e6:.3f} | "
                         f"{p['paths_per_second'] / m['paths_per_second']:.2f} |")
        lines.append("")
    if time_rows:
        lines += ["Equal-time error against the reference (RMSE; seconds actually taken and samples per pixel in brackets; "
                  "efficiency = 1 / (RMSE² × seconds)):", "",
                  "| scene | time limit (s) | threads | Prism RMSE | Mitsuba configuration | Mitsuba RMSE | "
                  "Mitsuba RMSE ÷ Prism RMSE | Prism efficiency ÷ Mitsuba | mean ÷ reference (Prism, Mitsuba) | "
                  "worst mean z (Prism, Mitsuba) |",
                  "|---|---|---|---|---|---|---|---|---|---|"]
        prism = {(r["scene"], r["time_limit"]): r for r in time_rows if r["renderer"] == "prism"}
        worst = lambda r: max((r["z_r"], r["z_g"], r["z_b"]), key=abs)  # noqa: E731
        for m in (r for r in time_rows if r["renderer"] == "mitsuba"):
            p = prism[(m["scene"], m["time_limit"])]
            lines.append(
                f"| {m['scene']} | {m['time_limit']:g} | {p['threads']} | {p['rmse']:.4f} ({p['seconds']:.1f} s, {p['spp']}) | "
                f"{m['configuration']} | {m['rmse']:.4f} ({m['seconds']:.1f} s, {m['spp']}) | {m['rmse'] / p['rmse']:.2f} | "
                f"{p['efficiency'] / m['efficiency']:.2f} | {p['mean_ratio']:.4f}, {m['mean_ratio']:.4f} | "
                f"{worst(p):+.1f}, {worst(m):+.1f} |"
            )
    return "\n".join(lines) + "\n"


def machine_note():
    with open("/proc/loadavg") as f:
        load = " ".join(f.read().split()[:3])
    return f"{os.cpu_count()} logical cores, load average (1/5/15 min) {load}"


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0], formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument(
        "scenes",
        nargs="*",
        default=["scenes/cornell.toml", "scenes/bunny.toml", "benches/peers/cornell_box_mitsuba.toml"],
        help="Prism scene files",
    )
    parser.add_argument("--prism", default="target/release/prism", help="the prism binary")
    parser.add_argument("--variant", default="llvm_ad_rgb", help="Mitsuba variant (falls back to scalar_rgb if unusable)")
    parser.add_argument("--output-dir", default="benches/peers/results")
    parser.add_argument("--threads", default="1,2", help="thread counts of the paths-per-second runs")
    parser.add_argument("--spp", type=int, default=16, help="samples per pixel of the paths-per-second runs")
    parser.add_argument("--width", type=int, help="width of the paths-per-second runs (default: the scene's)")
    parser.add_argument("--times", default="2,8,32", help="equal-time limits in seconds (comma-separated; empty: skip)")
    parser.add_argument("--equal-time-threads", type=int, default=2)
    parser.add_argument("--pass-spp", type=int, default=4, help="Mitsuba samples per pixel per pass in the equal-time runs")
    parser.add_argument("--reference-dir", default="references", help="SCENE.exr references (Prism's, 256 pixels wide)")
    parser.add_argument("--seed", type=int, default=1, help="seed of the equal-time renders (the references use another)")
    parser.add_argument("--sampler", default="independent", help="Mitsuba sampler (its default, independent; or multijitter, ...)")
    parser.add_argument("--configurations", default="defaults,no-background-nee",
                        help="Mitsuba configurations: defaults; no-background-nee (the background found by BSDF sampling only, as in Prism)")
    parser.add_argument("--rr-depth", type=int, default=5, help="Mitsuba's Russian roulette depth (its default: 5)")
    parser.add_argument("--keep-images", help="save the equal-time images here as .npy")
    parser.add_argument("--skip-paths", action="store_true", help="skip the paths-per-second runs")
    parser.add_argument("--prism-args", default="",
                        help="extra flags for every prism render, e.g. '--caustic-light-paths false'")
    args = parser.parse_args()
    PRISM_EXTRA_ARGS.extend(args.prism_args.split())
    args.threads = [int(t) for t in args.threads.split(",") if t]
    args.times = [float(t) for t in args.times.split(",") if t]
    args.configurations = [c for c in args.configurations.split(",") if c]
    if any(c not in CONFIGURATIONS for c in args.configurations) or not args.configurations:
        parser.error(f"--configurations takes {', '.join(CONFIGURATIONS)}")
    if not Path(args.prism).is_file():
        parser.error(f"{args.prism}: no such file (cargo build --release, or --prism PATH)")

    mitsuba = Mitsuba(args.variant)
    path_rows, time_rows = [], []
    for scene in args.scenes:
        scene_path = Path(scene)
        try:
            if not args.skip_paths:
                paths_per_second(args, mitsuba, scene_path, path_rows)
            if args.times:
                equal_time(args, mitsuba, scene_path, time_rows)
        except Unsupported as error:
            sys.exit(f"{scene_path}: cannot translate for Mitsuba: {error}")

    output = Path(args.output_dir)
    comments = [
        f"benches/peers/mitsuba_cornell.py: {mitsuba.version()}, path integrator (max_depth = Prism's + 1, rr_depth {args.rr_depth}), "
        f"sampler {args.sampler}; Prism {args.prism} (pt, sobol{', ' + args.prism_args if args.prism_args else ''})",
        machine_note(),
    ]
    if path_rows:
        write_csv(output / "mitsuba_paths.csv",
                  ["scene", "renderer", "configuration", "threads", "width", "height", "spp", "seconds", "first_render_seconds",
                   "paths_per_second"],
                  path_rows, comments + ["seconds: the second of two identical Mitsuba renders (the first compiles); Prism's RenderSeconds"])
    if time_rows:
        write_csv(output / "mitsuba_equal_time.csv",
                  ["scene", "renderer", "configuration", "threads", "width", "height", "time_limit", "seconds", "spp", "rmse", "efficiency",
                   "block_rmse", "mean_ratio", "bias_r", "bias_g", "bias_b", "z_r", "z_g", "z_b"],
                  time_rows, comments + [f"against {args.reference_dir}/SCENE.exr; efficiency = 1 / (rmse^2 seconds); "
                                         f"Mitsuba passes of {args.pass_spp} spp"])
    table = markdown(path_rows, time_rows, comments)
    (output / "mitsuba.md").write_text(table)
    print(table)
    print(f"wrote mitsuba_paths.csv, mitsuba_equal_time.csv and mitsuba.md in {output}", file=sys.stderr)


if __name__ == "__main__":
    main()
