#!/bin/sh
# test.sh BIN (make test-slurm): the pipelines on a real one-node Slurm
# (tests/slurm/cluster.sh), against the same runs made locally with the
# binaries in BIN:
#   1. a small paper study (pipelines/paper.mk, a table of tiny beds) run
#      locally, then from "a login node" (SCHEDULER=slurm, batch jobs): every
#      file of every bed the same byte for byte, the tools' exit codes
#      passed through (a bed past its --max-time: pack 2, settle-check 1);
#      meanwhile one bed's pack job is requeued mid-run (as preemption does)
#      and another gets the warning signal before its time limit (it
#      requeues itself): both resume from their checkpoint and end with the
#      same settled bed as the local run (the trajectory is chunked
#      differently after a resume, so its .mcap is not compared);
#   2. a bed whose job is cancelled mid-run fails its make target and says
#      so; the next make resumes it and finishes it as the local run did;
#   3. the same study inside an allocation (salloc: job steps);
#   4. the default pipeline (pipelines/default.mk) locally and on Slurm, its
#      pack requeued mid-run (the recipe has no --resume: run.sh adds it).
# Stops every daemon it started, by pid; KEEP=1 keeps the runs. Fails (exit 1) when Slurm cannot
# start: it never passes by skipping.
set -u
[ $# -eq 1 ] || { echo "test-slurm: error: usage: test.sh BIN" >&2; exit 2; }
root=$(cd "$(dirname "$0")/../.." && pwd)
bin=$(cd "$1" 2>/dev/null && pwd) || { echo "test-slurm: error: no directory $1 (build first)" >&2; exit 2; }
for t in mkpellet pack settle-check voidprof compare bedexport; do
    [ -x "$bin/$t" ] || { echo "test-slurm: error: $bin/$t missing (build first)" >&2; exit 2; }
done
work=$(mktemp -d "${TMPDIR:-/tmp}/packbed-slurm.XXXXXX") || exit 2
# munged wants every directory above its socket open to all.
chmod 755 "$work"
cluster=$work/cluster
start=$(date +%s)

say() { echo "test-slurm: [$(($(date +%s) - start)) s] $*"; }
fail() {
    echo "test-slurm: FAILED: $*" >&2
    for f in "$work"/*/out/slurm/*.log "$cluster"/log/slurmctld.log; do
        [ -f "$f" ] || continue
        echo "--- $f" >&2
        tail -n 20 "$f" >&2
    done
    echo "test-slurm: the runs are kept in $work" >&2
    keep=1
    exit 1
}
keep=${KEEP:-}
watchers=
cleanup() {
    # shellcheck disable=SC2086 # a list of pids
    [ -z "$watchers" ] || kill $watchers 2>/dev/null
    sh "$root/tests/slurm/cluster.sh" stop "$cluster"
    [ -n "$keep" ] || rm -rf "$work"
}
trap cleanup EXIT
trap 'fail "interrupted"' INT TERM HUP

sh "$root/tests/slurm/cluster.sh" start "$cluster" ||
    fail "Slurm could not start (slurm-wlm and munge installed? see the lines above)"
export SLURM_CONF="$cluster/slurm.conf"

# Five tiny beds (9-19 pellets, about a second each; one stopped by its
# --max-time before it settles) and two of about 150 spheres (some 15 s
# each), to be interrupted.
cat >"$work/beds.csv" <<'EOF'
config,study,shape,tube_diameter_mm,seeds,fill_height_mm,window_z0_mm,window_z1_mm,scheme,cor,friction,position_jitter,angle_jitter,max_time_s,label,same_as,drop_height_mm
t-sphere-D30,validation,sphere,30,2,20,0,15,one-column,,,,,5,tiny spheres
t-cylinder-D30,validation,cylinder,30,1,20,0,15,one-column,,,,,5,tiny cylinders
t-ring-D30,validation,ring,30,1,20,0,15,one-column,,,,,5,tiny rings
t-unsettled-D30,validation,sphere,30,1,20,0,15,one-column,,,,,0.3,stopped before it settles
t-long-D40,loading,sphere,40,2,120,0,100,one-column,,,,,20,interrupted beds
EOF
TINY="t-sphere-D30-s1 t-sphere-D30-s2 t-cylinder-D30-s1 t-ring-D30-s1 t-unsettled-D30-s1"
LONG="t-long-D40-s1 t-long-D40-s2"

# make with the paper pipeline in directory $1 (created), then the rest.
paper() {
    d=$1
    shift
    mkdir -p "$work/$d"
    (cd "$work/$d" && make --no-print-directory -f "$root/pipelines/paper.mk" BIN="$bin" OUT=out DOCS=docs \
        TABLE="$work/beds.csv" "$@")
}

# Every file of beds $4... in run $3 equal to run $2's, the trajectories
# too if $1 is "with-mcap". Times (*.time) differ by nature and are left out.
same_beds() {
    mcap=
    [ "$1" = with-mcap ] && mcap=1
    a=$2
    b=$3
    shift 3
    for id; do
        n=0
        for f in "$work/$a/out/cases/$id".* "$work/$a/out/runs/$id".* "$work/$a/docs/runs/$id".*; do
            case $f in *.time) continue ;; *.mcap) [ -n "$mcap" ] || continue ;; esac
            g=$work/$b/${f#"$work/$a/"}
            cmp -s "$f" "$g" || fail "$id: ${f#"$work/$a/"} differs between the $a and the $b run"
            n=$((n + 1))
        done
        [ $n -ge 8 ] || fail "$id: only $n files to compare in the $a run"
    done
}

# Waits for job $1 (a job name) to run and for the files matching $2 (pack's
# partial trajectory, written a simulated second at a time) to reach $3
# bytes, then runs $4... with the job's id appended, while the job still runs.
# Progress, not time: the machine may be busy.
when_running() {
    job=$1
    files=$2
    bytes=$3
    shift 3
    i=0
    while :; do
        id=$(squeue -h -t R -n "$job" -o %i)
        if [ -n "$id" ]; then
            # shellcheck disable=SC2086 # a glob
            size=$(cat $files 2>/dev/null | wc -c)
            [ "$size" -ge "$bytes" ] && break
        fi
        i=$((i + 1))
        [ $i -lt 1500 ] || { echo "when_running: $job did not reach $bytes bytes of $files" >"$work/when.$job"; return 1; }
        sleep 0.2
    done
    [ -n "$(squeue -h -t R -j "$id" -o %i 2>/dev/null)" ] ||
        { echo "when_running: $job ($id) ended before it could be interrupted" >"$work/when.$job"; return 1; }
    "$@" "$id" || { echo "when_running: $* $id failed" >"$work/when.$job"; return 1; }
    echo "$id" >"$work/when.$job"
}
# Four tenths of a file's size: a bed well inside its run.
part_of() { echo $(($(wc -c <"$1") * 2 / 5)); }
# A paper bed of the run in $1: its partial trajectory, 0.4 of the local one.
paper_bed() { echo "$work/$1/out/runs/$2.run.mcap.part $(part_of "$work/local/out/runs/$2.mcap")"; }

say "1. the study locally"
paper local -j2 all >"$work/local.log" 2>&1 || fail "the local study failed (log: $work/local.log)"
grep -q '"settled": false' "$work/local/out/runs/t-unsettled-D30-s1.settle.json" ||
    fail "t-unsettled-D30-s1 settled locally: it no longer tests exit codes 2 and 1"

say "1. the study on Slurm (batch jobs), one bed requeued, one warned before its time limit"
# shellcheck disable=SC2046 # two words
when_running t-long-D40-s1:pack $(paper_bed sbatch t-long-D40-s1) scontrol requeue &
w1=$!
watchers="$watchers $w1"
# shellcheck disable=SC2046
when_running t-long-D40-s2:pack $(paper_bed sbatch t-long-D40-s2) scancel --batch --signal=USR1 &
w2=$!
watchers="$watchers $w2"
paper sbatch -j7 all SCHEDULER=slurm SLURM_MODE=sbatch >"$work/sbatch.log" 2>&1 ||
    fail "the study on Slurm failed (log: $work/sbatch.log)"
wait $w1 || fail "$(cat "$work/when.t-long-D40-s1:pack")"
wait $w2 || fail "$(cat "$work/when.t-long-D40-s2:pack")"
same_beds with-mcap local sbatch $TINY
same_beds no-mcap local sbatch $LONG
log=$work/sbatch/out/slurm
for id in $TINY $LONG; do
    [ -s "$log/$id.log" ] || fail "no log of $id in $log"
done
# Not settled within --max-time: pack and settle-check both say no (exit 1), and both codes
# reach make, pack's before settle-check's.
[ "$(grep -c 'leg 0: exit 1' "$log/t-unsettled-D30-s1.log")" -ge 2 ] ||
    fail "pack's and settle-check's exit code 1 not passed through (log $log/t-unsettled-D30-s1.log)"
for id in $LONG; do
    grep -q "pack: error: interrupted at t = [0-9.]* s" "$log/$id.log" || fail "$id: pack was not interrupted (log $log/$id.log)"
    grep -q "leg 1 on " "$log/$id.log" || fail "$id: no second leg after the requeue"
    grep -q "partial run there: out/runs/$id.run.mcap" "$log/$id.log" || fail "$id: the requeued leg found no partial run"
done
grep -q 'near its time limit: requeued' "$log/t-long-D40-s2.log" || fail "t-long-D40-s2 did not requeue itself on the warning"
leg0=$(sed -n 's/.*interrupted at t = \([0-9.]*\) s.*/\1/p' "$log/t-long-D40-s1.log" | head -1)
say "   requeued at t = $leg0 s and resumed, the warned bed too; every bed as the local run"

say "2. a bed cancelled mid-run, then resumed by the next make"
id="t-long-D40-s1"
rm -f "$work/sbatch/out/runs/$id".* "$work/sbatch/docs/runs/$id".* "$log/$id.log"
# shellcheck disable=SC2046
when_running $id:pack $(paper_bed sbatch $id) scancel &
w1=$!
watchers="$watchers $w1"
if paper sbatch "docs/runs/$id.summary.json" SCHEDULER=slurm SLURM_MODE=sbatch >"$work/cancel.log" 2>&1; then
    fail "make succeeded although the bed's job was cancelled"
fi
wait $w1 || fail "$(cat "$work/when.$id:pack")"
grep -q "run.sh: error: $id: pack did not finish under Slurm: job [0-9]* ended CANCELLED" "$work/cancel.log" ||
    fail "the cancelled bed's make did not say why it failed (log: $work/cancel.log)"
[ -f "$work/sbatch/out/runs/$id.run.mcap" ] || fail "the cancelled pack left no partial run"
paper sbatch "docs/runs/$id.summary.json" SCHEDULER=slurm SLURM_MODE=sbatch >"$work/resume.log" 2>&1 ||
    fail "the next make did not finish the cancelled bed (log: $work/resume.log)"
grep -q "partial run there: out/runs/$id.run.mcap" "$log/$id.log" || fail "the next make did not resume the cancelled bed"
same_beds no-mcap local sbatch $id
say "   cancelled: make failed with the job's state; resumed and finished as the local run"

say "3. the study inside an allocation (job steps)"
mkdir -p "$work/srun"
(cd "$work/srun" && salloc --quiet -N1 -c "$(nproc)" --mem=8G make --no-print-directory -f "$root/pipelines/paper.mk" \
    BIN="$bin" OUT=out DOCS=docs TABLE="$work/beds.csv" -j2 validation SCHEDULER=slurm) >"$work/srun.log" 2>&1 ||
    fail "the study in an allocation failed (log: $work/srun.log)"
grep -q 'leg 0 on ' "$work/srun/out/slurm/t-ring-D30-s1.log" || fail "no job step in the allocation's bed log"
same_beds with-mcap local srun $TINY
say "   every bed as the local run"

say "4. the default pipeline locally and on Slurm, its pack requeued mid-run"
# 80 spheres (some 7 s) instead of 40, to be requeued mid-run.
bed="--tube-diameter 40 --count 80 --seed 1"
mkdir -p "$work/default-local" "$work/default-slurm"
(cd "$work/default-local" && make --no-print-directory -f "$root/pipelines/default.mk" BIN="$bin" OUT=out BED_ARGS="$bed") \
    >"$work/default-local.log" 2>&1 || fail "the default pipeline failed locally (log: $work/default-local.log)"
# Whatever the recipe names pack's output, its partial run ends in .mcap.part.
when_running bed:pack "$work/default-slurm/out/*.mcap.part" "$(part_of "$work/default-local/out/bed.mcap")" scontrol requeue &
w1=$!
watchers="$watchers $w1"
(cd "$work/default-slurm" && make --no-print-directory -f "$root/pipelines/default.mk" BIN="$bin" OUT=out BED_ARGS="$bed" \
    SCHEDULER=slurm) >"$work/default-slurm.log" 2>&1 || fail "the default pipeline failed on Slurm (log: $work/default-slurm.log)"
wait $w1 || fail "$(cat "$work/when.bed:pack")"
(cd "$work/default-local" && find out -type f | sort) >"$work/default.files"
[ "$(wc -l <"$work/default.files")" -ge 15 ] || fail "the default pipeline wrote too few files"
while read -r f; do
    # The trajectory, and the tools' own output (timings, Slurm's legs), differ.
    case $f in out/bed.mcap | out/log/*) continue ;; esac
    cmp -s "$work/default-local/$f" "$work/default-slurm/$f" || fail "default pipeline: $f differs on Slurm"
done <"$work/default.files"
grep -q 'leg 1 on .*/pack .*--resume' "$work/default-slurm/out/slurm/bed.log" ||
    fail "the requeued pack of the default pipeline did not go on with --resume"
say "   resumed; every file the same but the trajectory"

say "passed in $(($(date +%s) - start)) s (Slurm $(sinfo --version | awk '{ print $2 }'))"
