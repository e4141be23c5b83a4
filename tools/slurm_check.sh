#!/usr/bin/env bash
# The SLURM profile on a real (one-node) SLURM cluster: install SLURM and munge with apt-get,
# start a private cluster on this host, build a few small targets through
# profiles/slurm (snakemake-executor-plugin-slurm), check that every job went through SLURM,
# build the same targets locally and check that the results are identical.
#
#     tools/slurm_check.sh          # with the project's venv active (or .venv beside it)
#
# Needs root and apt-get (Debian 12: SLURM 22.05, munge 0.5.15). Without them, or with
# MOSYS_SKIP_SLURM=1, or when apt-get fails, or when this host already has a SLURM
# configuration of its own, it prints "skipped: <reason>" and exits 0. Otherwise it exits 0 only
# when everything passed, and non-zero with the daemons' and the builds' log tails otherwise.
# MOSYS_SLURM_CHECK_KEEP=1 keeps the temporary directory (the cluster is stopped all the same).
#
# The cluster: munged on a private socket and key, slurmctld and slurmd as root in the
# foreground, all of their files in one temporary directory; no accounting, no cgroups
# (proctrack/linuxproc, task/none). /etc/slurm/slurm.conf is made a link to the generated file
# for the time of the check: the plugin's job step drops SLURM_CONF before its srun.
set -euo pipefail

ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
PARTITION=mosys_check
TARGETS=(
    results/controllers/pendulum/A.h5
    results/plots/pendulum/A_portrait.png
    results/bsr/starman_shuffle/seed1.h5
    results/bsr/starman_shuffle/seed2.h5
)
SLURM_RULES=(dp_controller bsr_search)  # the check fails unless these at least run as SLURM jobs
CLUSTER_TIMEOUT=${MOSYS_SLURM_CLUSTER_TIMEOUT:-90}   # s for the node to become idle
BUILD_TIMEOUT=${MOSYS_SLURM_BUILD_TIMEOUT:-900}      # s for each build
PLUGIN_REQUIREMENT='snakemake-executor-plugin-slurm>=2.8,<3'
SYSTEM_CONF=/etc/slurm/slurm.conf

say() { printf 'slurm_check: %s\n' "$*"; }
skip() {
    rm -f "${APT_LOG:-}"
    SKIPPED=1
    say "skipped: $*"
    exit 0
}
fail() { say "FAILED: $*" >&2; exit 1; }  # the EXIT trap (once set) cleans up
now() { printf '%s' "$EPOCHREALTIME"; }
TIMES=()
phase_done() {  # name start
    local seconds
    seconds=$(awk -v a="$2" -v b="$(now)" 'BEGIN { printf "%.1f", b - a }')
    TIMES+=("$1: ${seconds} s")
    say "$1 took ${seconds} s"
}

# --- can SLURM run here? ---------------------------------------------------------------------
CHECK_START=$(now)
[[ ${MOSYS_SKIP_SLURM:-0} != 1 ]] || skip "MOSYS_SKIP_SLURM=1"
[[ $(id -u) == 0 ]] || skip "not root (installing SLURM and running its daemons needs root)"
command -v apt-get >/dev/null || skip "no apt-get (SLURM is installed from Debian's packages)"
if [[ -e $SYSTEM_CONF || -L $SYSTEM_CONF ]]; then
    if [[ -L $SYSTEM_CONF && $(readlink "$SYSTEM_CONF") == */mosys-slurm.*/slurm.conf ]]; then
        stale_link=1  # left by a check that was killed; replaced below, under the lock
    else
        skip "$SYSTEM_CONF exists: this host has a SLURM configuration of its own; not touching it"
    fi
fi

if [[ -n ${VIRTUAL_ENV:-} ]]; then
    PYTHON=$VIRTUAL_ENV/bin/python
elif [[ -x $ROOT/.venv/bin/python ]]; then
    PYTHON=$ROOT/.venv/bin/python
else
    fail "no venv: activate the project's venv (pip install -e .) first"
fi
VENV_BIN=$(dirname "$PYTHON")
export PATH="$VENV_BIN:$PATH"  # the jobs (sbatch --export=ALL) find mosys and this python
"$PYTHON" -c 'import mosys, snakemake, h5py' 2>/dev/null ||
    fail "$PYTHON cannot import mosys, snakemake and h5py: pip install -e . first"

LOCK=/tmp/mosys-slurm-check.lock
exec 9>"$LOCK"
flock -n 9 || { LOCK=""; fail "another tools/slurm_check.sh is running on this host"; }

WORK=""        # the temporary directory: the cluster's files and the two builds
PIDS=()          # the daemons, stopped in reverse order
LINKED=0
FAILED_PHASE=""

