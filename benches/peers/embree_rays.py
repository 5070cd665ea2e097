#!/usr/bin/env python3
"""Embree 4 on the meshes and rays of `prism bench --rays`.

What it measures, for each mesh Prism exports (the Stanford bunny, the bunny
subdivided twice and four times) and each Embree scene mode (robust, and
Embree's default):

- build: milliseconds of `rtcCommitScene` (Embree's BVH build over the
  triangles, medium build quality, as embreex sets it) on 1 and 2 threads;
- closest hit on the primary and the incoherent rays, and occlusion (any hit)
  on the incoherent rays, in millions of rays per second on 1 and 2 threads;
  the table compares Embree's closest hit with two of Prism's queries:
  `closest` (`Scene::intersect`: the query and then the hit record a renderer
  shades with, the point with its error bound, unit normals and uv) and
  `distance` (`Scene::nearest_distance`: the query alone, distance and
  primitive). The second is the work of Embree's `rtcIntersect1`, which
  returns the distance, barycentrics, an unnormalised geometric normal and
  the primitive (Prism's leaf tests find the barycentrics too; the normal,
  one cross product, they do not make); a renderer on Embree builds its hit
  record afterwards (Mitsuba's `SurfaceInteraction`);
- agreement with Prism on the very same rays: hit/miss disagreements, hits
  whose distance differs by more than a relative 1e-5, hits on another
  triangle (legitimate where a ray crosses a shared edge), and occlusion
  disagreements.

Usage (from the repository root, after `cargo build --release`):

    pip install embreex numpy        # Embree 4.4 in a wheel; not a Prism dependency
    ./target/release/prism bench --rays --export-rays /tmp/prism-rays
    python3 benches/peers/embree_rays.py /tmp/prism-rays \
        --prism docs/rays.csv --prism-build docs/rays_build.csv --output-dir docs

It writes `embree_rays.csv` and `embree_build.csv` (columns as Prism's
`rays.csv` and `rays_build.csv`, plus `peer`, `mode` and the disagreement
counts) and `embree_rays.md` (a side-by-side table with Prism ÷ Embree when
Prism's CSVs are given). For a quick check of the script itself:
`--max-rays 20000 --repetitions 1 --meshes bunny`.

How threads are controlled: embreex's `EmbreeScene.run` traces its rays in a
plain C loop of `rtcIntersect1`/`rtcOccluded1` calls with the GIL released, so
each thread count is measured by that many Python threads, each tracing an
interleaved share of the rays (chunks of 4096, as Prism's rayon loop takes
them) in one `run` call; only those calls are timed (the Python overhead is
one call per thread, not per ray). The build runs on Embree's TBB threads,
which embreex cannot configure (it creates its device with no config
string); TBB sizes its pool from the process's CPU affinity, so each thread
count runs in a child process pinned to that many cores
(`os.sched_setaffinity` before Embree is loaded). The child reports how many
threads the process had after the builds, as a check.
"""

import argparse
import csv
import json
import os
import subprocess
import sys
import threading
import time
from pathlib import Path

CHUNK = 4096  # rays per work item, as in Prism's bench (rays.rs)
RELATIVE_T_TOLERANCE = 1e-5
# The queries Prism measures: (ray set, query).
CASES = [("primary", "closest"), ("incoherent", "closest"), ("incoherent", "occlusion")]


def load_export(directory, only_meshes):
    """Meshes and ray sets of `prism bench --rays --export-rays`, by name."""
    import numpy as np

    directory = Path(directory)
    meshes = {}
    for faces_path in sorted(directory.glob("*.faces.u32")):
        name = faces_path.name[: -len(".faces.u32")]
        if only_meshes and name not in only_meshes:
            continue
        vertices = np.fromfile(directory / f"{name}.vertices.f32", dtype="<f4").reshape(-1, 3)
        faces = np.fromfile(faces_path, dtype="<u4").reshape(-1, 3)
        meshes[name] = (vertices, faces)
    if not meshes:
        sys.exit(f"{directory}: no NAME.faces.u32 files (run prism bench --rays --export-rays {directory})")
    return dict(sorted(meshes.items(), key=lambda item: len(item[1][1])))


