#!/usr/bin/env bash
# Reproduce the shipped models from nothing: simulate the training sets and the shifted
# validation sets (other seeds, moved room/people/camera ranges), train, export ONNX + cards.
#   bash models/train.sh
# Steps resume: rerunning skips finished shards and continues training from checkpoints.
# Time on 2 CPU cores: ~15 min per 2560 windows of simulation (count4 or activity3: ~60 min),
# ~7 min per count epoch (6560 windows kept of 8192), ~14 min per activity epoch (7104 kept of 11264).
set -euo pipefail
cd "$(dirname "$0")/.."
W=${WALLCLI:-.venv/bin/wallcli}
JOBS=${JOBS:-2}
EPOCHS_COUNT=${EPOCHS_COUNT:-12}
EPOCHS_ACTIVITY=${EPOCHS_ACTIVITY:-5}

# The cards' validation: fresh shifted sets of 1024 windows from 256 scenes (seeds used nowhere else).
# Validation never steers training (--select last), so which set a run watches changes only the
# per-epoch history in its card; the shipped runs watched val_count4 (seed 106, 512) and
# val_activity2 (seed 104, 384), and their cards were measured on these.
$W simulate --dataset 1024 --task count -o data/val_count6 --jobs "$JOBS" --seed 107 --domain shifted
$W simulate --dataset 1024 --task activity -o data/val_activity3 --jobs "$JOBS" --seed 108 --domain shifted
# Second shifted sets (session 8), measured after training into the cards' validation.other_sets:
# one set of 256 scenes can sit several points on the lucky side.
$W simulate --dataset 512 --task count -o data/val_count7 --jobs "$JOBS" --seed 121 --domain shifted
$W simulate --dataset 1024 --task activity -o data/val_activity4 --jobs "$JOBS" --seed 122 --domain shifted

# Training sets place people where their light reaches the camera above its noise (--placement
# visible, the default).
# count 0.4.0 (shipped as 0.4.1: its 8-bit weights rounded to 7 bits by research/requantize.py; this
# command now quantises to 7 bits from float directly): moving people only, a quarter flatland,
# superposition augmentation
$W simulate --dataset 8192 --task count -o data/count4 --jobs "$JOBS" --seed 6 --world mixed
$W train count --data data/count4 --val data/val_count6 --out models/count.onnx --epochs "$EPOCHS_COUNT" \
  --threads 2 --min-snr-db -10 --select last --superpose 0.25 --quantize int8 --model-version 0.4.0 --force

# activity 0.3.0 (shipped as 0.3.1, likewise): two training sets from two seeds, used as one
$W simulate --dataset 3072 --task activity -o data/activity2 --jobs "$JOBS" --seed 4
$W simulate --dataset 8192 --task activity -o data/activity3 --jobs "$JOBS" --seed 7
$W train activity --data data/activity2 --data data/activity3 --val data/val_activity3 --out models/activity.onnx \
  --epochs "$EPOCHS_ACTIVITY" --threads 2 --min-snr-db -10 --select last --quantize int8 --model-version 0.3.0 --force

# The second sets' figures in the cards (research/evaluate.py --record; the model is not touched)
PY=${PYTHON:-.venv/bin/python}
$PY research/evaluate.py count data/val_count7 --record
$PY research/evaluate.py activity data/val_activity4 --record

# Decided or undetermined (sessions 12-13): thresholds fitted on simulated validation the models
# never trained on (three 'wide'-domain sets and the shifted sets' first halves), each set also
# checked on its own (wallcli/infer/confidence.py fit(groups=...)), then the transfer figures.
# val_wide22, val_wide23, val_count6s and val_activity3s were simulated before session 13 taught the simulator that windows and
# ceiling panels light people directly (commit 577a295); to make them bit for bit, simulate them
# from the simulator of commit 56e3ec4 (git worktree add /tmp/s12 56e3ec4, run its wallcli there).
# val_wide33 is from the simulator as it is now.
$W simulate --dataset 768 --task count --domain wide --placement wide --seed 22 -o data/val_wide22 --jobs "$JOBS"
$W simulate --dataset 1024 --task count --domain wide --placement wide --seed 23 -o data/val_wide23 --jobs "$JOBS"
$W simulate --dataset 1024 --task count --domain wide --placement wide --seed 33 -o data/val_wide33 --jobs "$JOBS"
$W simulate --dataset 512 --task count -o data/val_count6s --jobs "$JOBS" --seed 107 --domain shifted
$W simulate --dataset 512 --task activity -o data/val_activity3s --jobs "$JOBS" --seed 108 --domain shifted
$PY research/calibrate.py models/count.onnx data/val_wide22 data/val_wide23 data/val_wide33 data/val_count6s --level 0.97 --edges 0
$PY research/calibrate.py models/activity.onnx data/val_wide22 data/val_wide23 data/val_wide33 data/val_activity3s --level 0.97 --edges 0
mkdir -p runs
for task in count activity; do
  $W evaluate ../shared/transfer --task "$task" --json --jobs "$JOBS" > "runs/transfer_$task.json"
  $PY research/record_transfer.py "models/$task.onnx" "runs/transfer_$task.json"
done
