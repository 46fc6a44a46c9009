#!/usr/bin/env bash
# slurm_one_node.sh WORKDIR N JOB_SCRIPT
#
# Run JOB_SCRIPT as a Slurm job array of N tasks (ids 0..N-1) on a private,
# throw-away, one-node Slurm cluster (slurmctld + slurmd on this machine).
# Everything the cluster writes (config, state, spool, logs, pid files) lives
# in WORKDIR/slurm; task output goes to WORKDIR/array_<id>.out.
#
# Exit status:
#   0   every array task exited 0
#   1   the job failed: a task exited non-zero / was killed / the job timed
#       out, or sbatch refused the script.  The failed tasks' output is shown.
#   2   usage error
#   77  the cluster could not be started (ctest SKIP_RETURN_CODE); the
#       reason and the tail of the daemon logs are printed as "SKIP: ..."
#
# Environment knobs:
#   SLURM_HARNESS_TIMEOUT        seconds to wait for the array job (600)
#   SLURM_HARNESS_START_TIMEOUT  seconds to wait for the node to be idle (60)
#   SLURM_HARNESS_KEEP_LOGS=0    delete WORKDIR/slurm on success (default 1)
#   SLURM_HARNESS_PORTS="C D"    slurmctld/slurmd ports for the first attempt
#                                (testing aid; default: random free ports)
#
# Needs: slurmctld/slurmd/sbatch/sinfo/squeue/scontrol/scancel (Slurm 22.05
# was used to write this), coreutils `timeout`, util-linux `setsid`.  Run as
# root (SlurmUser=root).  No munge daemon: AuthType=auth/none, CredType=cred/none.

set -u
set -o pipefail

PATH="$PATH:/usr/sbin:/sbin"

usage() {
    echo "usage: $0 WORKDIR N JOB_SCRIPT" >&2
    exit 2
}

[ $# -eq 3 ] || usage
case "$2" in '' | *[!0-9]*) echo "N must be a positive integer, got '$2'" >&2; usage ;; esac
N=$((10#$2))
[ "$N" -ge 1 ] || { echo "N must be >= 1" >&2; usage; }
[ -f "$3" ] && [ -r "$3" ] || { echo "JOB_SCRIPT '$3' is not a readable file" >&2; usage; }

mkdir -p -- "$1" || { echo "cannot create WORKDIR '$1'" >&2; exit 2; }
WORKDIR=$(cd -- "$1" && pwd -P) || exit 2
JOB_SCRIPT=$(cd -- "$(dirname -- "$3")" && pwd -P)/$(basename -- "$3")
case "$WORKDIR" in
    *[[:space:]#=]*) echo "WORKDIR '$WORKDIR' must not contain blanks, '#' or '=' (slurm.conf syntax)" >&2; exit 2 ;;
esac

JOB_TIMEOUT=${SLURM_HARNESS_TIMEOUT:-600}
START_TIMEOUT=${SLURM_HARNESS_START_TIMEOUT:-60}
KEEP_LOGS=${SLURM_HARNESS_KEEP_LOGS:-1}
FIXED_PORTS=${SLURM_HARNESS_PORTS:-}
case "$JOB_TIMEOUT" in '' | *[!0-9]*) echo "SLURM_HARNESS_TIMEOUT must be an integer" >&2; exit 2 ;; esac
case "$START_TIMEOUT" in '' | *[!0-9]*) echo "SLURM_HARNESS_START_TIMEOUT must be an integer" >&2; exit 2 ;; esac

# Variables from an enclosing Slurm job or the user's shell (SBATCH_PARTITION,
# SLURM_JOB_ID, SLURM_CONF, ...) would change what our commands do: drop them.
for _v in $(compgen -e); do
    case "$_v" in
        SLURM_* | SBATCH_* | SQUEUE_* | SINFO_* | SCONTROL_* | SCANCEL_* | SALLOC_* | SRUN_*) unset "$_v" ;;
    esac
done
unset _v

D="$WORKDIR/slurm"                 # everything the cluster owns
CONF="$D/slurm.conf"
LOGDIR="$D/log"
HOST=$(hostname -s 2>/dev/null || hostname)
# Every process we start (daemons, sbatch, hence slurmstepd and the job tasks)
# carries this variable; the clean-up finds strays by it in /proc/*/environ.
TAG="slurm-harness-$$-$(date +%s%N)-$RANDOM"

