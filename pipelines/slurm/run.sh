#!/bin/sh
# run.sh [OPTIONS] -- CMD ARGS...: runs one stage of a bed (CMD) as a Slurm
# job and returns what CMD printed and its exit code, as if it had run here.
# The pipelines put it in front of each stage through pipelines/slurm/sched.mk
# (SCHEDULER=slurm); README "On a cluster" says how to use it.
#
# Inside an allocation (SLURM_JOB_ID set) the stage is a job step (srun);
# elsewhere (a login node) it is a batch job of its own (sbatch --wait), which
# Slurm requeues on preemption and this script requeues when the warning
# signal comes before its time limit; `pack --resume` then goes on from the
# run's last checkpoint. Resources come from the command: pack's bed size and
# --max-time give its time limit and memory, the other stages are short.
#
# Options (sched.mk passes them from Make variables of the same meaning):
#   --name BED        the bed, for the job name and the log
#   --log FILE        the bed's log: every leg of every stage appends to it
#   --mode M          auto (srun inside an allocation, else sbatch), srun, sbatch
#   --cpus N          CPUs per stage (the pipelines give pack THREADS threads and ask for as many)
#   --max-time T      the longest time limit to ask for, minutes
#   --short-time T    the time limit of the stages other than pack, minutes
#   --grace S         the warning signal comes S seconds before the time limit
#   --requeues K      the most times a job requeues itself
#   --args ARGS       more sbatch/srun options (partition, account, ...),
#                     split at spaces; they come last, so they win
#   --dry-run         print the sbatch or srun command instead of running it
# Exit: CMD's code; 2 with one line on stderr when Slurm could not run CMD to
# its end (cancelled, timed out, failed to submit).
#
# Internal: run.sh --job PREFIX [--batch K] -- CMD ARGS... is the job's side
# (--batch: a batch job that may requeue itself K times).

set -u
self=$0

msg() { echo "run.sh: $*"; }
die() { echo "run.sh: error: $*" >&2; exit 2; }

# The stage's name: the first word that names a tool (timed.sh and nice come
# before it in some recipes).
stage_of() {
    for a; do
        case ${a##*/} in
        pack | settle-check | voidprof | compare | bedexport | mkpellet | paper-report)
            echo "${a##*/}"
            return
            ;;
        esac
    done
    echo "${1##*/}"
}

# --- the job's side: runs on the node, in a batch job or a job step -----------
job_side() {
    prefix=$1
    shift
    requeues=
    if [ "$1" = --batch ]; then requeues=$2; shift 2; fi
    shift # --
    leg=${SLURM_RESTART_COUNT:-0}
    job=${SLURM_JOB_ID:-?}${SLURM_STEP_ID:+.$SLURM_STEP_ID}
    # A leg requeued after CMD had finished must not run it again.
    if [ -f "$prefix.rc" ]; then
        msg "job $job leg $leg: the command finished in an earlier leg"
        exit "$(cat "$prefix.rc")"
    fi
    # A requeued pack goes on from its checkpoint (without a checkpoint
    # --resume starts over, so the result is the same either way).
    if [ "$leg" -gt 0 ] && [ "$(stage_of "$@")" = pack ]; then
        resume=1
        for a; do [ "$a" = --resume ] && resume=; done
        if [ -n "$resume" ]; then
            for a; do
                shift
                set -- "$@" "$a"
                case ${a##*/} in pack) [ -n "$resume" ] && set -- "$@" --resume && resume= ;; esac
            done
        fi
    fi
    msg "job $job leg $leg on $(hostname): $*"
    # The submitting side stops a step by its id (srun would kill it outright).
    [ -n "$requeues" ] || echo "$job" >"$prefix.step"
    # Which partial run a resuming pack finds (pack --quiet does not say).
    if [ "$(stage_of "$@")" = pack ]; then
        out=
        next=
        for a; do
            if [ -n "$next" ]; then out=$a; next=; fi
            case $a in -o | --output) next=1 ;; --output=*) out=${a#--output=} ;; esac
        done
        for f in "$out" "$out.part" "$out.resume"; do
            [ -n "$out" ] && [ -f "$f" ] && msg "partial run there: $f ($(wc -c <"$f") bytes)"
        done
    fi
    stopped=
    # Slurm ends a job (cancel, requeue, preemption, time limit) with SIGTERM
    # to every process of it, pack included; wait for pack to close its archive.
    trap 'stopped=1' TERM INT HUP
    # The warning before the time limit (sbatch --signal=B:USR1@grace, to this
    # shell only): requeue, which ends this leg as above.
    trap 'warned' USR1
    "$@" >"$prefix.out" 2>"$prefix.err" &
    pid=$!
    while :; do
        wait "$pid"
        rc=$?
        kill -0 "$pid" 2>/dev/null || break
    done
    cat "$prefix.err"
    if [ -n "$stopped" ]; then
        if [ -n "$requeues" ]; then after="cancelled, or requeued to go on"; else after="the next make goes on"; fi
        msg "job $job leg $leg stopped by Slurm (the command exited $rc): $after"
        exit 143
    fi
    echo "$rc" >"$prefix.rc.tmp" && mv "$prefix.rc.tmp" "$prefix.rc"
    msg "job $job leg $leg: exit $rc"
    exit "$rc"
}

