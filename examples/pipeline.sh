#!/usr/bin/env bash
# Set up wallcli (once, into .venv) and run the main job on a bundled example clip:
# how strong is the signal, the space-time plots, how many people, what they do, where along
# the wall, and the amplified video. Outputs go to out/ at the top of the checkout (git-ignored):
# outside examples/, so that `wallcli scan examples` finds the bundled clips only, not this script's
# amplified video (which is no wall).
set -euo pipefail
cd "$(dirname "$0")/.."
if [ ! -x .venv/bin/wallcli ]; then
  python3 -m venv .venv
  .venv/bin/python -m pip install -q --upgrade pip
  .venv/bin/python -m pip install -q .
fi
w=.venv/bin/wallcli
clip=${1:-examples/walking.mp4}
out=out
mkdir -p "$out"

echo "== signal and noise ($clip)" >&2
$w snr "$clip"
echo "== space-time plots -> $out/plots.npz, $out/plots.png" >&2
$w stplot "$clip" -o "$out/plots.npz" --png "$out/plots.png" --force
# count and activity print the same way: a table titled with the answer, and one line saying
# why it is decided or not (-v adds the models' validated accuracy; --json gives the data)
echo "== how many people (from the plots)" >&2
$w count "$out/plots.npz"
echo "== what they are doing" >&2
$w activity "$clip"
echo "== where along the wall (tracks of the shades) -> $out/tracks.png" >&2
$w track "$clip" --png "$out/tracks.png" --force
echo "== amplified video -> $out/amplified.mp4" >&2
$w amplify "$clip" "$out/amplified.mp4" --side-by-side --force
