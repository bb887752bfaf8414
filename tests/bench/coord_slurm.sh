#!/bin/sh
# coord_slurm.sh -- measures the cost of Slurm job steps against local workers.
#
# The cost of Slurm: the same render as job steps in an allocation of a
# real Slurm cluster on this machine (tests/support/slurm_cluster.sh: one node per
# core, one CPU each) against local worker processes with the same number
# of slots, alternated inside one allocation.  ratio = T(slurm) / T(local).
# Each job step runs in a session of its own, which Linux's autogroup
# scheduling treats as a group of its own: on a machine busy with other
# work, steps would get more CPU than local workers sharing franja's
# session.  So the local workers start through `setsid` too (a host table
# whose worker is a wrapper), and both sides compete alike.
# Also measured: the launch latency of one job step (median of 20 sruns of `true` on a
# node, against starting `true` here), and the scene broadcast (a first
# render that sbcasts the scene to every node, against a second one that
# finds it cached).
cd "$(dirname "$0")/../.." || exit 1
ROOT=$(pwd)
. tests/support/bench_common.sh
. tests/support/slurm_lib.sh
N=$(nproc)
ARGS="--size ${SIZE:-256x256} --spp ${SPP:-128}"
sl_init "$N" 1
machine
bin/franja compile scenes/cornell.json -o "$T/scene.fbin" >/dev/null 2>&1 &&
    bin/franja compile scenes/knot.json -o "$T/knot.fbin" >/dev/null 2>&1 || { echo "compile failed"; exit 1; }
SCENE="$T/scene.fbin"
BIG="$T/knot.fbin"

# Step launch latency, inside one allocation: 20 steps one after the
# other, each timed; the median and the range (and the same for starting
# `true` here).
cat >"$T/launch.sh" <<'SH'
now() { date +%s%N; }
i=0
while [ $i -lt 20 ]; do
    s=$(now); srun --exclusive -N1 -n1 -c1 --mem=0 -Q -w n1 true </dev/null || exit 1; echo "srun $(($(now) - s))"
    s=$(now); /bin/true </dev/null; echo "local $(($(now) - s))"
    i=$((i + 1))
done >"$T/launch.times"
for k in srun local; do
    sed -n "s/^$k //p" "$T/launch.times" | sort -n | awk -v k=$k '{ a[NR] = $1 / 1e6 }
        END { printf "%s %.1f %.1f %.1f\n", k, a[int((NR + 1) / 2)], a[1], a[NR] }'
done | awk '{ m[$1] = $2; lo[$1] = $3; hi[$1] = $4 }
    END { printf "step launch (median of 20): %.1f ms per srun step (%.1f-%.1f), %.2f ms per local process (%.2f-%.2f)\n",
          m["srun"], lo["srun"], hi["srun"], m["local"], lo["local"], hi["local"] }'
SH
sl_alloc 120 -N"$N" -n"$N" env T="$T" sh "$T/launch.sh" 2>/dev/null

# Scene broadcast: the first render on fresh nodes sends the scene (the
# knot, a mesh scene of some megabytes), the second finds it cached.
cat >"$T/bcast.sh" <<SH
bin/franja render "$BIG" -o "$T/b1.pfm" --size 16x16 --spp 1 --slurm --workdir "$T/work" 2>"$T/b1.log" &&
bin/franja render "$BIG" -o "$T/b2.pfm" --size 16x16 --spp 1 --slurm --workdir "$T/work" 2>"$T/b2.log"
SH
sl_alloc 120 -N"$N" -n"$N" sh "$T/bcast.sh" 2>/dev/null || { echo "broadcast renders failed"; cat "$T/b1.log"; exit 1; }
ready() { sed -n 's/.*scene \(uploaded\|already there\) (\([0-9.]*\) s).*/\2/p' "$1" | sort -n | tail -n 1; }
grep -q "scene uploaded" "$T/b1.log" && grep -q "scene already there" "$T/b2.log" ||
    { echo "the scene was not broadcast once and then found cached"; exit 1; }
B1=$(ready "$T/b1.log") B2=$(ready "$T/b2.log")
echo "scene broadcast ($(($(wc -c <"$BIG") / 1024)) KB to each of $N nodes at once): a node is ready in $B1 s" \
    "with sbcast, $B2 s when the scene is cached (probe and check): $(calc "$B1 - $B2") s for the broadcast"

# The render, alternated in one allocation.
printf '#!/bin/sh\nexec setsid %s "$@"\n' "$ROOT/bin/franja-worker" >"$T/setsid-worker"
chmod +x "$T/setsid-worker"
echo "here local - $N worker=$T/setsid-worker" >"$T/local.hosts"
cat >"$T/compare.sh" <<SH
. tests/support/bench_common.sh
RUNS=${RUNS:-3}
compare "bin/franja render $SCENE -o $T/l.pfm $ARGS --hosts $T/local.hosts" \
    "bin/franja render $SCENE -o $T/s.pfm $ARGS --slurm --workdir $T/work" || exit 1
cmp -s "$T/l.pfm" "$T/s.pfm" || { echo "Slurm and local images differ"; exit 1; }
echo "local $N slots: \$TA s, $N Slurm nodes x 1 CPU: \$TB s; ratio \$(calc "\$TB / \$TA") (overhead \$(calc "(\$TB - \$TA) * 100 / \$TA") %, \$(calc "\$TB - \$TA") s)"
SH
sl_alloc 600 -N"$N" -n"$N" sh "$T/compare.sh" 2>/dev/null || exit 1
echo "machine after: load $(cut -d' ' -f1-3 /proc/loadavg)"
