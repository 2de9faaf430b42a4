#!/usr/bin/env bash
# Session 12's transfer experiment (NOT the shipped models: models/train.sh makes those): the
# 'wide' simulator domain, 'lite' nets reading both plots, trained and calibrated, then measured on
# the independent transfer set. They did not beat the shipped models there (research/models-notebook.md), so
# they write to runs/, not models/.
#   bash research/transfer/train_wide.sh
# Steps resume: rerunning skips finished shards and continues training from checkpoints.
# Time on 2 CPU cores (session 12): ~1 min per 128 windows of 'wide' simulation, ~15 windows/s of
# training per net.
set -euo pipefail
cd "$(dirname "$0")/../.."
W=${WALLCLI:-.venv/bin/wallcli}
PY=${PYTHON:-.venv/bin/python}
JOBS=${JOBS:-2}
EPOCHS=${EPOCHS:-10}
WIDE=${WIDE:-4864}  # windows of the training set (38 shards of 32 scenes x 4 windows)

# One 'wide' count dataset serves both nets: its scenes hold 0-2 movers of every activity (and a
# third of the empty rooms someone standing still); the activity net learns from its windows with
# at most one mover, labelled by their activity (wallcli/train/data.py).
$W simulate --dataset "$WIDE" --task count --domain wide --placement wide --seed 21 -o data/wide21 --jobs "$JOBS"
$W simulate --dataset 768 --task count --domain wide --placement wide --seed 22 -o data/val_wide22 --jobs "$JOBS"

for task in count activity; do
  extra=""
  [ "$task" = count ] && extra="--superpose 0.2"
  $W train "$task" --data data/wide21 --val data/val_wide22 --out "runs/wide_$task.onnx" --arch lite \
    --epochs "$EPOCHS" --anneal 3 --min-snr-db -20 --balance --select last $extra --threads 1 \
    --calibrate data/val_wide22 --confidence-level 0.97 --model-version 0.5.0 --force
done


# Transfer: the independent renderer's clips (never trained or calibrated on), into the cards
for task in count activity; do
  $W evaluate ../shared/transfer --task "$task" --json --jobs "$JOBS" --model "runs/wide_$task.onnx" > "runs/transfer_wide_$task.json"
  $PY research/record_transfer.py "runs/wide_$task.onnx" "runs/transfer_wide_$task.json"
done