CTLD_PID=""
SLURMD_PID=""
SBATCH_PID=""
WATCHDOG_PID=""
CLEANED=0
JOB_FINISHED=0

T_START=$(date +%s.%N)
log() { echo "slurm_one_node [$(awk -v a="$T_START" -v b="$(date +%s.%N)" 'BEGIN{printf "%.1f", b-a}')s]: $*" >&2; }

now() { date +%s; }

# Run a Slurm client command against our cluster only, bounded in time.
sl() { SLURM_CONF="$CONF" timeout -k 5 30 "$@"; }
sl_quick() { SLURM_CONF="$CONF" timeout -k 2 5 "$@"; }

STARTED=0 # set once the daemons have been launched (logs are ours)
tail_logs() {
    local d f
    [ "$STARTED" = 1 ] || return 0
    for d in slurmctld slurmd; do
        f="$LOGDIR/$d.log"
        [ -s "$f" ] || f="$LOGDIR/$d.stdout" # errors before the log file opens
        [ -s "$f" ] || continue
        echo "---- last lines of $f ----"
        # the PMIx plugin noise is harmless (MpiDefault=none)
        grep -vE 'pmix|MPI: Cannot create context' "$f" | tail -n 20
    done
}

# Processes of this cluster: those whose environment carries $TAG (daemons,
# sbatch, job tasks) and those holding a file under $D open (slurmstepd starts
# with an empty environment but keeps slurmd.log open).  Never ourselves.
tagged_pids() {
    local self=${BASHPID:-$$}
    {
        grep -lzxF "SLURM_HARNESS_TAG=$TAG" /proc/[0-9]*/environ
        find /proc/[0-9]*/fd -maxdepth 1 -lname "$D/*"
    } 2>/dev/null | cut -d/ -f3 | sort -un |
        grep -vxE "$$|$self${WATCHDOG_PID:+|$WATCHDOG_PID}"
}

alive() { [ -n "$1" ] && kill -0 "$1" 2>/dev/null; }

# wait up to $2 seconds for pid $1 to exit (it may or may not be our child)
wait_gone() {
    local pid=$1 deadline=$(($(now) + $2))
    while alive "$pid"; do
        [ "$(now)" -ge "$deadline" ] && return 1
        sleep 0.2
    done
    return 0
}

STOP_GRACE=20 # seconds between SIGTERM and SIGKILL for a daemon
stop_daemon() { # pid pidfile
    local pid=$1 pf=$2
    if [ -z "$pid" ] && [ -s "$pf" ]; then pid=$(cat "$pf" 2>/dev/null); fi
    alive "$pid" || return 0
    kill -TERM "$pid" 2>/dev/null
    if ! wait_gone "$pid" "$STOP_GRACE"; then
        log "$(basename "$pf" .pid) (pid $pid) ignored SIGTERM, killing it"
        kill -KILL "$pid" 2>/dev/null
        wait_gone "$pid" 5
    fi
    wait "$pid" 2>/dev/null # reap if it is our child
    return 0
}

