#!/usr/bin/env bash
# Regenerates docs/rerun_viewer.png: the urgent merge's recording in the Rerun viewer (0.36.3)
# with the recording's own default layout, under Xvfb with Mesa's software Vulkan, the time
# cursor set by a scripted click. No hand clicks, no hand-written blueprint.
#
#   apt-get install -y xvfb imagemagick mesa-vulkan-drivers libgl1-mesa-dri xdotool optipng pngquant
#   pip install rerun-sdk==0.36.3
#   scripts/rerun_screenshot.sh [TIME_S]          # default 10.77 s (just after the lane change); ~55 s
#
# Notes: Xvfb must run with `-extension Composite` (without it the viewer's window stays
# black), only WGPU_BACKEND=vulkan works (the GL backend lacks the R32Float target), and the
# viewer runs with a fresh HOME so that no blueprint saved by an earlier session replaces the
# recording's default layout.
set -euo pipefail

time_s="${1:-10.77}"
display=":98"
port=9899
work="$(mktemp -d /tmp/mergesim_shot.XXXXXX)"
repo="$(cd "$(dirname "$0")/.." && pwd)"
mkdir -p "$work/home" "$work/xdg" && chmod 700 "$work/xdg"

# MERGE_SIM=/path/to/merge_sim uses that binary instead of `cargo run`.
if [ -n "${MERGE_SIM:-}" ]; then
    "$MERGE_SIM" --quiet --rrd "$work/urgent.rrd"
else
    cargo run --release --bin merge_sim -- --quiet --rrd "$work/urgent.rrd"
fi

Xvfb "$display" -screen 0 1600x900x24 -extension Composite >"$work/xvfb.log" 2>&1 &
xvfb_pid=$!
viewer_pid=""
cleanup() {
    [ -n "$viewer_pid" ] && kill "$viewer_pid" 2>/dev/null || true
    kill "$xvfb_pid" 2>/dev/null || true
}
trap cleanup EXIT
sleep 2
# `rerun` from pip is a Python entry point; run the native binary it wraps, so that its pid
# is the viewer's.
rerun_bin="$(python3 -c 'import rerun_cli, os; print(os.path.join(os.path.dirname(rerun_cli.__file__), "rerun"))' 2>/dev/null || command -v rerun)"
HOME="$work/home" DISPLAY="$display" WGPU_BACKEND=vulkan XDG_RUNTIME_DIR="$work/xdg" \
    "$rerun_bin" --port "$port" "$work/urgent.rrd" >"$work/rerun.log" 2>&1 &
viewer_pid=$!
# The viewer plays the recording once when it opens (25 s of simulated time at 1x) and stops,
# paused, at its end; a click on the bar then moves the time cursor without playing.
sleep 40
# The collapsed time panel's bar spans x = 258..1390 px for the run's 0..25 s (1600 px wide
# window); a click there moves the time cursor.
x=$(python3 -c "print(round(258 + (1390 - 258) * $time_s / 25.0))")
DISPLAY="$display" xdotool mousemove "$x" 885
sleep 0.5
DISPLAY="$display" xdotool click 1
# Park the pointer off the views (no hover tooltips).
DISPLAY="$display" xdotool mousemove 1590 5
sleep 5
DISPLAY="$display" import -window root "$work/final.png"
pngquant --quality=80-95 --speed 1 -f -o "$repo/docs/rerun_viewer.png" "$work/final.png"
optipng -quiet -o2 "$repo/docs/rerun_viewer.png"
echo "wrote $repo/docs/rerun_viewer.png (t ~ $time_s s; the viewer's readout is in the image)"
