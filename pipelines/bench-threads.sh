#!/usr/bin/env bash
# How `pack --threads` scales on pack's reference beds, in one run on one machine:
#   [THREADS="1 2"] [REPEATS=3] bash pipelines/bench-threads.sh [BIN] [CASES]
# BIN: the release binaries (default target/release). CASES (default "ring256 cyl620 sph690"):
#   ring256  256 Raschig rings 10/6 x 10 mm, D = 60.18 mm, batch, the first 0.3 s of the pour
#   cyl620   620 cylinders 10 x 10 mm, D = 91.58 mm, batch, the first 0.3 s of the pour
#   sph690   690 spheres of 10 mm, D = 79.9 mm, batch, to rest
#   cyl620-rest  the 620 cylinders to rest (about a minute a repeat; not in the default cases)
# Each repeat runs the thread counts one after another (so a drift of the machine's speed
# hits them alike); per case and thread count it prints the median wall and CPU seconds
# (user + system) over the repeats, and beside the first thread count's run of the same
# repeat the median wall ratio (with its range: a wide one says the machine was busy), the
# CPU ratio, and whether every frame's poses (settle-check --all-frames --csv) are the same
# bit for bit. The serial fraction behind these figures, and what it gives on more cores:
# docs/engine.md, Threads.
set -euo pipefail
BIN=${1:-target/release}
CASES=${2:-ring256 cyl620 sph690}
THREADS=${THREADS:-1 2}
REPEATS=${REPEATS:-3}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$BIN/mkpellet" sphere --diameter 10 -o "$work/s.pellet" >/dev/null
"$BIN/mkpellet" cylinder --diameter 10 --height 10 -o "$work/c.pellet" >/dev/null
"$BIN/mkpellet" ring --outer-diameter 10 --inner-diameter 6 --height 10 -o "$work/r.pellet" >/dev/null

args_of() {  # case → pack's arguments
  case $1 in
    ring256) echo "--pellet $work/r.pellet --tube-diameter 60.18 --count 256 --max-time 0.3" ;;
    cyl620) echo "--pellet $work/c.pellet --tube-diameter 91.58 --count 620 --max-time 0.3" ;;
    sph690) echo "--pellet $work/s.pellet --tube-diameter 79.9 --count 690" ;;
    cyl620-rest) echo "--pellet $work/c.pellet --tube-diameter 91.58 --count 620" ;;
    *) echo "bench-threads: unknown case $1 (ring256, cyl620, sph690, cyl620-rest)" >&2; return 2 ;;
  esac
}

printf "%-8s %7s %8s %8s %18s %9s %11s\n" case threads wall_s cpu_s wall_ratio cpu_ratio same_frames
for c in $CASES; do
  args=$(args_of "$c")
  for r in $(seq 1 "$REPEATS"); do
    for n in $THREADS; do
      t="$work/$c.$n.$r"
      # shellcheck disable=SC2086
      /usr/bin/time -f "%e %U %S" -o "$t.time" "$BIN/pack" $args --scheme batch --seed 1 --threads "$n" \
        --quiet --force -o "$t.mcap" >/dev/null 2>&1 || true
      "$BIN/settle-check" "$t.mcap" --all-frames --csv "$t.csv" >/dev/null 2>&1 || true
      rm -f "$t.mcap"
    done
  done
  first=${THREADS%% *}
  python3 - "$work" "$c" "$first" "$REPEATS" $THREADS <<'EOF'
import filecmp, os, statistics, sys
work, case, first, repeats, threads = sys.argv[1], sys.argv[2], sys.argv[3], int(sys.argv[4]), sys.argv[5:]
def times(n, r):
    wall, user, system = open(os.path.join(work, f"{case}.{n}.{r}.time")).read().split()[-3:]
    return float(wall), float(user) + float(system)
for n in threads:
    runs = [times(n, r) for r in range(1, repeats + 1)]
    base = [times(first, r) for r in range(1, repeats + 1)]
    wall = statistics.median(w for w, _ in runs)
    cpu = statistics.median(c for _, c in runs)
    ratios = sorted(w / b[0] for (w, _), b in zip(runs, base))
    cpu_ratio = statistics.median(c / b[1] for (_, c), b in zip(runs, base))
    same = all(
        os.path.exists(p := os.path.join(work, f"{case}.{n}.{r}.csv"))
        and filecmp.cmp(p, os.path.join(work, f"{case}.{first}.{r}.csv"), shallow=False)
        for r in range(1, repeats + 1)
    )
    span = "%.3f (%.3f-%.3f)" % (statistics.median(ratios), ratios[0], ratios[-1])
    print("%-8s %7s %8.2f %8.2f %18s %9.3f %11s" % (case, n, wall, cpu, span, cpu_ratio, "yes" if same else "NO"))
EOF
done
