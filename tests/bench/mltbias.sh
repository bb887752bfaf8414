#!/bin/sh
# mltbias.sh -- Metropolis start-up bias on Veach's door, and what the mutations do there.
#
# Veach's door (tests/bench/scenes/door-veach.json, 96x72): the pixels of
# column 42, rows 15-39, see the far room through the 1 cm gap, a bright
# region that few paths reach.  MLT renders it at each of SPPS mutations
# per pixel (default 64 and 512) with each of SEEDS (default 1 and 1001; one
# worker per core),
# and imgstat prints that column's mean and the whole image's against a
# long BDPT reference (REF_SPP samples per pixel, made once and kept in
# build/bench under a checksum of the worker's version and the scene).
# Chains too short to reach the gap's room leave the column too dark.  Then
# bin/bench/mltstats counts, by path length, how many small and large steps
# the chains propose and accept at the first of SPPS.
cd "$(dirname "$0")/../.." || exit 1
[ -x bin/tools/imgstat ] && [ -x bin/bench/mltstats ] ||
    { echo "$0: bin/tools/imgstat or bin/bench/mltstats is missing: run make bench" >&2; exit 1; }
SPPS=${SPPS:-"64 512"} SEEDS=${SEEDS:-"1 1001"} REF_SPP=${REF_SPP:-2048} N=$(nproc)
SCENE=tests/bench/scenes/door-veach.json RECT="42 15 43 40"
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
mkdir -p build/bench
echo "machine: $N cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //')"
echo "reproduce: SPPS=\"$SPPS\" SEEDS=\"$SEEDS\" REF_SPP=$REF_SPP sh tests/bench/mltbias.sh"
bin/franja compile "$SCENE" -o "$T/door.fbin" >/dev/null || exit 1
key=$( (bin/franja-worker --version; cat "$SCENE") | sha256sum | cut -c1-12)
REF=build/bench/mltbias-ref-$REF_SPP-$key.pfm
if [ ! -s "$REF" ]; then
    bin/franja render "$T/door.fbin" --integrator bdpt --spp "$REF_SPP" -j "$N" -o "$T/ref.pfm" 2>/dev/null &&
        mv "$T/ref.pfm" "$REF" || { echo "the reference render failed" >&2; exit 1; }
fi
col() { bin/tools/imgstat "$1" --rect $RECT | sed 's/.* mean=\([^ ]*\).*/\1/'; }
all() { bin/tools/imgstat "$1" | sed 's/.* mean=\([^ ]*\).*/\1/'; }
echo "BDPT reference, $REF_SPP spp: the gap's column $(col "$REF"), the image $(all "$REF")"
for seed in $SEEDS; do
    sed "s/\"seed\": [0-9]*/\"seed\": $seed/" "$SCENE" >"$T/seed.json"
    bin/franja compile "$T/seed.json" -o "$T/seed.fbin" >/dev/null || exit 1
    for spp in $SPPS; do
        /usr/bin/time -f '%U %S' -o "$T/time" bin/franja render "$T/seed.fbin" --integrator mlt --spp "$spp" \
            -j "$N" -o "$T/mlt.pfm" 2>/dev/null || { echo "the MLT render failed" >&2; exit 1; }
        echo "MLT, seed $seed, $spp mutations/pixel ($(awk '{ printf "%.1f", $1 + $2 }' "$T/time") CPU-s):" \
            "the gap's column $(col "$T/mlt.pfm"), the image $(all "$T/mlt.pfm")"
    done
done
bin/bench/mltstats "$SCENE" --spp "${SPPS%% *}"
