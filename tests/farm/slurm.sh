#!/usr/bin/env bash
# End-to-end render-farm test under a real Slurm (issue 22): starts a private single-node
# Slurm (munged, slurmctld, slurmd from Debian 12's packages, installed by tools/setup.sh;
# this script installs nothing), submits tools/farm/slurm_array.sh as an array job over
# scene/examples/bounce.json, SIGKILLs one task's octray in the middle of a frame, requeues
# that task, waits for the job, and checks the frames against a plain local render.
#
#   tests/farm/slurm.sh path/to/octray
#
# Everything (munge key and socket, slurm.conf, state, spool, logs, the job's output)
# lives in one mktemp folder; nothing under /etc, /run or /var is touched. The daemons
# run in their foreground modes as children of this script, on ports of its own
# (OCTRAY_SLURM_PORT, default derived from this script's PID, and the next one; it refuses
# to start when either is taken), and are stopped by PID, with the folder removed, on any
# exit: pass, fail, or SIGTERM/SIGINT (as `timeout` sends). Every wait is bounded. On
# failure it says why and prints the tails of the daemons' and tasks' logs. Needs root
# (slurmd starts jobs as the submitting user and munged's key must be root's).
set -euo pipefail

if [[ $# -ne 1 ]]; then
    echo "usage: $0 path/to/octray" >&2
    exit 2
fi
octray=$(realpath "$1")
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
scene=$repo/scene/examples/bounce.json
job_script=$repo/tools/farm/slurm_array.sh
frames=0-11       # 12 frames of the 48
tasks=3           # array 0-2 on two CPUs: two run at once, the third waits
kill_task=1       # the task whose octray is killed mid-frame and requeued
size=(--width 64 --height 36 --spp 4096)  # ~2.5 s a frame on one thread: a wide window to kill one mid-frame

fail() {
    echo "tests/farm/slurm.sh: FAIL: $*" >&2
    exit 1
}

[[ -x $octray ]] || fail "$1 is not an executable octray"
[[ -f $scene ]] || fail "no scene $scene"
[[ $(id -u) -eq 0 ]] || fail "must run as root (munged's key and slurmd's job launch need it)"
for tool in munged mungekey slurmctld slurmd sbatch squeue sinfo scontrol scancel; do
    command -v "$tool" >/dev/null 2>&1 ||
        fail "$tool not found: install slurmctld slurmd slurm-client munge (tools/setup.sh does)"
done

tmp=$(mktemp -d /tmp/octray-slurm.XXXXXX)
# Daemons and jobs run as root but slurmstepd and munge clients must traverse it.
chmod 755 "$tmp"
mkdir -p "$tmp"/{munge,state,spool,log,work,out,ref}
conf=$tmp/slurm.conf
export SLURM_CONF=$conf
pids=()        # daemons this script started, in start order
names=()
job=

# Prints the last lines of every log this run wrote.
show_logs() {
    local f
    for f in "$tmp"/log/* "$tmp"/work/*.log; do
        [[ -f $f ]] || continue
        # A daemon's .out (its stderr) repeats its .log when it has one.
        [[ $f == *.out && -s ${f%.out}.log ]] && continue
        echo "----- tail of ${f#"$tmp"/} -----" >&2
        tail -n 25 "$f" >&2
    done
}

# The processes of this run that are not the daemons: the job's shells, octray and
# slurmstepd hold files in $tmp open, or run in it, or carry our SLURM_CONF.
stray_pids() {
    local dir p
    for dir in /proc/[0-9]*; do
        p=${dir#/proc/}
        [[ $p == "$$" ]] && continue
        if grep -qsF -- "SLURM_CONF=$conf" "$dir/environ" ||
            [[ $(readlink "$dir/cwd" 2>/dev/null) == "$tmp"* ]] ||
            find "$dir/fd" -maxdepth 1 -lname "$tmp/*" 2>/dev/null | grep -q .; then
            echo "$p"
        fi
    done
}

stop_pid() {  # PID NAME: SIGTERM, up to 10 s, then SIGKILL
    local pid=$1 i
    kill -TERM "$pid" 2>/dev/null || return 0
    for ((i = 0; i < 100; i++)); do
        kill -0 "$pid" 2>/dev/null || break
        sleep 0.1
    done
    if kill -0 "$pid" 2>/dev/null; then
        echo "tests/farm/slurm.sh: $2 (pid $pid) ignored SIGTERM for 10 s: SIGKILL" >&2
        kill -KILL "$pid" 2>/dev/null || true
    fi
    wait "$pid" 2>/dev/null || true
}

cleanup() {
    local status=$? i p left
    trap - EXIT INT TERM
    set +e
    if [[ $status -eq 143 || $status -eq 130 ]]; then
        echo "tests/farm/slurm.sh: FAIL: interrupted by a signal (a timeout?); stopping the daemons" >&2
    fi
    if [[ $status -ne 0 ]]; then
        show_logs
    fi
    if [[ -n $job ]]; then
        scancel "$job" >/dev/null 2>&1
        for ((i = 0; i < 50; i++)); do
            [[ -z $(squeue -h -j "$job" -t running,completing,pending 2>/dev/null) ]] && break
            sleep 0.2
        done
    fi
    for ((i = ${#pids[@]} - 1; i >= 0; i--)); do   # slurmd, slurmctld, then munged
        stop_pid "${pids[i]}" "${names[i]}"
    done
    # Anything of this run still alive (a slurmstepd or octray the daemons left behind).
    left=$(stray_pids)
    for p in $left; do
        echo "tests/farm/slurm.sh: killing leftover pid $p: $(tr '\0' ' ' <"/proc/$p/cmdline" 2>/dev/null)" >&2
        kill -KILL "$p" 2>/dev/null
    done
    rm -rf "$tmp"
    exit "$status"
}
trap cleanup EXIT
trap 'exit 143' TERM
trap 'exit 130' INT

# ---- ports: our own, refused when taken ------------------------------------------------
port_taken() {  # PORT: listening on this machine (TCP, any address)?
    local hex
    printf -v hex '%04X' "$1"
    grep -q ":$hex 00000000:0000 0A" /proc/net/tcp /proc/net/tcp6 2>/dev/null
}
# Below Linux's ephemeral range (32768-60999), so that no outgoing connection holds it.
ctld_port=${OCTRAY_SLURM_PORT:-$((20000 + ($$ % 6000) * 2))}
slurmd_port=$((ctld_port + 1))
for port in "$ctld_port" "$slurmd_port"; do
    if port_taken "$port"; then
        fail "port $port is already in use (another Slurm or test run?); refusing to start." \
            "Set OCTRAY_SLURM_PORT to a free pair N, N+1"
    fi
done

# ---- munge --------------------------------------------------------------------------------
mungekey --create --keyfile="$tmp/munge/munge.key" ||
    fail "mungekey could not create a key"
chmod 600 "$tmp/munge/munge.key"
chmod 755 "$tmp/munge"
socket=$tmp/munge/munge.socket.2
munged -F --socket="$socket" --key-file="$tmp/munge/munge.key" \
    --pid-file="$tmp/munge/munged.pid" --seed-file="$tmp/munge/munged.seed" \
    --log-file="$tmp/log/munged.log" >>"$tmp/log/munged.out" 2>&1 &
pids+=($!)
names+=(munged)

# Waits up to SECONDS for COMMAND to succeed; otherwise fails with MESSAGE.
wait_for() {
    local seconds=$1 message=$2 i
    shift 2
    for ((i = 0; i < seconds * 5; i++)); do
        "$@" && return 0
        sleep 0.2
    done
    fail "$message (waited $seconds s)"
}
daemons_alive() {
    local i
    for i in "${!pids[@]}"; do
        kill -0 "${pids[i]}" 2>/dev/null || fail "${names[i]} (pid ${pids[i]}) exited; see its log below"
    done
}
wait_for 10 "munged did not create its socket $socket" test -S "$socket"
daemons_alive

# ---- slurm.conf ---------------------------------------------------------------------------
# The node as slurmd sees it (NodeName, CPUs, sockets, cores, threads, RealMemory).
node_line=$(slurmd -C | head -n 1) || fail "slurmd -C failed"
node=$(sed -n 's/^NodeName=\([^ ]*\).*/\1/p' <<<"$node_line")
[[ -n $node ]] || fail "cannot read the node name from slurmd -C: $node_line"
cpus=$(sed -n 's/.* CPUs=\([0-9]*\).*/\1/p' <<<"$node_line")
cat >"$conf" <<EOF
# Generated by tests/farm/slurm.sh: a private single-node cluster in $tmp.
ClusterName=octraytest
SlurmctldHost=$node(127.0.0.1)
SlurmctldPort=$ctld_port
SlurmdPort=$slurmd_port
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=$socket,cred_expire=5
CredType=cred/munge
StateSaveLocation=$tmp/state
SlurmdSpoolDir=$tmp/spool
SlurmctldPidFile=$tmp/slurmctld.pid
SlurmdPidFile=$tmp/slurmd.pid
SlurmctldLogFile=$tmp/log/slurmctld.log
SlurmdLogFile=$tmp/log/slurmd.log
SlurmctldDebug=info
SlurmdDebug=info
ProctrackType=proctrack/pgid
TaskPlugin=task/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
MpiDefault=none
ReturnToService=2
MailProg=/bin/true
JobCompType=jobcomp/filetxt
JobCompLoc=$tmp/log/jobcomp.txt
${node_line/NodeName=$node/NodeName=$node NodeAddr=127.0.0.1} State=UNKNOWN
PartitionName=octray Nodes=$node Default=YES MaxTime=INFINITE State=UP
EOF

slurmctld -D -f "$conf" >>"$tmp/log/slurmctld.out" 2>&1 &
pids+=($!)
names+=(slurmctld)
slurmd -D -f "$conf" -N "$node" >>"$tmp/log/slurmd.out" 2>&1 &
pids+=($!)
names+=(slurmd)

node_idle() {
    daemons_alive
    [[ $(sinfo -h -n "$node" -o %T 2>/dev/null) == idle ]]
}
start=$SECONDS
wait_for 30 "node $node did not become idle" node_idle
echo "slurm: munged, slurmctld, slurmd up (pids ${pids[*]}), node $node idle with $cpus CPUs" \
    "after $((SECONDS - start)) s; ports $ctld_port/$slurmd_port"

# ---- 1. the array job ---------------------------------------------------------------------
out=$tmp/out
job=$(cd "$tmp/work" && OCTRAY=$octray sbatch --parsable --array="0-$((tasks - 1))" \
    --cpus-per-task=1 --time=10 --output="$tmp/work/octray-%A_%a.log" \
    "$job_script" "$scene" "$out" --frames "$frames" "${size[@]}") ||
    fail "sbatch refused the job"
job=${job%%;*}
echo "slurm: submitted array job $job (tasks 0-$((tasks - 1)), frames $frames)"

task_state() {  # TASK: its state (RUNNING, COMPLETED, ...)
    squeue -h -t all -j "${job}_$1" -o %T 2>/dev/null | head -n 1
}
log_of() { echo "$tmp/work/octray-${job}_$1.log"; }

# ---- 2. kill task $kill_task mid-frame, requeue it ----------------------------------------
# Mid-frame: it has finished one frame (so it is in its frame loop) and holds an empty
# placeholder for the next.
killable() {
    daemons_alive
    [[ $(task_state "$kill_task") == RUNNING ]] &&
        grep -q ' rendered\|Mrays/s' "$(log_of "$kill_task")" 2>/dev/null
}
wait_for 60 "task $kill_task never ran a frame" killable
# The task's octray: the process running $octray whose environment is that task's.
# Candidates by name (pgrep), each checked by its binary and environment.
victim=
for p in $(pgrep -x "$(basename "$octray" | cut -c 1-15)" || true); do
    dir=/proc/$p
    [[ $(readlink "$dir/exe" 2>/dev/null) == "$octray" ]] || continue
    env=$(tr '\0' '\n' <"$dir/environ" 2>/dev/null) || continue
    if grep -qx "SLURM_CONF=$conf" <<<"$env" &&
        grep -qx "SLURM_ARRAY_JOB_ID=$job" <<<"$env" &&
        grep -qx "SLURM_ARRAY_TASK_ID=$kill_task" <<<"$env"; then
        victim=${dir#/proc/}
    fi
done
[[ -n $victim ]] || fail "no octray process of task ${job}_$kill_task found in /proc"
kill -KILL "$victim"
# The killed task's frames are positions kill_task, kill_task + tasks, ... of 0-11.
held=()
for ((f = kill_task; f <= 11; f += tasks)); do
    name=$(printf 'bounce.%04d.exr' "$f")
    [[ -f $out/$name && ! -s $out/$name ]] && held+=("$name")
done
echo "slurm: SIGKILLed octray pid $victim of task ${job}_$kill_task; its empty placeholder(s)" \
    "left behind: ${held[*]:-none}"
[[ ${#held[@]} -gt 0 ]] || fail "task $kill_task was not in the middle of a frame when killed"

task_ended() {
    local s
    s=$(task_state "$kill_task")
    [[ $s == FAILED || $s == CANCELLED || $s == COMPLETED ]]
}
wait_for 30 "task ${job}_$kill_task did not end after SIGKILL" task_ended
echo "slurm: task ${job}_$kill_task ended $(task_state "$kill_task"); requeueing it"
scontrol requeue "${job}_$kill_task" || fail "scontrol requeue ${job}_$kill_task failed"
# A requeued task waits cred_expire + 1 s (BeginTime); start it as soon as it can.
task_pending() { [[ $(task_state "$kill_task") == PENDING ]]; }
wait_for 30 "task ${job}_$kill_task did not become PENDING after the requeue" task_pending
scontrol update JobId="${job}_$kill_task" StartTime=now ||
    fail "scontrol update StartTime=now failed"

# ---- wait for the job --------------------------------------------------------------------
job_done() {
    local states
    daemons_alive
    states=$(squeue -h -t all -j "$job" -o %T 2>/dev/null) || return 1
    [[ -n $states ]] || return 1
    if grep -qvx 'COMPLETED' <<<"$states"; then
        if grep -qE 'FAILED|CANCELLED|TIMEOUT|NODE_FAIL|OUT_OF_MEMORY' <<<"$states"; then
            fail "a task of job $job ended badly: $(squeue -h -t all -j "$job" -o '%i %T %r' | tr '\n' ';')"
        fi
        return 1
    fi
    [[ $(wc -l <<<"$states") -eq $tasks ]]
}
wait_for 180 "job $job did not complete" job_done
echo "slurm: job $job completed at $((SECONDS - start)) s after the daemons started"

# ---- 3. checks -----------------------------------------------------------------------------
expected=()
for ((f = 0; f <= 11; f++)); do
    expected+=("$(printf 'bounce.%04d.exr' "$f")")
done
mapfile -t present < <(cd "$out" && find . -mindepth 1 -printf '%P\n' | sort)
if [[ "${present[*]}" != "${expected[*]}" ]]; then
    fail "the output holds [${present[*]}], expected exactly [${expected[*]}]" \
        "(no temporaries, nothing else)"
fi
empties=$(find "$out" -type f -empty -printf '%P ')
[[ -z $empties ]] || fail "empty placeholder(s) left: $empties"

"$octray" render "$scene" --frames "$frames" "${size[@]}" --progress none \
    -o "$tmp/ref/{scene}.####.exr" >"$tmp/log/local-render.log" 2>&1 ||
    fail "the local reference render failed: $(cat "$tmp/log/local-render.log")"
for name in "${expected[@]}"; do
    "$octray" compare "$tmp/ref/$name" "$out/$name" --fail 0 --warn 0 >"$tmp/log/compare.log" 2>&1 ||
        fail "$name differs from the local render: $(cat "$tmp/log/compare.log")"
done
echo "check: ${#expected[@]} frames, each once, no temporary or empty file, pixels equal to a local render"

# The logs: how many frames each task rendered (summed over its attempts), and the
# requeue. A frame line ("frame 2/4  bounce frame 4  -> path  trace 1.2 s  9.7 Mrays/s
# write 0.004 s") is printed once per frame rendered (a skipped frame's line has no rate);
# the killed attempt prints no summary.
total=0
for ((t = 0; t < tasks; t++)); do
    log=$(log_of "$t")
    [[ -f $log ]] || fail "task $t wrote no log $log"
    n=$(grep -E -c '^frame [0-9]+/[0-9]+ .* -> .* Mrays/s' "$log" || true)
    attempts=$(grep -c '^octray task .* attempt ' "$log" || true)
    summary=$(grep -E '^(done|interrupted): ' "$log" | tail -n 1)
    echo "task $t: $attempts attempt(s), $n frame(s) rendered; last summary: ${summary:-none}"
    total=$((total + n))
    if [[ $t -eq $kill_task ]]; then
        [[ $attempts -eq 2 ]] || fail "task $t's log shows $attempts attempts, expected 2 (requeued once)"
        grep -q 'SLURM_RESTART_COUNT=1' "$log" || fail "task $t's log does not show the requeue"
        for name in "${held[@]}"; do
            grep -q "released stale placeholder: .*/$name\$" "$log" ||
                fail "task $t's retry did not say it released the placeholder $name"
        done
    else
        [[ $attempts -eq 1 ]] || fail "task $t's log shows $attempts attempts, expected 1"
    fi
    [[ -n $summary ]] || fail "task $t's log has no summary line"
done
[[ $total -eq ${#expected[@]} ]] ||
    fail "the tasks rendered $total frames in all, expected ${#expected[@]} (each exactly once)"
restarts=$(scontrol show job "${job}_$kill_task" | grep -o 'Restarts=[0-9]*')
[[ $restarts == Restarts=1 ]] || fail "scontrol shows $restarts for task $kill_task, expected Restarts=1"
echo "check: the logs account for every frame once; task $kill_task was requeued ($restarts)"
echo "task $kill_task's log (both attempts):"
grep -v '^Progress: ' "$(log_of "$kill_task")" | sed 's/^/  | /'
echo "tests/farm/slurm.sh: passed in $SECONDS s"
