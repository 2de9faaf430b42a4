#!/usr/bin/env bash
# Session 13's big run on a lent GPU machine (16 cores, one GPU): simulate a 'wide' dataset ten
# times the size 2 CPU cores allow in a session, train the lite and the seed nets on the GPU,
# calibrate them on a simulated validation set, and pack the models for the way back.
# Nothing here is needed to reproduce the shipped models on a CPU: models/train.sh does that (slowly).
#
# Session 20 (issue 35, point 7): path-traced clean scenes for the cache (wallcli/datagen/ptcache.py),
# rendered with Mitsuba's CUDA variant at a sample count whose Monte-Carlo noise is under a third of
# a camera's, packed for the way back (64 MiB a call), composed and trained on here. The wheels:
# mitsuba 3.9.1 and drjit 1.5.0 for cp312, slimmed (research/pathtrace/slim_wheel.py --variants
# cuda_ad_rgb,scalar_rgb), in .whl/ (git-ignored), carried as `.whl`.
#
#   bash research/transfer/device_run.sh pt       # install, render for RENDER s in the background, pack what is done
#   bash research/transfer/device_run.sh ptmore   # the next call, on the same warm machine: wait, pack the rest
#
#   bash research/transfer/device_run.sh gen     # start simulating in the background (setsid), wait a while
#   bash research/transfer/device_run.sh train   # wait for the data, train 4 nets at once, pack them into $OUT
#   bash research/transfer/device_run.sh wait    # keep waiting on whatever runs (resumable training)
#
# Environment: D (work folder, /tmp/wd), N (training windows), NV (validation windows), JOBS,
# DEV (cuda | cpu), EPOCHS, BUDGET (seconds this call may wait), PY (python), OUT (where the pack goes).
set -uo pipefail
cd "$(dirname "$0")/../.."
D=${D:-/tmp/wd}
PY=${PY:-python3}
N=${N:-10240}
NV=${NV:-1536}
JOBS=${JOBS:-16}
DEV=${DEV:-cuda}
EPOCHS=${EPOCHS:-12}
ANNEAL=${ANNEAL:-3}
BUDGET=${BUDGET:-540}
OUT=${OUT:-$D/out}
mkdir -p "$D" "$OUT"
export PYTHONPATH=$PWD${PYTHONPATH:+:$PYTHONPATH} PYTHONUNBUFFERED=1
W="$PY -m wallcli"

progress() {
  echo "[$SECONDS s] val: $(ls "$D"/val32/shard-*.npz 2>/dev/null | wc -l) shards, train: $(ls "$D"/wide31/shard-*.npz 2>/dev/null | wc -l) shards"
  for f in "$D"/train_*.log; do [ -f "$f" ] && echo "  $(basename "$f"): $(tr '\r' '\n' < "$f" | grep -a -E 'epoch|Error|wrote' | tail -1 | cut -c1-160)"; done
  true
}

net() {  # name task arch extra...
  local name=$1 task=$2 arch=$3; shift 3
  setsid $W train "$task" --data "$D/wide31" --val "$D/val32" --out "$D/models/$name.onnx" --arch "$arch" \
    --epochs "$EPOCHS" --anneal "$ANNEAL" --min-snr-db -20 --balance --select last --threads 3 --device "$DEV" \
    --calibrate "$D/val32" --confidence-level 0.97 --model-version 0.5.0 --force "$@" \
    > "$D/train_$name.log" 2>&1 < /dev/null &
}

ptprogress() {
  echo "[$SECONDS s] scenes: $(ls /tmp/ptc/pt/*/scene-*.npz 2>/dev/null | wc -l); $(tail -1 /tmp/fill.log 2>/dev/null | cut -c1-160)"
}

case "${1:-}" in
  pt)
    SPP=${SPP:-4096}; PTSEED=${PTSEED:-2000}; RENDER=${RENDER:-560}; WAIT=${WAIT:-400}
    python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade --target .site .whl/*.whl || exit 4
    export PYTHONPATH=$PWD/.site:$PYTHONPATH WALLCLI_CACHE=/tmp/ptc WALLCLI_PT_VARIANT=cuda_ad_rgb OMP_NUM_THREADS=1
    nvidia-smi -L
    python3 -c "import mitsuba as mi; mi.set_variant('cuda_ad_rgb'); print('mitsuba', mi.__version__, mi.variant())" || exit 5
    setsid python3 research/ptcache/fill.py --seed "$PTSEED" --start 0 --stop 5000 --jobs "$JOBS" --spp "$SPP" \
      --budget "$RENDER" > /tmp/fill.log 2>&1 < /dev/null &
    setsid python3 research/ptcache/spp_noise.py --scenes 8 --frames 40 --ref 16384 --spps 512,1024,2048,4096 \
      > /tmp/noise.log 2>&1 < /dev/null &
    while [ $SECONDS -lt "$WAIT" ]; do sleep 30; ptprogress; done
    python3 research/ptcache/pack.py --root /tmp/ptc/pt --out "$OUT" --ledger /tmp/packed.txt --tag a --total-mib 60
    cat /tmp/noise.log; cp /tmp/fill.log /tmp/noise.log "$OUT"/ 2>/dev/null
    exit 0
    ;;
  ptmore)
    WAIT=${WAIT:-120}
    while [ $SECONDS -lt "$WAIT" ] && pgrep -f ptcache/fill.py > /dev/null; do sleep 10; done
    ptprogress
    python3 research/ptcache/pack.py --root /tmp/ptc/pt --out "$OUT" --ledger /tmp/packed.txt --tag b --total-mib 60
    cat /tmp/noise.log; cp /tmp/fill.log /tmp/noise.log "$OUT"/ 2>/dev/null
    exit 0
    ;;
  gen)
    setsid bash -c "$W simulate --dataset $NV --task count --domain wide --placement wide --seed 32 -o $D/val32 --jobs $JOBS \
      && $W simulate --dataset $N --task count --domain wide --placement wide --seed 31 -o $D/wide31 --jobs $JOBS \
      && touch $D/gen.done" > "$D/gen.log" 2>&1 < /dev/null &
    ;;
  train)
    while [ ! -f "$D/gen.done" ] && [ $SECONDS -lt "$BUDGET" ]; do sleep 15; done
    if [ ! -f "$D/gen.done" ]; then progress; echo "data not ready"; exit 3; fi
    mkdir -p "$D/models"
    net lite_count count lite --superpose 0.2
    net lite_activity activity lite
    net seed_count count seed --superpose 0.2 --quantize int8
    net seed_activity activity seed --quantize int8
    ;;
  wait) ;;
  *) echo "usage: device_run.sh gen|train|wait" >&2; exit 2 ;;
esac

while [ $SECONDS -lt "$BUDGET" ]; do
  if [ "${1}" = gen ] && [ -f "$D/gen.done" ]; then break; fi
  if [ "${1}" != gen ] && ! pgrep -f "wallcli train" > /dev/null; then break; fi
  sleep 20
  [ $((SECONDS % 120)) -lt 20 ] && progress
done
progress
tail -c 600 "$D/gen.log" | tr '\r' '\n' | tail -3
if [ -d "$D/models" ]; then
  tar -czf "$OUT/pack.tgz" --exclude="*.ckpt.pt" -C "$D" models $(cd "$D" && ls train_*.log) && ls -la "$OUT"
fi
