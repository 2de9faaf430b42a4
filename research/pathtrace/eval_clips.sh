#!/usr/bin/env bash
# Labelled clips of the same scenes in one world (pt or room) for `wallcli evaluate`: N clips in a
# cycle of six classes (empty, walking, crouching, waving, jumping, two walkers), 'wide' domain,
# 10 s at 30 fps, 96x72, people 1.5-5 m away. On a GPU machine pt renders ~100 frames/s.
#   bash research/pathtrace/eval_clips.sh pt OUTDIR N [FIRST_SEED] [PARALLEL]
set -uo pipefail
world=$1 out=$2 n=$3 first=${4:-600} par=${5:-4}
W=${WALLCLI:-"python3 -m wallcli"}
mkdir -p "$out"
one() {
  i=$1; c=$((i % 6)); s=$((first + i))
  case $c in
    0) a="--people 0";; 1) a="--people 1 --activity walking";; 2) a="--people 1 --activity crouching";;
    3) a="--people 1 --activity waving";; 4) a="--people 1 --activity jumping";; 5) a="--people 2 --activity walking";;
  esac
  [ -f "$out/c$s.mp4" ] || $W simulate -o "$out/c$s.mp4" --world "$world" $a --seed "$s" --domain wide --duration 10 \
    --fps 30 --size 96x72 --grid 16x24 --distance 1.5,5 $( [ "$world" = pt ] && echo --spp 256 ) 2>>"$out/log"
}
export -f one; export out first world W
seq 0 $((n - 1)) | xargs -P "$par" -I{} bash -c 'one {}'