cleanup() {
    [ "$CLEANED" = 1 ] && return
    CLEANED=1
    trap '' INT TERM HUP
    if alive "$SBATCH_PID"; then
        kill -TERM "$SBATCH_PID" 2>/dev/null
        wait_gone "$SBATCH_PID" 5 || kill -KILL "$SBATCH_PID" 2>/dev/null
        wait "$SBATCH_PID" 2>/dev/null
    fi
    # Cancel whatever still runs while the daemons can still do it cleanly
    # (not needed when sbatch --wait saw the job finish).
    if [ "$JOB_FINISHED" = 0 ] && alive "$CTLD_PID" &&
        [ -n "$(sl squeue -h -t PENDING,RUNNING,SUSPENDED,COMPLETING,CONFIGURING -o %i 2>/dev/null)" ]; then
        sl scancel --full --partition=harness >/dev/null 2>&1
        local deadline=$(($(now) + 20))
        while [ -n "$(sl squeue -h -t RUNNING,COMPLETING,PENDING -o %i 2>/dev/null)" ] &&
            [ "$(now)" -lt "$deadline" ]; do
            sleep 0.5
        done
    fi
    if [ "$STARTED" = 1 ]; then
        log "stopping daemons"
        stop_daemon "$SLURMD_PID" "$D/run/slurmd.pid"
        stop_daemon "$CTLD_PID" "$D/run/slurmctld.pid"
        log "daemons gone"
    fi
    # Anything left that carries our tag (slurmstepd, job processes): kill it.
    local round pids
    for round in 1 2 3 4 5; do
        pids=$(tagged_pids)
        [ -z "$pids" ] && break
        if [ "$round" = 1 ]; then
            log "killing leftover processes: $(echo $pids)"
            kill -TERM $pids 2>/dev/null
            sleep 1
        else
            kill -KILL $pids 2>/dev/null
            sleep 0.2
        fi
    done
    if [ -n "$WATCHDOG_PID" ]; then
        kill -TERM -- "-$WATCHDOG_PID" 2>/dev/null || kill -TERM "$WATCHDOG_PID" 2>/dev/null
        wait "$WATCHDOG_PID" 2>/dev/null
    fi
    wait 2>/dev/null
}

on_exit() {
    local rc=$?
    cleanup
    log "done, exit status $rc"
    exit "$rc"
}
trap on_exit EXIT
trap 'log "interrupted"; exit 130' INT
trap 'log "terminated"; exit 143' TERM
trap 'log "hangup"; exit 129' HUP

skip() {
    echo "SKIP: $*"
    tail_logs
    STOP_GRACE=3 # a daemon that failed to start may hang on SIGTERM
    exit 77
}

# ---------------------------------------------------------------- checks
for b in slurmctld slurmd sbatch sinfo squeue scontrol scancel; do
    command -v "$b" >/dev/null 2>&1 || skip "Slurm binary '$b' not found in PATH ($PATH)"
done
for b in timeout setsid; do
    command -v "$b" >/dev/null 2>&1 || skip "required tool '$b' not found"
done
[ "$(id -u)" = 0 ] || skip "must run as root (SlurmUser=root, slurmd needs root); uid is $(id -u)"
[ -n "$HOST" ] || skip "cannot determine the short host name"

