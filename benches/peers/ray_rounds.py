#!/usr/bin/env python3
"""Prism against Embree on the rays of `prism bench --rays`, in alternated rounds.

One run of `embree_rays.py` measures Embree minutes after Prism's
`bench --rays` measured Prism, and on a shared machine the load changes in
between: single runs of the same two binaries have put a row anywhere from
0.85 to 1.28. This script alternates the two, N rounds, each round running
both back to back (Prism first in odd rounds, Embree first in even ones, so
a drift in load favours neither), and reports per row the ratio of each
round, their median and their range.

Usage (from the repository root, after `cargo build --release`; needs
`pip install embreex numpy`, as embree_rays.py does):

    ./target/release/prism bench --rays --export-rays /tmp/prism-rays
    python3 benches/peers/ray_rounds.py /tmp/prism-rays --rounds 5 --output-dir /tmp/rounds

It writes `ray_rounds.md` (the table) and keeps each round's CSVs in
`round_K/` under the output folder. Embree runs in robust mode, the one
whose answers are exact enough to compare with (see embree_rays.py).
"""

import argparse
import statistics
import subprocess
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from embree_rays import load_export, machine_note, read_prism_csv  # noqa: E402

HERE = Path(__file__).resolve().parent


def run_prism(prism, folder, repetitions):
    run([prism, "bench", "--rays", "--repetitions", str(repetitions), "--output-dir", str(folder)])


def run_embree(export_dir, folder, repetitions):
    command = [sys.executable, str(HERE / "embree_rays.py"), export_dir, "--modes", "robust"]
    command += ["--repetitions", str(repetitions), "--output-dir", str(folder)]
    run(command)


def run(command):
    """Runs `command` quietly; on failure, shows what it said and stops."""
    done = subprocess.run(command, capture_output=True, text=True)
    if done.returncode != 0:
        sys.stderr.write(done.stdout + done.stderr)
        sys.exit(f"{' '.join(command)} failed with exit status {done.returncode}")


def ratios_of_round(folder):
    """Prism ÷ Embree robust per (mesh, rays, Prism's query, threads); Prism's
    `closest` and `distance` both against Embree's closest hit."""
    prism = {(r["mesh"], r["rays"], r["query"], r["threads"]): float(r["mrays_per_second"]) for r in read_prism_csv(folder / "rays.csv")}
    embree = {
        (r["mesh"], r["rays"], r["query"], r["threads"]): float(r["mrays_per_second"])
        for r in read_prism_csv(folder / "embree_rays.csv")
        if r["mode"] == "robust"
    }
    ratios = {}
    for (mesh, rays, query, threads), rate in prism.items():
        peer_query = "closest" if query == "distance" else query
        peer = embree.get((mesh, rays, peer_query, threads))
        if peer:
            ratios[(mesh, rays, query, threads)] = rate / peer
    return ratios


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0], formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("export_dir", help="folder written by prism bench --rays --export-rays")
    parser.add_argument("--prism", default="target/release/prism", help="the Prism binary")
    parser.add_argument("--rounds", type=int, default=5, help="alternated rounds of both")
    parser.add_argument("--repetitions", type=int, default=3, help="timed runs per measurement in each round; the best is kept")
    parser.add_argument("--output-dir", default="benches/peers/results", help="where ray_rounds.md and each round's CSVs go")
    args = parser.parse_args()
    if args.rounds < 1 or args.repetitions < 1:
        parser.error("--rounds and --repetitions must be at least 1")

    if not Path(args.prism).is_file():
        parser.error(f"--prism {args.prism}: no such file (build it with cargo build --release)")
    load_export(args.export_dir, [])  # fails early, naming the folder, if it holds no export
    output = Path(args.output_dir)
    rounds = []
    notes = []
    for index in range(args.rounds):
        folder = output / f"round_{index + 1}"
        folder.mkdir(parents=True, exist_ok=True)
        notes.append(machine_note())
        steps = [lambda: run_prism(args.prism, folder, args.repetitions), lambda: run_embree(args.export_dir, folder, args.repetitions)]
        for step in steps if index % 2 == 0 else reversed(steps):
            step()
        rounds.append(ratios_of_round(folder))
        print(f"round {index + 1} of {args.rounds} done", file=sys.stderr, flush=True)

    keys = [key for key in rounds[0] if all(key in r for r in rounds)]
    cores, _, _ = notes[0].partition(", load average")
    loads = "; ".join(note.partition("(1/5/15 min) ")[2] for note in notes)
    lines = [
        f"<!-- benches/peers/ray_rounds.py: {args.rounds} alternated rounds of prism bench --rays and embree_rays.py (robust), "
        f"best of {args.repetitions} runs each; {cores} -->",
        f"<!-- load average (1/5/15 min) at each round's start: {loads} -->",
    ]
    header = ["mesh", "rays", "query", "threads"] + [f"round {i + 1}" for i in range(args.rounds)] + ["median", "range"]
    lines += ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    for key in keys:
        values = [r[key] for r in rounds]
        cells = list(key) + [f"{v:.2f}" for v in values]
        cells += [f"**{statistics.median(values):.2f}**", f"{min(values):.2f}–{max(values):.2f}"]
        lines.append("| " + " | ".join(cells) + " |")
    table = "\n".join(lines) + "\n"
    (output / "ray_rounds.md").write_text(table)
    print(table)


if __name__ == "__main__":
    main()
