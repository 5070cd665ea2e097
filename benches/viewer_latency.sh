#!/usr/bin/env bash
# The viewer's latencies in a real window, for comparing builds: how long
# from launch until the first image is on screen, and from a camera change
# (a short drag over the image, which orbits the camera) until the first
# refreshed image. Each binary is started ROUNDS times, the binaries
# alternated so that they share the machine's load, under Xvfb with openbox
# (for focus) and PRISM_VIEWER_LOG=1, which prints both times (see
# docs/viewer.md, "Measuring"). Each run drags CHANGES times, 1.5 s apart;
# the camera change logged with the first image (the scene's own camera) is
# not counted.
#
# Usage: benches/viewer_latency.sh BINARY... [-- SCENE]
# Prints one CSV row per event (binary, run, event, milliseconds) and then
# the median of each event per binary. Environment: ROUNDS (default 3),
# CHANGES (default 6). Needs xvfb, openbox, xdotool and libgl1-mesa-dri;
# not run by CI (about 15 s per run).
set -euo pipefail

# Paths as given, made absolute before the script moves to the repository.
binaries=()
scene=""
while (($#)); do
    if [[ $1 == -- ]]; then
        (($# == 2)) || { echo "usage: $0 BINARY... [-- SCENE]" >&2; exit 2; }
        [[ -f $2 ]] || { echo "viewer_latency: no scene file $2" >&2; exit 2; }
        scene=$(realpath "$2")
        break
    fi
    [[ -x $1 ]] || { echo "viewer_latency: $1 is not an executable" >&2; exit 2; }
    binaries+=("$(realpath "$1")")
    shift
done
((${#binaries[@]})) || { echo "usage: $0 BINARY... [-- SCENE]" >&2; exit 2; }
cd "$(dirname "$0")/.."
for tool in xvfb-run openbox xdotool; do
    command -v "$tool" >/dev/null || { echo "viewer_latency: $tool is not installed" >&2; exit 2; }
done
rounds=${ROUNDS:-3}
changes=${CHANGES:-6}
rows=$(mktemp)
trap 'rm -f "$rows"' EXIT

# One run: prints the viewer's log on stdout.
run_once() {
    local bin=$1
    export bin changes scene
    LIBGL_ALWAYS_SOFTWARE=1 LP_NUM_THREADS=1 xvfb-run -a -s "-screen 0 1280x800x24" bash -c '
        set -euo pipefail
        openbox >/dev/null 2>&1 &
        openbox_pid=$!
        sleep 1
        log=$(mktemp)
        # `prism view SCENE`, or the embedded default scene without one.
        PRISM_VIEWER_LOG=1 "$bin" ${scene:+view "$scene"} 2>"$log" &
        viewer=$!
        trap "kill $viewer $openbox_pid 2>/dev/null || true; rm -f $log" EXIT
        for _ in $(seq 1 600); do
            grep -q "first image shown" "$log" && break
            kill -0 "$viewer" 2>/dev/null || break
            sleep 0.05
        done
        window=$(xdotool search --sync --onlyvisible --name "^Prism" | head -1)
        # Over the image, right of the side panel.
        xdotool mousemove --window "$window" 760 360
        sleep 1.5
        for _ in $(seq 1 "$changes"); do
            # Separate events with pauses, so the UI sees a press, moves, a release.
            xdotool mousedown 1
            for _ in 1 2 3 4; do sleep 0.05; xdotool mousemove_relative 6 0; done
            sleep 0.05
            xdotool mouseup 1
            xdotool mousemove --window "$window" 760 360
            sleep 1.5
        done
        cat "$log"
    '
}

for round in $(seq 1 "$rounds"); do
    for bin in "${binaries[@]}"; do
        run_once "$bin" | awk -v bin="$bin" -v run="$round" '
            /first image shown/ { first = $2; print bin "," run ",first image," $2 }
            /camera change → refreshed image in/ && first != "" && $2 > first + 1 {
                for (i = 1; i <= NF; i++) if ($i == "in") { print bin "," run ",camera change," $(i + 1) }
            }' | tee -a "$rows"
    done
done

echo
echo "medians (ms):"
python3 - "$rows" <<'EOF'
import csv, statistics, sys
values = {}
for binary, _run, event, ms in csv.reader(open(sys.argv[1])):
    values.setdefault((binary, event), []).append(float(ms))
for (binary, event), samples in sorted(values.items()):
    print(f"{binary}: {event}: median {statistics.median(samples):.1f} "
          f"(range {min(samples):.1f}-{max(samples):.1f}, {len(samples)} samples)")
EOF