def load_rays(directory, mesh, ray_set, max_rays):
    """Origins and directions (f32), and Prism's answers: face (−1 on a miss),
    distance, and whether the ray is occluded."""
    import numpy as np

    stem = Path(directory) / f"{mesh}-{ray_set}"
    rays = np.fromfile(f"{stem}.rays.f32", dtype="<f4").reshape(-1, 6)
    answers = np.fromfile(f"{stem}.prism.f64", dtype="<f8").reshape(-1, 2)
    occluded_path = Path(f"{stem}.prism-occluded.u8")
    occluded = np.fromfile(occluded_path, dtype="u1").astype(bool) if occluded_path.exists() else None
    if max_rays and max_rays < len(rays):
        # Evenly spaced rays, so a subset of the primary rays still spans the image.
        pick = np.linspace(0, len(rays) - 1, max_rays).astype(np.int64)
        rays, answers = rays[pick], answers[pick]
        occluded = None if occluded is None else occluded[pick]
    return (
        np.ascontiguousarray(rays[:, :3]),
        np.ascontiguousarray(rays[:, 3:]),
        answers[:, 0].astype(np.int64),
        answers[:, 1],
        occluded,
    )


def shares(array, threads):
    """Each thread's rays: chunks of CHUNK dealt round-robin, made contiguous."""
    import numpy as np

    chunks = [array[i : i + CHUNK] for i in range(0, len(array), CHUNK)]
    return [np.ascontiguousarray(np.concatenate(chunks[t::threads])) for t in range(threads) if chunks[t::threads]]


def timed_run(scene, origins, directions, threads, query):
    """Seconds to trace every ray on `threads` threads, and the answers in
    input order (for 1 thread) or None."""
    if threads == 1:
        kwargs = {"output": 1} if query == "closest" else {"query": "OCCLUDED"}
        start = time.perf_counter()
        answer = scene.run(origins, directions, **kwargs)
        return time.perf_counter() - start, answer
    parts = list(zip(shares(origins, threads), shares(directions, threads)))
    kwargs = {"output": 1} if query == "closest" else {"query": "OCCLUDED"}
    # The threads start first and wait, so thread creation is not timed
    # (Prism's rayon pool exists before its timer starts too).
    ready = threading.Barrier(len(parts) + 1)

    def trace(part):
        ready.wait()
        scene.run(*part, **kwargs)

    workers = [threading.Thread(target=trace, args=(part,)) for part in parts]
    for worker in workers:
        worker.start()
    ready.wait()
    start = time.perf_counter()
    for worker in workers:
        worker.join()
    return time.perf_counter() - start, None


def disagreements(query, answer, prism_face, prism_t, prism_occluded):
    """Counts of rays where Embree and Prism disagree."""
    import numpy as np

    prism_hit = prism_face >= 0
    if query == "occlusion":
        embree_occluded = answer == 0
        reference = prism_occluded if prism_occluded is not None else prism_hit
        return {"hit_miss_disagreements": int(np.count_nonzero(embree_occluded != reference))}
    embree_hit = answer["primID"] >= 0
    both = embree_hit & prism_hit
    embree_t = answer["tfar"].astype(np.float64)
    relative = np.abs(embree_t[both] - prism_t[both]) / np.maximum(np.abs(prism_t[both]), 1e-30)
    return {
        "hit_miss_disagreements": int(np.count_nonzero(embree_hit != prism_hit)),
        "t_disagreements": int(np.count_nonzero(relative > RELATIVE_T_TOLERANCE)),
        "max_relative_t_difference": float(relative.max()) if relative.size else 0.0,
        "other_triangle": int(np.count_nonzero(answer["primID"][both] != prism_face[both])),
    }


