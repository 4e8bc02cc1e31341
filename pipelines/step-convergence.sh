#!/usr/bin/env bash
# Whether a stepper's beds depend on its step: each bed packed at pack's default step and at
# fractions of it (the velocity-level stepper's --step-travel and --max-step both scaled; the
# force-level stepper's --substep-scale), over several seeds, then a markdown table of the bulk porosity (mean ± standard error), the mean
# CPU time and the settle times, with the change of the mean from the row above in combined
# standard errors.
#   [SEEDS=10] [SCALES="1 0.5"] [LIMIT=both] bash pipelines/step-convergence.sh [BIN] [OUT] [CASES]
# LIMIT: which of the velocity-level stepper's two limits the scale applies to: both (the
# default), travel (--step-travel only) or max-step (--max-step only); the other stays at
# pack's default. Beds of a single limit are kept apart (<case>.<limit>-<scale>.<seed>).
# BIN: the release binaries (default target/release); OUT: where the beds go (default
# out/step-convergence); CASES (default "sph690 cyl300"):
#   sph690  690 spheres of 10 mm, D = 79.9 mm, batch; porosity over 0–100 mm
#   cyl300  300 cylinders 10 x 10 mm, D = 69.83 mm, batch; porosity over 0–80 mm
#   sph690-force, cyl300-force  the same beds with the force-level stepper
#     (--stepper acceleration; about three times the CPU)
# Resumable: a bed whose summary is in OUT is not packed again (delete OUT to re-run). The
# seeds run one after another on one core; a few minutes for sph690, about half an hour for
# cyl300 at two scales.
set -euo pipefail
BIN=${1:-target/release}
OUT=${2:-out/step-convergence}
CASES=${3:-sph690 cyl300}
SEEDS=${SEEDS:-10}
SCALES=${SCALES:-1 0.5}
LIMIT=${LIMIT:-both}
case $LIMIT in
  both) tag= ;;
  travel | max-step) tag="$LIMIT-" ;;
  *) echo "step-convergence: LIMIT must be both, travel or max-step (got $LIMIT)" >&2; exit 2 ;;
esac
mkdir -p "$OUT"
[ -f "$OUT/s.pellet" ] || "$BIN/mkpellet" sphere --diameter 10 -o "$OUT/s.pellet" >/dev/null
[ -f "$OUT/c.pellet" ] || "$BIN/mkpellet" cylinder --diameter 10 --height 10 -o "$OUT/c.pellet" >/dev/null

# pack's own defaults, from its --help, so that scale 1 is exactly the default step.
default_of() {
  "$BIN/pack" --help | tr '\n' ' ' | sed -n "s/.*--$1 <[A-Z]*> [^[]*\[default: \([0-9.e-]*\);.*/\1/p"
}
travel=$(default_of step-travel)
max_step=$(default_of max-step)
[ -n "$travel" ] && [ -n "$max_step" ] || { echo "step-convergence: cannot read pack's default step" >&2; exit 2; }

bed() {  # case scale seed → packs it unless done; its record is $OUT/<case>.<scale>.<seed>.json
  local case=$1 scale=$2 seed=$3 args window
  local t="$OUT/$case.$tag$scale.$seed"
  [ -f "$t.json" ] && return 0
  local step
  case $case in
    *-force)
      [ "$LIMIT" = both ] || { echo "step-convergence: LIMIT=$LIMIT is the velocity-level stepper's; $case has one substep rule" >&2; exit 2; }
      step="--stepper acceleration --substep-scale $scale" ;;
    *) local kt=$scale km=$scale
       [ "$LIMIT" = max-step ] && kt=1
       [ "$LIMIT" = travel ] && km=1
       step="--stepper velocity --step-travel $(awk -v a="$travel" -v k="$kt" 'BEGIN{print a * k}')"
       step="$step --max-step $(awk -v a="$max_step" -v k="$km" 'BEGIN{print a * k}')" ;;
  esac
  case ${case%-force} in
    sph690) args="--pellet $OUT/s.pellet --tube-diameter 79.9 --count 690"; window=0,100 ;;
    cyl300) args="--pellet $OUT/c.pellet --tube-diameter 69.83 --count 300"; window=0,80 ;;
    *) echo "step-convergence: unknown case $case (sph690, cyl300, with or without -force)" >&2; exit 2 ;;
  esac
  # shellcheck disable=SC2086
  /usr/bin/time -f "%U %S" -o "$t.time" "$BIN/pack" $args --scheme batch --seed "$seed" $step --threads "${THREADS:-1}" \
    --max-time 20 --quiet --force -o "$t.mcap" >"$t.log" 2>&1 || true
  grep -o 'settled at [0-9.]* s' "$t.log" | awk '{print $3}' >"$t.settled" || true
  "$BIN/settle-check" "$t.mcap" -o "$t.packing" >/dev/null 2>&1 &&
    "$BIN/voidprof" "$t.packing" --window "$window" --summary "$t.json.part" -o /dev/null 2>/dev/null &&
    mv "$t.json.part" "$t.json"
  rm -f "$t.mcap" "$t.packing"
}

for case in $CASES; do
  for scale in $SCALES; do
    for seed in $(seq 1 "$SEEDS"); do
      bed "$case" "$scale" "$seed"
    done
  done
done

python3 - "$OUT" "$travel" "$max_step" "$SEEDS" "$CASES" "$SCALES" "$LIMIT" <<'EOF'
import json, math, os, sys
out, travel, max_step, seeds, cases, scales, limit = sys.argv[1], float(sys.argv[2]), float(sys.argv[3]), int(sys.argv[4]), sys.argv[5].split(), sys.argv[6].split(), sys.argv[7]
tag = "" if limit == "both" else limit + "-"
print("| bed | step | seeds | bulk porosity, mean ± s.e. | change (s.e.) | CPU s, mean | settled at, s |")
print("|---|---|---|---|---|---|---|")
for case in cases:
    above = None
    for scale in scales:
        por, cpu, settled = [], [], []
        for seed in range(1, seeds + 1):
            t = os.path.join(out, f"{case}.{tag}{scale}.{seed}")
            if not os.path.exists(t + ".json"):
                continue
            por.append(json.load(open(t + ".json"))["bulk_porosity"])
            user, system = open(t + ".time").read().split()[-2:]
            cpu.append(float(user) + float(system))
            s = open(t + ".settled").read().strip()
            settled.append(float(s) if s else math.inf)
        if len(por) < 2:
            continue
        n = len(por)
        mean = sum(por) / n
        se = math.sqrt(sum((p - mean) ** 2 for p in por) / (n - 1) / n)
        change = "—" if above is None else "%+.4f (%+.1f)" % (mean - above[0], (mean - above[0]) / math.hypot(se, above[1]))
        k = float(scale)
        default = " (default)" if k == 1 else ""
        if case.endswith("-force"):
            step = "substep × %g%s" % (k, default)
        else:
            kt = 1 if limit == "max-step" else k
            km = 1 if limit == "travel" else k
            step = "travel %g d, at most %g ms%s" % (travel * kt, max_step * km * 1e3, default)
        late = "%.2f–%.2f" % (min(settled), max(settled))
        print(f"| {case} | {step} | {n} | {mean:.4f} ± {se:.4f} | {change} | {sum(cpu) / n:.2f} | {late} |")
        above = (mean, se)
EOF
