#!/usr/bin/env bash
# Reproduce the shipped models from nothing: simulate the training sets and the shifted
# validation sets (other seeds, moved room/people/camera ranges), train, export ONNX + cards.
#   bash models/train.sh            # N=2048 windows per task, as shipped
# Steps resume: rerunning skips finished shards and continues training from checkpoints.
set -euo pipefail
cd "$(dirname "$0")/.."
W=${WALLCLI:-.venv/bin/wallcli}
JOBS=${JOBS:-2}
N=${N:-2048}
EPOCHS_COUNT=${EPOCHS_COUNT:-20}
EPOCHS_ACTIVITY=${EPOCHS_ACTIVITY:-11}

$W simulate --dataset "$N" --task count -o data/count --jobs "$JOBS" --seed 1 --world mixed
$W simulate --dataset 512 --task count -o data/val_count --jobs "$JOBS" --seed 101 --domain shifted
$W train count --data data/count --val data/val_count --out models/count.onnx --epochs "$EPOCHS_COUNT" --threads 1 --min-snr-db -15 --model-version 0.1.1 --force

$W simulate --dataset "$N" --task activity -o data/activity --jobs "$JOBS" --seed 2
$W simulate --dataset 384 --task activity -o data/val_activity --jobs "$JOBS" --seed 102 --domain shifted
$W train activity --data data/activity --val data/val_activity --out models/activity.onnx --epochs "$EPOCHS_ACTIVITY" --threads 1 --min-snr-db -15 --model-version 0.1.0 --force