def worker(args):
    """One thread count, in a process pinned to that many cores; prints JSON rows."""
    threads = args.worker
    os.sched_setaffinity(0, set(sorted(os.sched_getaffinity(0))[:threads]))
    import numpy as np
    from embreex import mesh_construction, rtcore, rtcore_scene

    device = rtcore.EmbreeDevice()
    rows = []
    for name, (vertices, faces) in load_export(args.export_dir, args.meshes).items():
        indices = faces.astype(np.int32)
        for mode in args.modes:
            robust = mode == "robust"
            build_ms = []
            scene = None
            for _ in range(max(3, args.repetitions)):
                scene = rtcore_scene.EmbreeScene(device, robust=robust)
                mesh_construction.TriangleMesh(scene, vertices, indices)
                # run() commits the scene (builds the BVH) on its first call.
                one = np.zeros((1, 3), np.float32)
                start = time.perf_counter()
                scene.run(one, one + np.float32([0, 0, 1]))
                build_ms.append((time.perf_counter() - start) * 1e3)
            rows.append(
                {
                    "kind": "build",
                    "mesh": name,
                    "triangles": len(faces),
                    "mode": mode,
                    "threads": threads,
                    "build_ms": min(build_ms),
                    "process_threads": len(os.listdir("/proc/self/task")),
                }
            )
            for ray_set, query in CASES:
                origins, directions, face, t, occluded = load_rays(args.export_dir, name, ray_set, args.max_rays)
                best = float("inf")
                answer = None
                for _ in range(args.repetitions):
                    seconds, answer = timed_run(scene, origins, directions, threads, query)
                    best = min(best, seconds)
                row = {
                    "kind": "rays",
                    "mesh": name,
                    "triangles": len(faces),
                    "rays": ray_set,
                    "query": query,
                    "mode": mode,
                    "threads": threads,
                    "ray_count": len(origins),
                    "mrays_per_second": len(origins) / best / 1e6,
                }
                if answer is not None:
                    hits = answer == 0 if query == "occlusion" else answer["primID"] >= 0
                    row["hit_fraction"] = float(np.count_nonzero(hits)) / max(len(origins), 1)
                    row.update(disagreements(query, answer, face, t, occluded))
                rows.append(row)
                print(
                    f"  [{threads} thread(s)] {name} {mode} {ray_set} {query}: {row['mrays_per_second']:.2f} Mrays/s",
                    file=sys.stderr,
                    flush=True,
                )
    json.dump(rows, sys.stdout)


def machine_note():
    with open("/proc/loadavg") as f:
        load = " ".join(f.read().split()[:3])
    return f"{os.cpu_count()} logical cores, load average (1/5/15 min) {load}"


def embree_version():
    from embreex import rtcore

    return " ".join(repr(rtcore.EmbreeDevice()).replace("version:", "").split())


def read_prism_csv(path):
    if not path:
        return []
    with open(path) as f:
        return list(csv.DictReader(line for line in f if not line.startswith("#")))


def write_csv(path, header, rows, comments):
    path.parent.mkdir(parents=True, exist_ok=True)
    with open(path, "w", newline="") as f:
        for comment in comments:
            f.write(f"# {comment}\n")
        writer = csv.writer(f, lineterminator="\n")
        writer.writerow(header)
        for row in rows:
            writer.writerow([row.get(column, "") for column in header])


def fmt(value, digits=2):
    return f"{value:.{digits}f}" if isinstance(value, float) else str(value)


