#!/usr/bin/env bash
# A profile-guided release build of prism (rustc's -Cprofile-generate /
# -Cprofile-use, https://doc.rust-lang.org/rustc/profile-guided-optimization.html).
#
#   bash benches/pgo/build.sh                      # any x86-64 CPU, like `cargo build --release`
#   RUSTFLAGS="-C target-cpu=x86-64-v4" bash benches/pgo/build.sh   # for AVX-512 machines only
#
# 1. builds an instrumented binary (target/pgo-generate), which counts how
#    often each branch and call is taken;
# 2. trains it on the shipped scenes (path tracing, spectral, SPPM, at small
#    sizes) and on `prism bench --rays` (the BVH build and the three ray types
#    on the bunny and its subdivisions): about a minute on two cores;
# 3. merges the counts with llvm-profdata (rustup's llvm-tools component)
#    and builds again with them (target/pgo/release/prism), so LLVM lays out
#    hot paths together and inlines where calls are frequent.
#
# The optimised binary computes exactly what the plain release build does
# (profiles change code layout and inlining, never floating-point semantics):
# the same pixels, bit for bit. Measured gains: docs/performance.md,
# "Profile-guided and host-tuned builds".
set -euo pipefail

root=$(cd "$(dirname "$0")/../.." && pwd)
cd "$root"

host=$(rustc -vV | sed -n 's/^host: //p')
profdata="$(rustc --print sysroot)/lib/rustlib/$host/bin/llvm-profdata"
if [[ ! -x "$profdata" ]]; then
    echo "error: $profdata not found; install it with: rustup component add llvm-tools" >&2
    exit 1
fi

profiles="$root/target/pgo-profiles"
rm -rf "$profiles"
mkdir -p "$profiles/train"
base_flags="${RUSTFLAGS:-}"

echo "== 1/3 instrumented build (target/pgo-generate)"
RUSTFLAGS="$base_flags -Cprofile-generate=$profiles/raw" \
    cargo build --release --locked --target-dir target/pgo-generate
instrumented=target/pgo-generate/release/prism

echo "== 2/3 training run"
render() { "$instrumented" render "$@" --threads 2 --quiet -o "$profiles/train/out.exr"; }
for scene in scenes/*.toml; do
    render "$scene" --width 128 --height 96 --spp 16
done
for scene in scenes/prism.toml scenes/prism-caustic.toml scenes/caustic.toml; do
    render "$scene" --integrator sppm --width 128 --height 96 --spp 8
done
render scenes/cornell.toml --spectral --width 96 --height 96 --spp 8
"$instrumented" bench --rays --repetitions 1 --output-dir "$profiles/train" >/dev/null

echo "== 3/3 optimised build (target/pgo)"
"$profdata" merge -o "$profiles/merged.profdata" "$profiles/raw"
# PRISM_PGO marks the binary as profile-guided in its benchmarks' CSV headers.
PRISM_PGO=1 RUSTFLAGS="$base_flags -Cprofile-use=$profiles/merged.profdata" \
    cargo build --release --locked --target-dir target/pgo
echo "built target/pgo/release/prism"