# slurmd puts unix sockets "<spool>/<node>_<job>.<step>" in its spool dir;
# sun_path holds 107 characters.
if [ $((${#D} + 6 + ${#HOST} + 24)) -gt 107 ]; then
    skip "WORKDIR path too long for slurmd's unix sockets (sun_path is 108 bytes): $D/spool"
fi

# Wipe the cluster of a previous run and stale task outputs.
rm -rf -- "$D"
rm -f -- "$WORKDIR"/array_*.out
mkdir -p "$D/state" "$D/spool" "$D/run" "$LOGDIR" || skip "cannot create directories under $D"
: >"$D/plugstack.conf" # keep the system's /etc/slurm/plugstack.conf out

# Watchdog: if this script dies without running its trap (SIGKILL, e.g. a
# ctest timeout), kill everything that carries our tag.  It lives in its own
# session so a process-group kill of the caller does not take it down first.
setsid bash -c '
    tail --pid="$1" -f /dev/null 2>/dev/null || while kill -0 "$1" 2>/dev/null; do sleep 1; done
    for r in 1 2 3; do
        pids=$( { grep -lzxF "SLURM_HARNESS_TAG=$2" /proc/[0-9]*/environ
                  find /proc/[0-9]*/fd -maxdepth 1 -lname "$3/*"; } 2>/dev/null |
                cut -d/ -f3 | sort -un | grep -vx "$$")
        [ -z "$pids" ] && break
        kill -KILL $pids 2>/dev/null
        sleep 1
    done
' slurm-harness-watchdog "$$" "$TAG" "$D" </dev/null >/dev/null 2>&1 &
WATCHDOG_PID=$!

# ---------------------------------------------------------------- hardware
NODE_LINE=$(SLURM_CONF="$D/none.conf" timeout 30 slurmd -C 2>"$LOGDIR/slurmd-C.err" | head -n 1)
case "$NODE_LINE" in
    NodeName=*CPUs=*RealMemory=*) ;;
    *) skip "'slurmd -C' did not report the node hardware: '$NODE_LINE' $(head -c 500 "$LOGDIR/slurmd-C.err")" ;;
esac
# keep CPUs/Boards/Sockets/Cores/Threads/RealMemory, use our own node name
NODE_HW=$(echo "$NODE_LINE" | tr ' ' '\n' | grep -E '^(CPUs|Boards|SocketsPerBoard|CoresPerSocket|ThreadsPerCore|RealMemory)=' | tr '\n' ' ')

# ---------------------------------------------------------------- ports
# Listening/used TCP ports, from /proc (no dependency on ss/netstat).
used_ports() {
    local h
    awk 'FNR > 1 && $2 ~ /:/ { split($2, a, ":"); print a[2] }' /proc/net/tcp /proc/net/tcp6 2>/dev/null |
        sort -u | while read -r h; do [ -n "$h" ] && echo $((16#$h)); done
}
# Pick a free port below the kernel's ephemeral range (so no outgoing
# connection can grab it between our check and the daemon's bind).
pick_port() {
    local lo p used i
    read -r lo _ </proc/sys/net/ipv4/ip_local_port_range 2>/dev/null || lo=32768
    [ "$lo" -gt 12000 ] || lo=32768
    used=" $(used_ports | tr '\n' ' ') $* "
    for i in $(seq 1 500); do
        p=$((10000 + (RANDOM * 32768 + RANDOM) % (lo - 10000)))
        case "$used" in *" $p "*) continue ;; esac
        echo "$p"
        return 0
    done
    return 1
}

write_conf() { # ctld_port slurmd_port
    local max_array=1001 max_jobs=10000
    [ "$N" -ge "$max_array" ] && max_array=$((N + 1))
    [ "$N" -ge $((max_jobs - 100)) ] && max_jobs=$((N + 1000))
    cat >"$CONF" <<EOF
# Generated by slurm_one_node.sh: private one-node cluster, throw-away.
ClusterName=harness
SlurmctldHost=$HOST(127.0.0.1)
SlurmctldPort=$1
SlurmdPort=$2
SlurmUser=root
SlurmdUser=root
# no munge daemon
AuthType=auth/none
CredType=cred/none
StateSaveLocation=$D/state
SlurmdSpoolDir=$D/spool
SlurmctldPidFile=$D/run/slurmctld.pid
SlurmdPidFile=$D/run/slurmd.pid
SlurmctldLogFile=$LOGDIR/slurmctld.log
SlurmdLogFile=$LOGDIR/slurmd.log
MailProg=/bin/true
SlurmctldDebug=info
SlurmdDebug=info
PlugStackConfig=$D/plugstack.conf
# no cgroups, no accounting
ProctrackType=proctrack/pgid
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
# one line per finished job/array task: our independent record of results
JobCompType=jobcomp/filetxt
JobCompLoc=$LOGDIR/jobcomp.log
SwitchType=switch/none
MpiDefault=none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
# sbatch --wait polls every 2 s only if MinJobAge < 6 (else 2, 8, 32 s ...);
# results are read from the jobcomp file, so early purging costs nothing
MinJobAge=5
# start array tasks as soon as resources free up (default delays up to 3 s)
SchedulerParameters=batch_sched_delay=0,sched_interval=5
MaxArraySize=$max_array
MaxJobCount=$max_jobs
KillWait=5
MessageTimeout=30
SlurmctldTimeout=300
SlurmdTimeout=300
InactiveLimit=0
NodeName=$HOST NodeAddr=127.0.0.1 NodeHostname=$HOST $NODE_HW State=UNKNOWN
PartitionName=harness Nodes=$HOST Default=YES MaxTime=INFINITE State=UP
EOF
}

# name of a daemon that exited or logged a fatal error (some linger for ~30 s
# after "fatal:", e.g. slurmctld when its port is taken)
failed_daemon() {
    if ! alive "$CTLD_PID" || grep -q 'fatal:' "$LOGDIR/slurmctld.log" "$LOGDIR/slurmctld.stdout" 2>/dev/null; then
        echo slurmctld
    elif ! alive "$SLURMD_PID" || grep -q 'fatal:' "$LOGDIR/slurmd.log" "$LOGDIR/slurmd.stdout" 2>/dev/null; then
        echo slurmd
    else
        return 1
    fi
}

node_state() { sl_quick sinfo -h -n "$HOST" -o %T 2>/dev/null | head -n 1; }

# Start both daemons and wait for an idle node.  Returns 0 on success, 1 on a
# port clash (worth retrying with other ports), calls skip otherwise.
start_cluster() {
    local deadline st who
    rm -rf "$D/state" "$D/spool" && mkdir -p "$D/state" "$D/spool"
    : >"$LOGDIR/slurmctld.log"
    : >"$LOGDIR/slurmd.log"
    : >"$LOGDIR/slurmctld.stdout"
    : >"$LOGDIR/slurmd.stdout"
    STARTED=1
    SLURM_CONF="$CONF" SLURM_HARNESS_TAG="$TAG" \
        slurmctld -D -c -i -f "$CONF" </dev/null >"$LOGDIR/slurmctld.stdout" 2>&1 &
    CTLD_PID=$!
    SLURM_CONF="$CONF" SLURM_HARNESS_TAG="$TAG" \
        slurmd -D -N "$HOST" -f "$CONF" </dev/null >"$LOGDIR/slurmd.stdout" 2>&1 &
    SLURMD_PID=$!

    deadline=$(($(now) + START_TIMEOUT))
    while :; do
        if who=$(failed_daemon); then
            sleep 0.5 # let the log be flushed
            if grep -qiE 'address already in use|unable to bind|error binding' \
                "$LOGDIR"/slurm*.log "$LOGDIR"/slurm*.stdout 2>/dev/null; then
                log "$who could not bind its port, retrying with other ports"
                STOP_GRACE=2
                stop_daemon "$SLURMD_PID" "$D/run/slurmd.pid"
                stop_daemon "$CTLD_PID" "$D/run/slurmctld.pid"
                CTLD_PID="" SLURMD_PID="" STOP_GRACE=20
                return 1
            fi
            local why
            why=$(grep -h 'fatal:' "$LOGDIR/$who.log" "$LOGDIR/$who.stdout" 2>/dev/null | tail -n 1)
            if [ -z "$why" ]; then
                local pid=$CTLD_PID
                [ "$who" = slurmd ] && pid=$SLURMD_PID
                wait "$pid" 2>/dev/null
                why="exited with status $?"
            fi
            skip "$who failed during start-up: $why"
        fi
        st=$(node_state)
        case "$st" in
            idle) return 0 ;;
        esac
        if [ "$(now)" -ge "$deadline" ]; then
            local hint
            case "$st" in
                "") hint="slurmctld does not answer on port $CTLD_PORT" ;;
                unknown*) hint="slurmd never registered with slurmctld" ;;
                *) hint=$(sl_quick scontrol show node "$HOST" 2>/dev/null | grep -oE '(State|Reason)=.*' | tr '\n' ' ') ;;
            esac
            skip "node '$HOST' not idle after ${START_TIMEOUT}s (SLURM_HARNESS_START_TIMEOUT): state '${st:-?}', $hint"
        fi
        sleep 0.3
    done
}

