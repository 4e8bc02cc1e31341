#!/bin/sh
# cluster.sh start DIR | stop DIR: a one-node Slurm on this machine, for
# tests/slurm/test.sh (and by hand, to try the pipelines on Slurm). Debian's
# slurm-wlm and munge, no systemd: munged with its own key and socket,
# slurmctld and slurmd as plain processes on localhost, no accounting, as
# many CPUs as the machine has. Everything lives in DIR: the configuration
# (DIR/slurm.conf: export SLURM_CONF=DIR/slurm.conf to use the cluster),
# state, logs and the daemons' pids, by which `stop` ends them.
# Exit: 0 started/stopped; 2 with one line on stderr when it cannot.
set -u

die() { echo "cluster.sh: error: $*" >&2; exit 2; }

# Up to the last lines of each daemon's log, to say why it did not start.
show_logs() {
    for f in "$dir"/log/*; do
        [ -s "$f" ] || continue
        echo "--- $f" >&2
        tail -n 15 "$f" >&2
    done
}

# A TCP port nobody listens on, from /proc/net/tcp{,6} (state 0A = LISTEN).
free_port() {
    p=$1
    while [ "$p" -lt 65000 ]; do
        hex=$(printf '%04X' "$p")
        if ! cat /proc/net/tcp /proc/net/tcp6 2>/dev/null | awk -v h=":$hex" '$4 == "0A" && substr($2, length($2) - 4) == h { f = 1 } END { exit !f }'; then
            echo "$p"
            return
        fi
        p=$((p + 1))
    done
    die "no free TCP port above $1"
}

stop_pid() {
    pid=$1
    kill -0 "$pid" 2>/dev/null || return 0
    kill -TERM "$pid" 2>/dev/null
    i=0
    while kill -0 "$pid" 2>/dev/null && [ $i -lt 100 ]; do sleep 0.2; i=$((i + 1)); done
    if kill -0 "$pid" 2>/dev/null; then
        echo "cluster.sh: pid $pid did not stop on SIGTERM; SIGKILL" >&2
        kill -KILL "$pid" 2>/dev/null
    fi
}

stop() {
    # Jobs first (their slurmstepd are slurmd's children), then the daemons
    # in the reverse order of their start, each by the pid recorded for it.
    if [ -f "$dir/slurmctld.pid.started" ] && kill -0 "$(cat "$dir/slurmctld.pid.started")" 2>/dev/null; then
        SLURM_CONF=$dir/slurm.conf scancel --full --quiet --user="$(id -un)" 2>/dev/null
        i=0
        while [ $i -lt 60 ] && [ -n "$(SLURM_CONF=$dir/slurm.conf squeue -h -o %i 2>/dev/null)" ]; do
            sleep 0.5
            i=$((i + 1))
        done
    fi
    for d in slurmd slurmctld munged; do
        if [ -f "$dir/$d.pid.started" ]; then
            stop_pid "$(cat "$dir/$d.pid.started")"
            rm -f "$dir/$d.pid.started"
        fi
    done
}

[ $# -eq 2 ] || die "usage: cluster.sh start|stop DIR"
action=$1
mkdir -p "$2" || die "cannot create $2"
dir=$(cd "$2" && pwd)
case $action in
stop) stop; exit 0 ;;
start) ;;
*) die "usage: cluster.sh start|stop DIR" ;;
esac

for c in munged munge slurmctld slurmd sbatch srun scontrol scancel squeue sinfo; do
    command -v "$c" >/dev/null || PATH=$PATH:/usr/sbin:/sbin command -v "$c" >/dev/null ||
        die "$c not found: install Debian's slurm-wlm and munge (apt-get install slurm-wlm munge)"
done
PATH=$PATH:/usr/sbin:/sbin
[ -f "$dir/slurmctld.pid.started" ] && die "$dir holds a cluster already (cluster.sh stop $dir first)"

mkdir -p "$dir/state" "$dir/spool" "$dir/log" "$dir/munge" "$dir/socket" || die "cannot create the cluster's directories in $dir"
# munged wants its key private and its socket's directories open to all.
chmod 700 "$dir/munge"
chmod 755 "$dir" "$dir/socket"
# munged refuses a key that others can read, and a key of fewer than 32 bytes.
key=$dir/munge/munge.key
dd if=/dev/urandom of="$key" bs=1024 count=1 2>/dev/null || die "cannot write the munge key $key"
chmod 400 "$key"
sock=$dir/socket/munge.sock
user=$(id -un)
node=$(hostname -s 2>/dev/null || uname -n)
cpus=$(nproc)
# 90 % of the memory, so that slurmd does not find less than configured.
mem=$(awk '/^MemTotal:/ { printf "%d", $2 / 1024 * 0.9 }' /proc/meminfo)
ctld_port=$(free_port $((20000 + $$ % 20000)))
slurmd_port=$(free_port $((ctld_port + 1)))
: >"$dir/plugstack.conf"
# cred_expire sets how long a requeued job waits before it may start again
# (120 s by default); the short scheduler intervals start jobs within seconds.
cat >"$dir/slurm.conf" <<EOF
ClusterName=packbedtest
SlurmctldHost=$node(127.0.0.1)
SlurmctldPort=$ctld_port
SlurmdPort=$slurmd_port
SlurmUser=$user
SlurmdUser=$user
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$sock,cred_expire=5
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/log/slurmctld.log
SlurmdLogFile=$dir/log/slurmd.log
PlugStackConfig=$dir/plugstack.conf
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
MpiDefault=none
MailProg=/bin/true
SchedulerType=sched/backfill
SchedulerParameters=sched_interval=1,bf_interval=1
SelectType=select/cons_tres
SelectTypeParameters=CR_Core_Memory
ReturnToService=2
KillWait=30
NodeName=$node NodeAddr=127.0.0.1 CPUs=$cpus RealMemory=$mem State=UNKNOWN
PartitionName=test Nodes=$node Default=YES MaxTime=INFINITE State=UP
EOF
export SLURM_CONF="$dir/slurm.conf"

munged --foreground --socket="$sock" --key-file="$key" --pid-file="$dir/munge/munged.pid" \
    --seed-file="$dir/munge/munged.seed" --log-file="$dir/log/munged.log" \
    >"$dir/log/munged.out" 2>&1 </dev/null &
echo $! >"$dir/munged.pid.started"
i=0
until munge --socket="$sock" -n 2>/dev/null | unmunge --socket="$sock" >/dev/null 2>&1; do
    i=$((i + 1))
    if [ $i -gt 50 ] || ! kill -0 "$(cat "$dir/munged.pid.started")" 2>/dev/null; then
        show_logs
        stop
        die "munged did not start (logs above, in $dir/log)"
    fi
    sleep 0.2
done

slurmctld -D -i >"$dir/log/slurmctld.out" 2>&1 </dev/null &
echo $! >"$dir/slurmctld.pid.started"
slurmd -D -N "$node" >"$dir/log/slurmd.out" 2>&1 </dev/null &
echo $! >"$dir/slurmd.pid.started"
i=0
until [ "$(sinfo -h -n "$node" -o %T 2>/dev/null)" = idle ]; do
    i=$((i + 1))
    for d in slurmctld slurmd; do
        if ! kill -0 "$(cat "$dir/$d.pid.started")" 2>/dev/null; then
            show_logs
            stop
            die "$d exited at start (logs above, in $dir/log)"
        fi
    done
    if [ $i -gt 120 ]; then
        show_logs
        stop
        die "the node $node did not become idle within 60 s (logs above, in $dir/log)"
    fi
    sleep 0.5
done
echo "cluster.sh: Slurm $(sinfo --version | awk '{ print $2 }') up: node $node, $cpus CPUs, $mem MB, controller on 127.0.0.1:$ctld_port; SLURM_CONF=$SLURM_CONF"
