#!/usr/bin/env bash
# Real-window screenshots of the viewer for the README: starts the release
# binary under Xvfb with openbox (for focus), drives it with xdotool and
# writes screenshots/viewer.png (the default scene rendering),
# viewer-inspect.png (1:1 zoom with the pixel readout), viewer-denoise.png
# (raw beside denoised) and viewer-region.png (a region render); then opens
# scenes/prism.toml (spectral SPPM) and writes viewer-prism-early.png (after
# 4 s) and viewer-prism.png (after 40 s).
#
# The click positions are those of the side panel's controls relative to the
# window's top-left corner (xdotool mousemove --window); if the panel's layout
# changes, re-measure them on a screenshot.
#
# Needs: xvfb imagemagick libgl1-mesa-dri xdotool openbox. Not run by CI
# (it waits for the render, ~1 minute). Environment: PRISM_BIN (default
# target/release/prism), SHOTS (default screenshots).
set -euo pipefail
cd "$(dirname "$0")/.."
bin=${PRISM_BIN:-target/release/prism}
shots=${SHOTS:-screenshots}
mkdir -p "$shots"
export bin shots LIBGL_ALWAYS_SOFTWARE=1

xvfb-run -a -s "-screen 0 1280x800x24" bash -c '
    set -euo pipefail
    openbox >/dev/null 2>&1 &
    openbox_pid=$!
    sleep 1
    "$bin" 2>/dev/null &
    viewer=$!
    trap "kill $viewer $openbox_pid 2>/dev/null || true" EXIT
    window=$(xdotool search --sync --onlyvisible --name "^Prism$" | head -1)
    sleep 2
    shot() { sleep "$2"; import -window "$window" "$shots/$1"; }
    point() { xdotool mousemove --window "$window" "$1" "$2"; }
    click() { point "$1" "$2"; xdotool click 1; sleep 0.5; }

    # The default scene converging; the pointer rests on the panel.
    point 158 283
    shot viewer.png 25
    # 1:1 zoom, the pointer on the mirror ball: the pixel readout.
    click 103 607
    point 850 445
    shot viewer-inspect.png 3
    # Back to fit; raw beside denoised.
    click 63 607
    click 245 552
    point 158 283
    shot viewer-denoise.png 8
    # Denoiser off; a region around the two balls.
    click 137 552
    click 123 332
    point 540 430
    xdotool mousedown 1
    for x in 600 700 800 900 960; do point "$x" $((430 + (x - 540) / 2)); sleep 0.1; done
    xdotool mouseup 1
    point 158 283
    shot viewer-region.png 15
'
xvfb-run -a -s "-screen 0 1280x800x24" bash -c '
    set -euo pipefail
    openbox >/dev/null 2>&1 &
    openbox_pid=$!
    sleep 1
    "$bin" view scenes/prism.toml 2>/dev/null &
    viewer=$!
    trap "kill $viewer $openbox_pid 2>/dev/null || true" EXIT
    window=$(xdotool search --sync --onlyvisible --name "^Prism" | head -1)
    xdotool mousemove --window "$window" 158 283
    sleep 4
    import -window "$window" "$shots/viewer-prism-early.png"
    sleep 36
    import -window "$window" "$shots/viewer-prism.png"
'
echo "gui_screenshots: wrote $shots/viewer.png viewer-inspect.png viewer-denoise.png viewer-region.png viewer-prism-early.png viewer-prism.png"