attempt=0
while :; do
    attempt=$((attempt + 1))
    if [ "$attempt" = 1 ] && [ -n "$FIXED_PORTS" ]; then
        read -r CTLD_PORT SLURMD_PORT <<<"$FIXED_PORTS"
    else
        CTLD_PORT=$(pick_port) || skip "no free TCP port found"
        SLURMD_PORT=$(pick_port "$CTLD_PORT") || skip "no free TCP port found"
    fi
    write_conf "$CTLD_PORT" "$SLURMD_PORT"
    t0=$(now)
    start_cluster && break
    [ "$attempt" -ge 3 ] && skip "daemons could not bind their ports in 3 attempts"
done
log "cluster up on ports $CTLD_PORT/$SLURMD_PORT (node $HOST: $NODE_HW) in $(($(now) - t0))s"

# ---------------------------------------------------------------- the job
T_SUBMIT=$(now)
SLURM_CONF="$CONF" SLURM_HARNESS_TAG="$TAG" \
    timeout -k 10 "$JOB_TIMEOUT" \
    sbatch --wait --parsable --array="0-$((N - 1))" --output="$WORKDIR/array_%a.out" \
    --job-name=harness "$JOB_SCRIPT" </dev/null >"$D/sbatch.out" 2>"$D/sbatch.err" &
