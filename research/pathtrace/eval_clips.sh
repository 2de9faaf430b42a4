#!/usr/bin/env bash
# Labelled clips of the same scenes in one world (pt or room) for `wallcli evaluate`: N clips in a
# cycle of six classes (empty, walking, crouching, waving, jumping, two walkers), 'wide' domain,
# 10 s at 30 fps, 96x72, people 1.5-5 m away. On a GPU machine pt renders ~100 frames/s.
#   bash research/pathtrace/eval_clips.sh pt OUTDIR N [FIRST_SEED] [PARALLEL]
# DOMAIN=steady draws 'steady' rooms (lighting nuisances in a sixth of them); PAIRS=mixed makes the
# two-person clips a cycle of activity pairs (walking+waving, walking+jumping, jumping+waving,
# crouching+walking, waving+crouching) instead of two walkers: the proxy set of
# research/shadows/README.md. With libLLVM 19 installed the CPU renders ~25 frames/s at 16 x 24.
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
  if [ "$c" = 5 ] && [ "${PAIRS:-}" = mixed ]; then
    pairs=(walking,waving walking,jumping jumping,waving crouching,walking waving,crouching)
    a="--people 2 --activity ${pairs[$(( (i / 6) % 5 ))]}"
  fi
  [ -f "$out/c$s.mp4" ] || $W simulate -o "$out/c$s.mp4" --world "$world" $a --seed "$s" --domain "${DOMAIN:-wide}" --duration 10 \
    --fps 30 --size 96x72 --grid 16x24 --distance 1.5,5 $( [ "$world" = pt ] && echo --spp 256 ) 2>>"$out/log"
}
export -f one; export out first world W DOMAIN PAIRS
seq 0 $((n - 1)) | xargs -P "$par" -I{} bash -c 'one {}'