warned() {
    if [ -z "$requeues" ]; then
        msg "SIGUSR1 in a job step: ignored (only a batch job of its own requeues itself)"
    elif [ "$leg" -ge "$requeues" ]; then
        msg "job $SLURM_JOB_ID near its time limit after $leg requeues (the most, --requeues $requeues): not requeued"
    else
        msg "job $SLURM_JOB_ID near its time limit: requeued, to go on from the checkpoint"
        scontrol requeue "$SLURM_JOB_ID" || msg "scontrol requeue $SLURM_JOB_ID failed; the job runs to its time limit"
    fi
}

if [ "${1:-}" = --job ]; then
    shift
    job_side "$@"
fi

# --- the submitting side: where make runs --------------------------------------
name=
log=
mode=auto
cpus=1
max_time=1440
short_time=60
grace=300
requeues=10
extra=
dry=
while [ $# -gt 0 ]; do
    case $1 in
    --name) name=$2; shift 2 ;;
    --log) log=$2; shift 2 ;;
    --mode) mode=$2; shift 2 ;;
    --cpus) cpus=$2; shift 2 ;;
    --max-time) max_time=$2; shift 2 ;;
    --short-time) short_time=$2; shift 2 ;;
    --grace) grace=$2; shift 2 ;;
    --requeues) requeues=$2; shift 2 ;;
    --args) extra=$2; shift 2 ;;
    --dry-run) dry=1; shift ;;
    --) shift; break ;;
    *) die "unknown option $1 (usage: run.sh [--name BED] [--log FILE] [OPTIONS] -- CMD ARGS...)" ;;
    esac
done
[ $# -gt 0 ] || die "no command to run (usage: run.sh [OPTIONS] -- CMD ARGS...)"
for n in "$cpus" "$max_time" "$short_time" "$grace" "$requeues"; do
    case $n in '' | *[!0-9]*) die "--cpus, --max-time, --short-time, --grace and --requeues take whole numbers, not '$n'" ;; esac
done
stage=$(stage_of "$@")
[ -n "$name" ] || name=$stage
[ -n "$log" ] || log=slurm-$name.log
case $mode in
auto) if [ -n "${SLURM_JOB_ID:-}" ]; then mode=srun; else mode=sbatch; fi ;;
srun | sbatch) ;;
*) die "--mode $mode: give auto, srun or sbatch" ;;
esac
[ -n "$dry" ] || command -v "$mode" >/dev/null || die "$mode not found: SCHEDULER=slurm needs the Slurm client commands on PATH"

