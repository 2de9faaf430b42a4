#!/usr/bin/env bash
# Renders the training and validation rooms of issue #59 in the background, one clip at a time,
# niced, resumable: render_batch.py skips clips already in labels.csv, so re-running continues.
# Training seeds: 1,000,000 + n; validation seeds: 2,000,000 + n (never in training).
# Every 8 training clips, 2 validation clips, until TRAIN_MAX / VAL_MAX are reached.
set -u
PY=${RENDER_PY:-$HOME/.venvs/render/bin/python}
GEN=${RENDER_GEN:-$(cd "$(dirname "$0")/../../../shared/render" && pwd)/render_batch.py}
OUT=${RENDER_OUT:-$(cd "$(dirname "$0")/../.." && pwd)/runs/render}
TRAIN_MAX=${TRAIN_MAX:-2400}
VAL_MAX=${VAL_MAX:-600}
mkdir -p "$OUT/train" "$OUT/val"
t=1; v=1
while [ "$t" -le "$TRAIN_MAX" ] || [ "$v" -le "$VAL_MAX" ]; do
  if [ "$t" -le "$TRAIN_MAX" ]; then
    nice -n 19 "$PY" "$GEN" "$OUT/train" --first "$t" --count 8 --seed-base 1000000 --cycle twos --spp 64 --python "$PY"
    t=$((t + 8))
  fi
  if [ "$v" -le "$VAL_MAX" ]; then
    nice -n 19 "$PY" "$GEN" "$OUT/val" --first "$v" --count 2 --seed-base 2000000 --cycle twos --spp 64 --prefix v --python "$PY"
    v=$((v + 2))
  fi
done