print_tail() {  # file [lines]
    [[ -s $1 ]] || return 0
    printf '\n----- %s (last %s lines) -----\n' "${1#"$WORK"/}" "${2:-40}" >&2
    tail -n "${2:-40}" "$1" >&2
}

cleanup() {
    local rc=$?
    trap - EXIT
    set +e
    if ((rc != 0)) && [[ -n $WORK ]]; then
        say "failure in phase '${FAILED_PHASE:-?}'; log tails follow" >&2
        print_tail "$WORK/slurm-build.log" 60
        print_tail "$WORK/local-build.log" 40
        for log in "$WORK"/slurm/.snakemake/slurm_logs/*/*/*.log \
            "$WORK"/slurm/.snakemake/slurm_logs/*/*.log; do
            [[ -f $log ]] && print_tail "$log" 20
        done
        print_tail "$WORK/slurmctld.log" 40
        print_tail "$WORK/slurmd.log" 40
        print_tail "$WORK/munge/munged.log" 20
        print_tail "$WORK/munge/munged.out" 20
    fi
    if [[ -n ${SLURM_UP:-} ]]; then  # jobs left over from a failed build
        mapfile -t leftover < <(squeue -h -o %i 2>/dev/null)
        if ((${#leftover[@]})); then
            scancel "${leftover[@]}" 2>/dev/null
            for _ in $(seq 30); do
                [[ -z $(squeue -h -t PD,R,CG -o %i 2>/dev/null) ]] && break
                sleep 1
            done
        fi
    fi
    local i pid
    for ((i = ${#PIDS[@]} - 1; i >= 0; i--)); do
        pid=${PIDS[i]}
        kill -TERM "$pid" 2>/dev/null || continue
        for _ in $(seq 50); do kill -0 "$pid" 2>/dev/null || break; sleep 0.2; done
        kill -KILL "$pid" 2>/dev/null
        wait "$pid" 2>/dev/null
    done
    if ((LINKED)) && [[ $(readlink "$SYSTEM_CONF" 2>/dev/null) == "$WORK/slurm.conf" ]]; then
        rm -f "$SYSTEM_CONF"
    fi
    if ((${#TIMES[@]})); then
        say "times: $(IFS=';'; printf '%s' "${TIMES[*]}" | sed 's/;/, /g')"
    fi
    if [[ -z $WORK ]]; then
        :
    elif [[ ${MOSYS_SLURM_CHECK_KEEP:-0} == 1 ]]; then
        say "kept $WORK"
    else
        rm -rf "$WORK"
    fi
    rm -f "$LOCK"
    if [[ -n ${SKIPPED:-} ]]; then
        :
    elif ((rc == 0)); then
        say "passed"
    else
        say "FAILED (exit $rc)" >&2
    fi
    exit "$rc"
}
trap cleanup EXIT
trap 'exit 130' INT TERM
if [[ ${stale_link:-0} == 1 ]]; then
    say "removing a stale $SYSTEM_CONF link ($(readlink "$SYSTEM_CONF")) of an earlier check"
    rm -f "$SYSTEM_CONF"
fi

# --- install -----------------------------------------------------------------------------------
FAILED_PHASE="install"
start=$(now)
DAEMONS=(munged slurmctld slurmd sinfo squeue sbatch srun scancel)
missing=0
for cmd in "${DAEMONS[@]}"; do command -v "$cmd" >/dev/null || missing=1; done
if ((missing)); then
    say "installing slurm-wlm and munge with apt-get"
    apt_options=(-qq -o DPkg::Lock::Timeout=300 -o Dpkg::Use-Pty=0)
    export DEBIAN_FRONTEND=noninteractive
    APT_LOG=$(mktemp /tmp/mosys-slurm-check-apt.XXXXXX)
    apt-get "${apt_options[@]}" update >"$APT_LOG" 2>&1 ||
        skip "apt-get update failed ($(tail -n 1 "$APT_LOG"))"
    apt-get "${apt_options[@]}" install -y --no-install-recommends slurm-wlm munge \
        >>"$APT_LOG" 2>&1 ||
        skip "apt-get install slurm-wlm munge failed ($(tail -n 1 "$APT_LOG"))"
    rm -f "$APT_LOG"
    for cmd in "${DAEMONS[@]}"; do
        command -v "$cmd" >/dev/null || fail "$cmd missing after installing slurm-wlm and munge"
    done
fi
if ! "$PYTHON" -c 'import snakemake_executor_plugin_slurm' 2>/dev/null; then
    say "installing $PLUGIN_REQUIREMENT into $(dirname "$VENV_BIN")"
    "$PYTHON" -m pip install -q "$PLUGIN_REQUIREMENT" ||
        fail "pip install $PLUGIN_REQUIREMENT failed"
fi
plugin_version=$("$PYTHON" -m pip show snakemake-executor-plugin-slurm 2>/dev/null |
    awk '/^Version/ { print $2 }')
say "$(slurmctld -V), $(munged -V 2>&1 | head -n 1), executor plugin $plugin_version"
phase_done install "$start"

# --- the cluster -------------------------------------------------------------------------------
WORK=$(mktemp -d /tmp/mosys-slurm.XXXXXX)

FAILED_PHASE="cluster up"
start=$(now)
NODE=$(hostname -s 2>/dev/null || uname -n)
NODE=${NODE%%.*}
CPUS=$(nproc)
MEM_MB=$(awk '/^MemTotal:/ { printf "%d", $2 / 1024 }' /proc/meminfo)
MARGIN_MB=$((MEM_MB / 10 > 512 ? MEM_MB / 10 : 512))
REAL_MB=$((MEM_MB - MARGIN_MB))
for port in 6817 6818; do
    if (exec 3<>"/dev/tcp/127.0.0.1/$port") 2>/dev/null; then
        fail "port $port (slurmctld, slurmd) is in use on this host"
    fi
done
mkdir -p "$WORK"/{munge,state,spool}
chmod 755 "$WORK"/munge  # munged wants its socket directory searchable

# munge: its own key and socket, so as not to meet a system munged
if command -v mungekey >/dev/null; then
    mungekey --create --keyfile="$WORK/munge/munge.key" 2>/dev/null
else
    dd if=/dev/urandom of="$WORK/munge/munge.key" bs=1024 count=1 status=none
fi
chmod 400 "$WORK/munge/munge.key"
SOCKET=$WORK/munge/munge.socket
munged --foreground --force --socket="$SOCKET" --key-file="$WORK/munge/munge.key" \
    --pid-file="$WORK/munge/munged.pid" --log-file="$WORK/munge/munged.log" \
    --seed-file="$WORK/munge/munged.seed" >"$WORK/munge/munged.out" 2>&1 &
PIDS+=($!)
for _ in $(seq 50); do [[ -S $SOCKET ]] && break; sleep 0.2; done
munge --socket="$SOCKET" --no-input | unmunge --socket="$SOCKET" >/dev/null ||
    fail "munged does not answer on $SOCKET"

cat >"$WORK/slurm.conf" <<EOF
# generated by tools/slurm_check.sh: a one-node cluster, no accounting, no cgroups
ClusterName=mosyscheck
SlurmctldHost=$NODE(127.0.0.1)
SlurmUser=root
SlurmdUser=root
SlurmctldPort=6817
SlurmdPort=6818
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$SOCKET
StateSaveLocation=$WORK/state
SlurmdSpoolDir=$WORK/spool
SlurmctldPidFile=$WORK/slurmctld.pid
SlurmdPidFile=$WORK/slurmd.pid
SlurmctldLogFile=$WORK/slurmctld.log
SlurmdLogFile=$WORK/slurmd.log
SlurmctldDebug=info
SlurmdDebug=info
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
MpiDefault=none
SwitchType=switch/none
MailProg=/bin/true
SchedulerType=sched/builtin
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
SlurmdParameters=config_overrides
ReturnToService=2
# the plugin polls with squeue (no accounting): finished jobs must stay listed for >= 120 s
MinJobAge=300
KillWait=5
InactiveLimit=0
NodeName=$NODE NodeAddr=127.0.0.1 CPUs=$CPUS RealMemory=$REAL_MB State=UNKNOWN
PartitionName=$PARTITION Nodes=$NODE Default=YES MaxTime=INFINITE State=UP
EOF
export SLURM_CONF=$WORK/slurm.conf
mkdir -p "$(dirname "$SYSTEM_CONF")"
ln -s "$WORK/slurm.conf" "$SYSTEM_CONF"
LINKED=1

slurmctld -D -c -i -f "$WORK/slurm.conf" >>"$WORK/slurmctld.out" 2>&1 &
PIDS+=($!)
slurmd -D -f "$WORK/slurm.conf" -N "$NODE" >>"$WORK/slurmd.out" 2>&1 &
PIDS+=($!)
SLURM_UP=1
state=""
deadline=$((SECONDS + CLUSTER_TIMEOUT))
while ((SECONDS < deadline)); do
    for pid in "${PIDS[@]}"; do
        kill -0 "$pid" 2>/dev/null || {
            cat "$WORK"/slurmctld.out "$WORK"/slurmd.out >&2
            fail "a daemon exited (pid $pid)"
        }
    done
    state=$(sinfo -h -n "$NODE" -o %t 2>/dev/null || true)
    [[ $state == idle ]] && break
    sleep 1
done
[[ $state == idle ]] ||
    fail "node $NODE not idle after ${CLUSTER_TIMEOUT} s (state: '${state:-none}')"
say "cluster up: node $NODE, $CPUS CPUs, RealMemory $REAL_MB MB, partition $PARTITION"
phase_done "cluster up" "$start"

# --- the builds --------------------------------------------------------------------------------
copy_workflow() {  # destination: like tests/test_workflow.py's copy_workflow
    mkdir -p "$1"
    local name
    for name in Snakefile workflow config profiles specs src; do
        if [[ -e $ROOT/$name ]]; then cp -a "$ROOT/$name" "$1/"; fi
    done
    find "$1" -name __pycache__ -type d -prune -exec rm -rf {} +
    # a tiny budget: two seeds of one BSR search at two generations
    cat >"$1/slurm_check.yaml" <<EOF
budget: slurm_check
bsr:
  generations: 2
  seeds: 2
EOF
}

FAILED_PHASE="SLURM build"
start=$(now)
copy_workflow "$WORK/slurm"
say "building ${TARGETS[*]} through SLURM"
(
    cd "$WORK/slurm"
    # the profile as README's command uses it, the partition through its environment variable;
    # no retries (a failure must show), every job's SLURM log kept, status polled every 2 s
    # after a job ends (the plugin's default, 40 s, is for real clusters)
    MOSYS_SLURM_PARTITION=$PARTITION timeout -k 60 "$BUILD_TIMEOUT" \
        "$PYTHON" -m snakemake "${TARGETS[@]}" --configfile=slurm_check.yaml \
        --workflow-profile profiles/slurm --executor slurm \
        --retries 0 --slurm-keep-successful-logs \
        --slurm-init-seconds-before-status-checks 2 --seconds-between-status-checks 2
) >"$WORK/slurm-build.log" 2>&1 || fail "the SLURM build failed (exit $?)"

# every job but the workflow's localrules went through SLURM: one submission and one SLURM job
# id per job, each job run by slurmd (slurmctld's log), COMPLETED (squeue), its log kept
LOG=$WORK/slurm-build.log
total=$(awk '$1 == "total" { print $2; exit }' "$LOG")
remote=$(grep -c '^rule ' "$LOG" || true)
local_jobs=$(grep -c '^localrule ' "$LOG" || true)
((${total:-0} > 0 && remote + local_jobs == total)) ||
    fail "the build ran $remote SLURM jobs and $local_jobs local ones, its plan had ${total:-?}"
mapfile -t ids < <(sed -n 's/.*has been submitted with SLURM jobid \([0-9]*\).*/\1/p' "$LOG" |
    sort -un)
