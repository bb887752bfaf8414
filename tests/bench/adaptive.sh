#!/bin/sh
# adaptive.sh -- measures adaptive against uniform sampling at equal CPU time.
#
# Adaptive sampling at equal time: scenes/spheres.json at 128x128, uniform
# sampling against --noise-threshold E (at most MAX_SPP samples a pixel),
# each at the sample count its CPU time allows, against a converged image
# (REF_SPP samples, another seed).  The uniform sample count is the one
# whose CPU time matches the adaptive render's (timed at SPP and scaled).
# Time is CPU seconds of one worker process (less sensitive to the load of
# the machine than wall time); medians of RUNS.
cd "$(dirname "$0")/../.." || exit 1
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
E=${E:-0.05} SPP=${SPP:-64} MAX_SPP=${MAX_SPP:-512} REF_SPP=${REF_SPP:-2048} RUNS=${RUNS:-3}
scene=scenes/spheres.json
echo "== adaptive: $scene 128x128, --noise-threshold $E (at most $MAX_SPP spp) vs uniform sampling at equal CPU time"
echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'), load $(cut -d' ' -f1-3 /proc/loadavg)"
echo "reproduce: sh tests/bench/adaptive.sh   (E, SPP, MAX_SPP, REF_SPP, RUNS in the environment)"
median() { tr ' ' '\n' | grep . | sort -g | awk '{ v[NR] = $1 } END { print v[int((NR + 1) / 2)] }'; }
rmse() { bin/tools/imgcmp "$1" "$2" | sed -n 's/^rmse \([0-9.]*\).*/\1/p'; }
# cpu SCENE OUT ARGS...: renders the whole image, prints its CPU seconds.
cpu() {
    s=$1 out=$2
    shift 2
    /usr/bin/time -f %U -o "$T/time" bin/franja-worker --scene "$s" --size 128x128 --rows 0:128 -o "$out" "$@" ||
        exit 1
    cat "$T/time"
}
sed 's/"seed": [0-9]*/"seed": 7/' $scene >"$T/ref.json"
cpu "$T/ref.json" "$T/ref.pfm" --spp "$REF_SPP" >/dev/null
ta="" tu="" ea="" eu="" ku=""
for run in $(seq "$RUNS"); do
    sed "s/\"seed\": [0-9]*/\"seed\": $run/" $scene >"$T/s.json"
    t=$(cpu "$T/s.json" "$T/a.pfm" --spp "$MAX_SPP" --noise-threshold "$E")
    t0=$(cpu "$T/s.json" "$T/u0.pfm" --spp "$SPP")
    k=$(awk "BEGIN { k = int($SPP * $t / $t0 + 0.5); print k < 1 ? 1 : k }")
    t1=$(cpu "$T/s.json" "$T/u.pfm" --spp "$k")
    ta="$ta $t" tu="$tu $t1" ku="$ku $k"
    ea="$ea $(rmse "$T/a.pfm" "$T/ref.pfm")" eu="$eu $(rmse "$T/u.pfm" "$T/ref.pfm")"
done
ma=$(echo $ea | median) mu=$(echo $eu | median)
echo "adaptive: RMSE$ea; median $ma; CPU s$ta"
echo "uniform:  RMSE$eu; median $mu; CPU s$tu at spp$ku"
awk "BEGIN { printf \"RMSE ratio adaptive/uniform at equal CPU time %.2f (below 1: adaptive sampling helps)\\n\", $ma / $mu }"
