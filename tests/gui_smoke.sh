#!/usr/bin/env bash
# A real window: starts the `prism` viewer under Xvfb on the default scene,
# waits for its first image plus a few seconds of accumulation, takes a
# screenshot of the screen and fails if the image region is blank or uniform
# (ImageMagick's standard deviation of the cropped region), or if the viewer
# died. Prints the viewer's timing log (PRISM_VIEWER_LOG=2: events, and the
# frame rate the UI sustains while repainting continuously) and each of its
# threads' CPU time and run-queue wait (see docs/viewer.md, "Where the frame
# time goes").
#
# Environment: PRISM_BIN (default: builds and uses target/debug/prism),
# SCREENSHOT (default: target/gui-smoke/viewer.png), SETTLE_SECONDS (default 4).
set -euo pipefail
cd "$(dirname "$0")/.."

# Install what is missing (Debian packages; CI runs as root).
missing=()
command -v xvfb-run >/dev/null 2>&1 || missing+=(xvfb xauth)
command -v import >/dev/null 2>&1 || missing+=(imagemagick)
dpkg -s libgl1-mesa-dri >/dev/null 2>&1 || missing+=(libgl1-mesa-dri)
if ((${#missing[@]})); then
    echo "gui_smoke: installing ${missing[*]}"
    apt-get update -qq
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq "${missing[@]}" >/dev/null
fi

bin=${PRISM_BIN:-}
if [[ -z $bin ]]; then
    cargo build --quiet --bin prism
    bin=${CARGO_TARGET_DIR:-target}/debug/prism
fi
screenshot=${SCREENSHOT:-target/gui-smoke/viewer.png}
settle=${SETTLE_SECONDS:-4}
mkdir -p "$(dirname "$screenshot")"
log=$(mktemp)
trap 'rm -f "$log" "$log.threads"' EXIT

export bin screenshot settle log
# Mesa's software rasteriser; one thread so the renderer keeps the cores.
export LIBGL_ALWAYS_SOFTWARE=1 LP_NUM_THREADS=1
xvfb-run -a -s "-screen 0 1280x800x24" bash -c '
    PRISM_VIEWER_LOG=${PRISM_VIEWER_LOG:-2} "$bin" 2>"$log" &
    pid=$!
    for _ in $(seq 1 600); do
        grep -q "first image shown" "$log" && break
        kill -0 "$pid" 2>/dev/null || break
        sleep 0.1
    done
    sleep "$settle"
    if ! kill -0 "$pid" 2>/dev/null; then
        echo "gui_smoke: the viewer exited early" >&2
        exit 1
    fi
    import -window root "$screenshot"
    # Where the CPU went: each thread of the viewer (the UI thread, the Mesa
    # llvmpipe rasteriser, the render workers) with its time on a CPU and its
    # time waiting for one since it started (Linux schedstat).
    for task in /proc/"$pid"/task/*; do
        read -r run wait _ < "$task/schedstat" || continue
        printf "gui_smoke: thread %-18s on a CPU %6d ms, waiting for one %6d ms\n" \
            "$(cat "$task/comm")" $((run / 1000000)) $((wait / 1000000)) >>"$log.threads"
    done
    kill "$pid"
    wait "$pid" 2>/dev/null || true
' || { echo "gui_smoke: FAILED (viewer log follows)"; cat "$log"; exit 1; }

echo "gui_smoke: viewer log:"
cat "$log"
cat "$log.threads" 2>/dev/null || true
grep -q "first image shown" "$log" || { echo "gui_smoke: FAILED: no image was shown"; exit 1; }

# The window opens at the top-left of the 1280x800 screen at 1200x760; the
# side panel takes ~300 px, so this 360x360 square lies inside the image.
region="360x360+580+180"
deviation=$(convert "$screenshot" -crop "$region" +repage -colorspace Gray -format "%[fx:standard_deviation]" info:)
mean=$(convert "$screenshot" -crop "$region" +repage -colorspace Gray -format "%[fx:mean]" info:)
echo "gui_smoke: image region $region: mean $mean, standard deviation $deviation"
if awk -v d="$deviation" 'BEGIN { exit !(d < 0.03) }'; then
    echo "gui_smoke: FAILED: the image region is blank or uniform"
    exit 1
fi
echo "gui_smoke: 1 passed, 0 failed"
