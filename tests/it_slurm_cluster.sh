#!/bin/sh
# it_slurm_cluster.sh -- tests the Slurm test cluster itself.
#
# The Slurm test cluster itself (tests/support/slurm_cluster.sh), before anything is
# rendered on it: three nodes come up idle, a step spans them, a lost node
# is noticed by the controller and comes back, and stop leaves no daemon and
# no step process behind.
ROOT=$(cd "$(dirname "$0")/.." && pwd)
. "$ROOT/tests/support/slurm_lib.sh"
sl_init 3

idle=$(sl_q sinfo -h -N -t idle -o %N | sort -u | tr '\n' ' ')
check "three nodes idle (got '$idle')" test "$idle" = "n1 n2 n3 "
sl_q scontrol show config >"$T/config" 2>&1
check "the controller's configuration is ours" grep -q "SLURM_CONF *= *$SLURM_CONF" "$T/config"

# One task on each node; every node names itself.
sl_srun 30 -N3 -n3 sh -c 'echo "$SLURMD_NODENAME $SLURM_NODEID"' >"$T/names" 2>"$T/srun.err"
names=$(cut -d' ' -f1 "$T/names" | sort | tr '\n' ' ')
check "a step runs one task per node (got '$names': $(cat "$T/srun.err"))" test "$names" = "n1 n2 n3 "

# An allocation sees its nodes and CPUs in its environment.
sl_alloc 30 -N3 -n6 sh -c 'echo "$SLURM_JOB_NODELIST $SLURM_JOB_CPUS_PER_NODE"' >"$T/alloc" 2>/dev/null
check "salloc -N3 -n6 gives n[1-3] with 2 CPUs each (got '$(cat "$T/alloc")')" \
    grep -qx 'n\[1-3\] 2(x3)' "$T/alloc"

# A node lost with a step on it: the harness kills its daemon and its step
# processes; the other nodes' tasks are the controller's business.
sl_alloc_bg 60 -N3 -n3 --no-kill srun -N3 -n3 sleep 30 >/dev/null 2>&1
sl_until 10 sh -c "test \"\$(sh '$CLUSTER' steps '$T/cl' n3 | wc -l)\" -ge 2"
check "a step on n3 has a slurmstepd and a task" test "$(sh "$CLUSTER" steps "$T/cl" n3 | wc -l)" -ge 2
sh "$CLUSTER" kill-node "$T/cl" n3
check "kill-node leaves nothing of n3 running" test -z "$(sh "$CLUSTER" pids "$T/cl" n3)"
check "kill-node leaves the other nodes' tasks" test -n "$(sl_pids n1)"
sl_bg_stop
sh "$CLUSTER" start-node "$T/cl" n3
check "a restarted node is idle again" sl_until 15 sh -c \
    "timeout 5 sinfo -h -N -n n3 -t idle -o %N </dev/null | grep -q n3"

# Stop: no daemon and no step process survive; the state is gone.
sl_alloc_bg 60 -N3 -n3 srun -N3 -n3 sleep 30 >/dev/null 2>&1
sl_until 10 sh -c "test \"\$(sh '$CLUSTER' steps '$T/cl' | wc -l)\" -ge 6"
t0=$(date +%s)
sh "$CLUSTER" stop "$T/cl"
sl_bg_stop
check "stop takes seconds, not more ($(($(date +%s) - t0)) s)" test $(($(date +%s) - t0)) -le 10
check "stop leaves no daemon or step ($(sh "$CLUSTER" pids "$T/cl" | tr '\n' ' '))" \
    test -z "$(sh "$CLUSTER" pids "$T/cl")"
check "stop removes the controller's and nodes' state" test ! -e "$T/cl/ctld" -a ! -e "$T/cl/spool"
sh "$CLUSTER" stop "$T/cl"
check "a second stop is harmless" test $? -eq 0
check "nothing started in an allocation is left running ($(sl_strays | tr '\n' ' '))" test -z "$(sl_strays)"
summary