def markdown(build_rows, ray_rows, prism_rays, prism_build, modes, comments):
    """Side-by-side tables: Prism, Embree per mode, and Prism ÷ Embree."""
    lines = [f"<!-- {c} -->" for c in comments]
    prism_ray = {(r["mesh"], r["rays"], r["query"], int(r["threads"])): float(r["mrays_per_second"]) for r in prism_rays}
    prism_ms = {r["mesh"]: (float(r["build_ms_1_thread"]), float(r["build_ms_2_threads"])) for r in prism_build}
    header = ["mesh", "triangles", "rays", "query", "threads"]
    if prism_ray:
        header.append("Prism Mrays/s")
    for mode in modes:
        header.append(f"Embree {mode} Mrays/s")
        if prism_ray:
            header.append(f"Prism ÷ Embree {mode}")
    lines += ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    embree = {(r["mesh"], r["rays"], r["query"], r["threads"], r["mode"]): r for r in ray_rows}
    keys = sorted({k[:4] for k in embree}, key=lambda k: (next(r["triangles"] for r in ray_rows if r["mesh"] == k[0]), CASES.index((k[1], k[2])), k[3]))
    for mesh, ray_set, query, threads in keys:
        any_row = embree[next(k for k in embree if k[:4] == (mesh, ray_set, query, threads))]
        # Embree's closest hit against both of Prism's: with the hit record
        # ("closest") and the query alone ("distance"; see the module doc).
        prism_queries = [query] + (["distance"] if query == "closest" and (mesh, ray_set, "distance", threads) in prism_ray else [])
        for prism_query in prism_queries:
            cells = [mesh, f"{any_row['triangles']:,}", ray_set, prism_query, str(threads)]
            prism = prism_ray.get((mesh, ray_set, prism_query, threads))
            if prism_ray:
                cells.append(fmt(prism) if prism is not None else "–")
            for mode in modes:
                row = embree.get((mesh, ray_set, query, threads, mode))
                cells.append(fmt(row["mrays_per_second"]) if row else "–")
                if prism_ray:
                    cells.append(fmt(prism / row["mrays_per_second"]) if row and prism is not None else "–")
            lines.append("| " + " | ".join(cells) + " |")

    lines += ["", "Build (milliseconds, best of repeated builds):", ""]
    header = ["mesh", "triangles"]
    for threads in (1, 2):
        if prism_ms:
            header.append(f"Prism {threads}T")
        header += [f"Embree {mode} {threads}T" for mode in modes]
    lines += ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    builds = {(r["mesh"], r["mode"], r["threads"]): r for r in build_rows}
    for mesh in dict.fromkeys(r["mesh"] for r in build_rows):
        triangles = next(r["triangles"] for r in build_rows if r["mesh"] == mesh)
        cells = [mesh, f"{triangles:,}"]
        for index, threads in enumerate((1, 2)):
            if prism_ms:
                cells.append(fmt(prism_ms[mesh][index], 1) if mesh in prism_ms else "–")
            for mode in modes:
                row = builds.get((mesh, mode, threads))
                cells.append(fmt(row["build_ms"], 1) if row else "–")
        lines.append("| " + " | ".join(cells) + " |")

    lines += ["", "Agreement with Prism on the same rays (1-thread runs):", ""]
    header = ["mesh", "rays", "query", "mode", "rays traced", "hit/miss differ", f"t differs > {RELATIVE_T_TOLERANCE:g} rel.", "max rel. t difference", "other triangle"]
    lines += ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    for r in ray_rows:
        if r["threads"] != 1 or "hit_miss_disagreements" not in r:
            continue
        lines.append(
            "| "
            + " | ".join(
                [
                    r["mesh"],
                    r["rays"],
                    r["query"],
                    r["mode"],
                    f"{r['ray_count']:,}",
                    str(r["hit_miss_disagreements"]),
                    str(r.get("t_disagreements", "–")),
                    f"{r['max_relative_t_difference']:.1e}" if "max_relative_t_difference" in r else "–",
                    str(r.get("other_triangle", "–")),
                ]
            )
            + " |"
        )
    return "\n".join(lines) + "\n"


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0], formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("export_dir", help="folder written by prism bench --rays --export-rays")
    parser.add_argument("--prism", help="Prism's rays.csv, for the side-by-side table")
    parser.add_argument("--prism-build", help="Prism's rays_build.csv, for the build table")
    parser.add_argument("--output-dir", default="benches/peers/results", help="where the CSVs and the markdown go")
    parser.add_argument("--modes", default="robust,default", help="Embree scene modes: robust (RTC_SCENE_FLAG_ROBUST), default (no flag)")
    parser.add_argument("--threads", default="1,2", help="thread counts (comma-separated)")
    parser.add_argument("--repetitions", type=int, default=3, help="timed runs per measurement; the best is kept (builds: at least 3)")
    parser.add_argument("--max-rays", type=int, default=0, help="trace only N evenly spaced rays of each set (0: all)")
    parser.add_argument("--meshes", default="", help="only these meshes (comma-separated, e.g. bunny,bunny-x16)")
    parser.add_argument("--worker", type=int, help=argparse.SUPPRESS)
    args = parser.parse_args()
    args.modes = [m for m in args.modes.split(",") if m]
    args.meshes = [m for m in args.meshes.split(",") if m]
    if any(m not in ("robust", "default") for m in args.modes):
        parser.error("--modes takes robust and/or default")
    if args.repetitions < 1:
        parser.error("--repetitions must be at least 1")
    if args.worker:
        worker(args)
        return

    thread_counts = [int(t) for t in args.threads.split(",") if t]
    if max(thread_counts) > len(os.sched_getaffinity(0)):
        parser.error(f"--threads {max(thread_counts)} is more than the {len(os.sched_getaffinity(0))} cores this process may use")
    load_export(args.export_dir, args.meshes)  # fail early on a bad folder
    rows = []
    for threads in thread_counts:
        command = [sys.executable, __file__, args.export_dir, "--worker", str(threads), "--modes", ",".join(args.modes)]
        command += ["--repetitions", str(args.repetitions), "--max-rays", str(args.max_rays), "--meshes", ",".join(args.meshes)]
        done = subprocess.run(command, stdout=subprocess.PIPE, check=True)
        rows += json.loads(done.stdout)
    build_rows = [r for r in rows if r["kind"] == "build"]
    ray_rows = [r for r in rows if r["kind"] == "rays"]
    # Agreement and hit fraction come from the 1-thread run (the same rays give the same answers).
    agreement = {(r["mesh"], r["rays"], r["query"], r["mode"]): r for r in ray_rows if "hit_fraction" in r}
    for r in ray_rows:
        for column, value in agreement.get((r["mesh"], r["rays"], r["query"], r["mode"]), {}).items():
            r.setdefault(column, value)
    for r in ray_rows:
        r["mrays_per_second"] = float(f"{r['mrays_per_second']:.6g}")
    for r in build_rows:
        r["build_ms"] = round(r["build_ms"], 3)

    output = Path(args.output_dir)
    comments = [
        f"benches/peers/embree_rays.py: {embree_version()} through embreex (rtcIntersect1/rtcOccluded1 per ray), best of {args.repetitions} runs, wall time",
        machine_note(),
    ]
    if args.max_rays:
        comments.append(f"only {args.max_rays} evenly spaced rays of each set (--max-rays): not the benchmark's figures")
    write_csv(
        output / "embree_rays.csv",
        ["peer", "mode", "mesh", "triangles", "rays", "query", "threads", "mrays_per_second", "hit_fraction", "ray_count",
         "hit_miss_disagreements", "t_disagreements", "max_relative_t_difference", "other_triangle"],
        [{"peer": "embree", **r} for r in ray_rows],
        comments,
    )
    build_table = {}
    for r in build_rows:
        entry = build_table.setdefault((r["mesh"], r["mode"]), {"peer": "embree", "mode": r["mode"], "mesh": r["mesh"], "triangles": r["triangles"]})
        entry[f"build_ms_{r['threads']}_thread{'s' if r['threads'] > 1 else ''}"] = r["build_ms"]
        entry[f"process_threads_{r['threads']}"] = r["process_threads"]
    write_csv(
        output / "embree_build.csv",
        ["peer", "mode", "mesh", "triangles", "build_ms_1_thread", "build_ms_2_threads", "process_threads_1", "process_threads_2"],
        list(build_table.values()),
        comments[:1] + ["build = rtcCommitScene; process_threads_N: threads of the N-core process after its builds (TBB workers + main)"] + comments[1:],
    )
    table = markdown(build_rows, ray_rows, read_prism_csv(args.prism), read_prism_csv(args.prism_build), args.modes, comments)
    (output / "embree_rays.md").write_text(table)
    print(table)
    print(f"wrote embree_rays.csv, embree_build.csv and embree_rays.md in {output}", file=sys.stderr)


if __name__ == "__main__":
    main()