# pack's bed: pellets (given, or the fill height's worth at a solid fraction
# of 0.6), simulated time limit (pack's default 120 s) and shape, from the
# flags or else the case file. Other stages: the short limit.
estimate() {
    awk -v mkpellet="$mkpellet" -v max_time="$max_time" -v short_time="$short_time" -v grace="$grace" -v stage="$stage" '
    function val(s) { sub(/^[^=]*=[ \t]*/, "", s); sub(/[ \t]*(#.*)?$/, "", s); gsub(/"/, "", s); return s }
    BEGIN {
        if (stage != "pack") { minutes = short_time; if (minutes < grace / 60 + 5) minutes = grace / 60 + 5; printf "%d 2048\n", minutes + 0.999; exit }
        n = split(ARGV[1], a, "\037"); ARGV[1] = ""
        for (i = 1; i <= n; i++) {
            if (a[i] ~ /(^|\/)pack$/) seen = 1
            if (!seen) continue
            if (a[i] ~ /^--[a-z-]+=/) { k = a[i]; sub(/=.*/, "", k); flag[k] = val(a[i]); continue }
            if (a[i] ~ /^--/ && i < n) flag[a[i]] = a[i + 1]
        }
        if ("--case" in flag) {
            file = flag["--case"]; dir = file; if (!sub(/\/[^\/]*$/, "", dir)) dir = "."
            while ((getline line < file) > 0) {
                if (line !~ /^[a-z-]+[ \t]*=/) continue
                k = line; sub(/[ \t]*=.*/, "", k)
                if (k == "pellet") case_pellet = val(line)
                else if (!(("--" k) in flag)) flag["--" k] = val(line)
            }
            if (case_pellet != "" && !("--pellet" in flag)) flag["--pellet"] = (case_pellet ~ /^\//) ? case_pellet : dir "/" case_pellet
        }
        t = ("--max-time" in flag) ? flag["--max-time"] + 0 : 120
        rate = 1.5; volume = 0
        if ("--pellet" in flag) {
            cmd = "\"" mkpellet "\" info \"" flag["--pellet"] "\" 2>/dev/null"
            while ((cmd | getline line) > 0) {
                if (line ~ /^shape:/) rate = (line ~ /^shape:[ \t]+sphere/) ? 0.15 : 1.5
                if (line ~ /^volume:/) { split(line, w, /[ \t]+/); volume = w[2] + 0 }
            }
            close(cmd)
        }
        if ("--count" in flag) pellets = flag["--count"] + 0
        else if (volume > 0 && ("--fill-height" in flag) && ("--tube-diameter" in flag))
            pellets = 0.6 * 3.14159265 * flag["--tube-diameter"] ^ 2 / 4 * flag["--fill-height"] / volume
        else pellets = 0
        # Wall seconds per pellet and simulated second: the slowest beds of the
        # paper study (spheres 0.12, cylinders 1.4, rings 1.0), doubled.
        if (pellets > 0) minutes = (2 * grace + 2 * rate * pellets * t) / 60 + 10
        else minutes = max_time
        if (minutes > max_time) minutes = max_time
        # Room for the warning signal before the limit.
        if (minutes < grace / 60 + 5) minutes = grace / 60 + 5
        printf "%d %d\n", minutes + 0.999, 512 + pellets
    }' "$(printf '%s\037' "$@")"
}
# mkpellet reads the pellet's shape and volume; it sits beside pack.
mkpellet=mkpellet
for a; do case ${a##*/} in pack) mkpellet=${a%pack}mkpellet ;; esac; done
resources=$(estimate "$@") || die "could not work out the resources of: $*"
time_min=${resources% *}
mem_mb=${resources#* }

logdir=$(dirname "$log")
spool=$logdir/.jobs
prefix=$spool/$name.$stage.$(hostname).$$
# $extra is a list of options: split at spaces.
if [ "$mode" = sbatch ]; then
    set -- sbatch --parsable --wait --job-name="$name:$stage" --nodes=1 --ntasks=1 --cpus-per-task="$cpus" \
        --mem="${mem_mb}M" --time="$time_min" --requeue --signal=B:USR1@"$grace" \
        --output="$log" --open-mode=append $extra "$self" --job "$prefix" --batch "$requeues" -- "$@"
else
    set -- srun --nodes=1 --ntasks=1 --cpus-per-task="$cpus" --mem="${mem_mb}M" --exact --job-name="$name:$stage" \
        $extra sh "$self" --job "$prefix" -- "$@"
fi
if [ -n "$dry" ]; then
    echo "$*"
    exit 0
fi
mkdir -p "$spool" || die "cannot create $spool"
rm -f "$prefix".*

jobid=
pid=
interrupted=
cancel() {
    interrupted=1
    # SIGTERM to the step's processes: pack closes its archive, the step ends.
    if [ "$mode" = srun ]; then
        if [ -f "$prefix.step" ]; then scancel --signal=TERM "$(cat "$prefix.step")"; else kill -TERM "$pid" 2>/dev/null; fi
        return 0
    fi
    [ -f "$prefix.id" ] && jobid=$(cut -d';' -f1 "$prefix.id")
    [ -n "$jobid" ] && scancel "$jobid"
}
trap cancel INT TERM HUP
if [ "$mode" = sbatch ]; then
    "$@" >"$prefix.id" 2>"$prefix.submit" &
else
    # Out of the terminal's reach (setsid): srun takes SIGINT and SIGTERM from the terminal
    # or from make as an order to kill the step at once.
    setsid "$@" >>"$log" 2>&1 </dev/null &
fi
pid=$!
# make's Ctrl-C stops the job too, so no run goes on unseen.
while :; do
    wait "$pid"
    status=$?
    kill -0 "$pid" 2>/dev/null || break
done
[ -f "$prefix.id" ] && jobid=$(cut -d';' -f1 "$prefix.id")
if [ -n "$interrupted" ] && [ -n "$jobid" ]; then
    # Wait (a while) for the job to end, so that the next make finds pack's
    # archive closed and not locked by a run still going.
    i=0
    while [ $i -lt 120 ] && scontrol -o show job "$jobid" 2>/dev/null |
        grep -q 'JobState=\(PENDING\|RUNNING\|COMPLETING\|CONFIGURING\|SUSPENDED\|REQUEUED\|RESIZING\|STOPPED\|SIGNALING\)'; do
        sleep 1
        i=$((i + 1))
    done
fi
if [ -f "$prefix.rc" ]; then
    cat "$prefix.out"
    cat "$prefix.err" >&2
    rc=$(cat "$prefix.rc")
    rm -f "$prefix".*
    exit "$rc"
fi
# The command did not finish: say why, with what it printed.
[ -f "$prefix.err" ] && cat "$prefix.err" >&2
if [ "$mode" = sbatch ] && [ -z "$jobid" ]; then
    why="could not submit ($(tr '\n' ' ' <"$prefix.submit" | sed 's/ *$//'))"
elif [ -n "$jobid" ]; then
    state=$(scontrol -o show job "$jobid" 2>/dev/null | sed -n 's/.*JobState=\([A-Z_]*\).*/\1/p')
    why="job $jobid ended ${state:-(state unknown)}"
else
    why="srun exited $status"
fi
[ -n "$interrupted" ] && why="interrupted; $why"
rm -f "$prefix".*
die "$name: $stage did not finish under Slurm: $why (log: $log)"
