#!/usr/bin/env bash
# Regenerate the bundled example clips with the simulator (same seed + options = same video, on
# any machine with AVX2: x264 runs on one thread and without its AVX-512 code; see io/writer.py).
# A typical camera (0.1 codes per electron, 1.5 codes read noise, H.264 crf 12) watching a wall
# region of 200k sensor pixels, people 1-2 m from the wall: faint (0.1-1 %) but visible signals.
set -euo pipefail
cd "$(dirname "$0")"
W=${WALLCLI:-../.venv/bin/wallcli}
S="--size 160x120 --duration 12 --fps 30 --iso-gain 0.1 --read-noise 1.5 --crf 12 --sensor-pixels 200000 --distance 1,2 --force"
$W simulate -o empty.mp4        --people 0                             --seed 31 $S
$W simulate -o standing.mp4     --people 1 --activity none             --seed 32 $S
$W simulate -o walking.mp4      --people 1 --activity walking          --seed 31 $S
$W simulate -o crouching.mp4    --people 1 --activity crouching        --seed 33 $S
$W simulate -o waving.mp4       --people 1 --activity waving           --seed 34 $S
$W simulate -o jumping.mp4      --people 1 --activity jumping          --seed 35 $S
$W simulate -o two-walking.mp4  --people 2 --activity walking          --seed 36 $S
$W simulate -o two-mixed.mp4    --people 2 --activity walking,crouching --seed 37 $S