SBATCH_PID=$!
log "sbatch --wait --array=0-$((N - 1)) $JOB_SCRIPT (timeout ${JOB_TIMEOUT}s)"
wait "$SBATCH_PID"
SBATCH_RC=$?
log "sbatch --wait returned $SBATCH_RC"
SBATCH_PID=""
JOBID=$(grep -Eo '^[0-9]+' "$D/sbatch.out" | head -n 1)

TIMED_OUT=0
# 124/137 come from `timeout` -- or from a task exiting with that status
if { [ "$SBATCH_RC" != 124 ] && [ "$SBATCH_RC" != 137 ]; } ||
    [ $(($(now) - T_SUBMIT)) -lt $((JOB_TIMEOUT - 1)) ]; then
    JOB_FINISHED=1 # sbatch ended on its own: the job is over (or never was)
else
    TIMED_OUT=1
    [ -n "$JOBID" ] || JOBID=$(sl squeue -h -o %F 2>/dev/null | head -n 1)
    echo "TIMEOUT: array job ${JOBID:-?} not finished after ${JOB_TIMEOUT}s (SLURM_HARNESS_TIMEOUT); cancelling it"
    sl squeue -h -o '%i %T %M %R' 2>/dev/null | sed 's/^/  /'
    sl scancel --partition=harness >/dev/null 2>&1
fi

if [ -z "$JOBID" ]; then
    echo "FAILED: sbatch did not submit the job (exit $SBATCH_RC):"
    cat "$D/sbatch.err"
    exit 1
fi

# Per-task results from jobcomp/filetxt: "... JobState=X ... ArrayTaskId=i
# ... ExitCode=a:b".  Give the controller a moment to write the last records.
task_results() {
    grep -E "(ArrayJobId=$JOBID |JobId=$JOBID )" "$LOGDIR/jobcomp.log" 2>/dev/null |
        sed -nE 's/.*JobState=([A-Z_]+).*ArrayTaskId=([0-9]+).*ExitCode=([0-9]+:[0-9]+).*/\2 \1 \3/p' |
        sort -n -u
}
deadline=$(($(now) + 15))
while [ "$(task_results | wc -l)" -lt "$N" ] && [ "$TIMED_OUT" = 0 ] && [ "$(now)" -lt "$deadline" ]; do
    sleep 0.3
done
declare -A RESULT=()
while read -r id st ec; do
    [ -n "$id" ] && RESULT[$id]="$st $ec"
done <<<"$(task_results)"

failed=""
for ((i = 0; i < N; i++)); do
    r=${RESULT[$i]:-}
    if [ -z "$r" ]; then
        failed="$failed $i"
        echo "task $i: no completion record (not run or not finished)"
    elif [ "$r" != "COMPLETED 0:0" ]; then
        failed="$failed $i"
        echo "task $i: state ${r% *}, exit code ${r#* } (status:signal)"
    fi
done

if [ "$SBATCH_RC" = 0 ] && [ -z "$failed" ]; then
    echo "OK: array job $JOBID, $N task(s) completed with exit code 0"
    if [ "$KEEP_LOGS" = 0 ]; then
        cleanup
        rm -rf -- "$D"
    fi
    exit 0
fi

echo "FAILED: array job $JOBID (sbatch --wait exit status $SBATCH_RC); failed task(s):${failed:- none recorded}"
[ -s "$D/sbatch.err" ] && { echo "---- sbatch stderr ----"; cat "$D/sbatch.err"; }
for i in $failed; do
    f="$WORKDIR/array_$i.out"
    echo "---- output of task $i ($f) ----"
    if [ -f "$f" ] && [ ! -s "$f" ]; then
        echo "(empty)"
    elif [ -f "$f" ]; then
        if [ "$(wc -l <"$f")" -gt 200 ]; then
            echo "[... first $(($(wc -l <"$f") - 200)) lines omitted ...]"
        fi
        tail -n 200 "$f"
    else
        echo "(no output file)"
    fi
done
exit 1
