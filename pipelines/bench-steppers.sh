#!/usr/bin/env bash
# The steppers side by side on pack's reference beds, with the peer yardsticks where they are
# present (../shared/peers/run.sh: LIGGGHTS, rapier), all in one run on one machine:
#   [STEPPERS="acceleration velocity"] bash pipelines/bench-steppers.sh [BIN] [CASES]
# BIN: the release binaries (default target/release). CASES (default "sph690 cyl40"):
#   sph690  690 spheres of 10 mm, D = 79.9 mm, batch (yardstick: liggghts-690)
#   cyl40   40 cylinders 10 x 10 mm, D = 40 mm, batch, seeds 1-3
#   ring40  40 Raschig rings 10/6 x 10 mm, D = 40 mm, batch, seeds 1-3
#   ring256 256 Raschig rings 10/6 x 10 mm, D = 60.18 mm, batch (yardstick: rapier-256-rings)
#   cyl620  620 cylinders 10 x 10 mm, D = 91.58 mm, batch (yardstick: rapier-620; minutes)
#   sph5000 5000 spheres of 10 mm, D = 154.6 mm, batch (the 690-sphere bed scaled at its
#           height-to-diameter ratio; minutes)
#   cyl2000 2000 cylinders 10 x 10 mm, D = 135.3 mm, batch (the 620-cylinder bed scaled so;
#           several minutes)
# Prints per run: case, stepper, seed, CPU s (user + system), settle time, porosity, the
# CPU per pellet per simulated second (ms: cpu_s / (N · settle_s), how the cost scales with
# the bed), the CPU ratio to the yardstick when there is one, and for the velocity-level stepper the contact
# solve over the last 0.1 s of the run: contact points per pair, the share of loaded contacts
# warm started and the share of steps whose solve converged; then two overlaps in % of dpv:
# pen_%, the engine's deepest penetration in the bed as written (pack's "% at the end"), and
# olap_%, the deepest pellet-pellet overlap of the same bed measured independently on the
# exact shapes (voidprof --structure: deepest_overlap_dpv).
set -euo pipefail
BIN=${1:-target/release}
CASES=${2:-sph690 cyl40}
STEPPERS=${STEPPERS:-acceleration velocity}
here=$(cd "$(dirname "$0")" && pwd)
peers="$here/../../shared/peers/run.sh"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$BIN/mkpellet" sphere --diameter 10 -o "$work/s.pellet" >/dev/null
"$BIN/mkpellet" cylinder --diameter 10 --height 10 -o "$work/c.pellet" >/dev/null
"$BIN/mkpellet" ring --outer-diameter 10 --inner-diameter 6 --height 10 -o "$work/r.pellet" >/dev/null

yardstick() {  # peer case → its CPU seconds, or empty
  [ -f "$peers" ] || return 0
  bash "$peers" "$1" 2>/dev/null | awk '{print $3}'
}

one() {  # label pellet tube count seed stepper window yard
  local label=$1 pellet=$2 tube=$3 count=$4 seed=$5 stepper=$6 window=$7 yard=$8
  local t="$work/time" out="$work/run"
  /usr/bin/time -f "%U %S" -o "$t" "$BIN/pack" --pellet "$work/$pellet" --tube-diameter "$tube" --count "$count" \
    --scheme batch --seed "$seed" --stepper "$stepper" --threads 1 -o "$out.mcap" >"$work/pack.log" 2>&1 || true
  local cpu settled
  cpu=$(awk '{printf "%.2f", $1 + $2}' "$t")
  settled=$(grep -o 'settled at [0-9.]* s' "$work/pack.log" | awk '{print $3}')
  local porosity=- olap=- measured
  if measured=$("$BIN/settle-check" "$out.mcap" -o "$out.packing" >/dev/null 2>&1 &&
    "$BIN/voidprof" "$out.packing" --window "$window" --structure --summary - -o /dev/null 2>/dev/null |
    python3 -c 'import json,sys; s=json.load(sys.stdin); o=s["deepest_overlap_dpv"]
print("%.4f %s" % (s["bulk_porosity"], "-" if o is None else "%.3f" % (100 * o)))'); then
    read -r porosity olap <<<"$measured"
  fi
  local pen
  pen=$(sed -n 's/.*, \([0-9.]*\) % at the end;.*/\1/p' "$work/pack.log")
  local ratio=-
  [ -n "$yard" ] && ratio=$(awk -v a="$cpu" -v b="$yard" 'BEGIN{printf "%.2f", a / b}')
  local per=-
  [ -n "$settled" ] && per=$(awk -v a="$cpu" -v n="$count" -v t="$settled" 'BEGIN{printf "%.2f", 1e3 * a / (n * t)}')
  local solve
  solve=$(sed -n 's/.*: \([0-9.]*\) contact points a pair, \([0-9.]*\) % of loaded.*, \([0-9.]*\) % of.*/\1 \2 \3/p' "$work/pack.log")
  [ -n "$solve" ] || solve="- - -"
  # shellcheck disable=SC2086
  printf "%-7s %-12s %4s %8s %9s %8s %8s %7s %9s %7s %7s %7s %7s\n" "$label" "$stepper" "$seed" "$cpu" "${settled:-unsettled}" \
    "$porosity" "$per" "$ratio" $solve "${pen:--}" "$olap"
}

printf "%-7s %-12s %4s %8s %9s %8s %8s %7s %9s %7s %7s %7s %7s\n" case stepper seed cpu_s settle_s porosity ms/N/s ratio pts/pair warm_% conv_% pen_% olap_%
for c in $CASES; do
  case $c in
    sph690)
      y=$(yardstick liggghts-690); [ -n "$y" ] && echo "yardstick liggghts-690 cpu_s $y"
      for s in $STEPPERS; do one sph690 s.pellet 79.9 690 1 $s 0,100 "$y"; done ;;
    cyl40)
      for seed in 1 2 3; do for s in $STEPPERS; do one cyl40 c.pellet 40 40 $seed $s 0,40 ""; done; done ;;
    ring40)
      for seed in 1 2 3; do for s in $STEPPERS; do one ring40 r.pellet 40 40 $seed $s 0,40 ""; done; done ;;
    ring256)
      y=$(yardstick rapier-256-rings); [ -n "$y" ] && echo "yardstick rapier-256-rings cpu_s $y"
      for s in $STEPPERS; do one ring256 r.pellet 60.18 256 1 $s 0,100 "$y"; done ;;
    cyl620)
      y=$(yardstick rapier-620); [ -n "$y" ] && echo "yardstick rapier-620 cpu_s $y"
      for s in $STEPPERS; do one cyl620 c.pellet 91.58 620 1 $s 0,100 "$y"; done ;;
    sph5000)
      for s in $STEPPERS; do one sph5000 s.pellet 154.6 5000 1 $s 0,200 ""; done ;;
    cyl2000)
      for s in $STEPPERS; do one cyl2000 c.pellet 135.3 2000 1 $s 0,150 ""; done ;;
    *) echo "bench-steppers: unknown case $c (sph690, cyl40, ring40, ring256, cyl620, sph5000, cyl2000)" >&2; exit 2 ;;
  esac
done