((${#ids[@]} == remote)) ||
    fail "expected $remote SLURM jobs, the build submitted ${#ids[@]}: ${ids[*]:-none}"
for rule in "${SLURM_RULES[@]}"; do
    grep -qx "rule $rule:" "$LOG" || fail "no $rule job went through SLURM"
done
if ((local_jobs)); then
    say "local jobs (localrules): $(grep '^localrule ' "$LOG" | sort | uniq -c | xargs)"
fi
for id in "${ids[@]}"; do
    status=$(squeue -h --states=all -j "$id" -o %T 2>/dev/null || true)
    [[ $status == COMPLETED ]] ||
        fail "SLURM job $id: squeue says '${status:-nothing}', not COMPLETED"
    grep -q "JobId=$id " "$WORK/slurmctld.log" || fail "SLURM job $id is not in slurmctld's log"
    logs=$(find "$WORK/slurm/.snakemake/slurm_logs" -name "$id.log" | wc -l)
    ((logs == 1)) || fail "SLURM job $id: no log in .snakemake/slurm_logs"
done
slurm_logs=$WORK/slurm/.snakemake/slurm_logs
say "SLURM ran ${#ids[@]} jobs (ids ${ids[*]}), all COMPLETED; their logs: $(
    find "$slurm_logs" -name '*.log' | sed "s|^$slurm_logs/||" | sort | xargs)"
phase_done "SLURM build" "$start"

FAILED_PHASE="local build"
start=$(now)
copy_workflow "$WORK/local"
say "building the same targets locally"
(
    cd "$WORK/local"
    timeout -k 60 "$BUILD_TIMEOUT" "$PYTHON" -m snakemake "${TARGETS[@]}" --cores 2 \
        --configfile=slurm_check.yaml
) >"$WORK/local-build.log" 2>&1 || fail "the local build failed (exit $?)"
phase_done "local build" "$start"

FAILED_PHASE="comparison"
start=$(now)
for target in "${TARGETS[@]}"; do
    for side in slurm local; do
        [[ -s $WORK/$side/$target ]] || fail "$side build: $target missing"
    done
done
# datasets and pixels identical; attributes too, except timings (wall seconds, rates, peak memory)
"$PYTHON" "$ROOT/tools/compare_results.py" "$WORK/local/results" "$WORK/slurm/results" ||
    fail "the SLURM build's results differ from the local build's"
phase_done comparison "$start"
phase_done total "$CHECK_START"
FAILED_PHASE=""
