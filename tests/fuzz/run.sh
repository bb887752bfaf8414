#!/bin/sh
# make fuzz: run each libFuzzer target (bin/fuzz/fuzz_*, built with ASan
# and UBSan) for SECONDS seconds (default 60) from its seed corpus, and
# print the executions and what was found.  Work files, the grown corpora
# and any crashing input go to build/fuzz/run/.  Exit status 1 if a target
# crashed, leaked, hit undefined behaviour or timed out.
#
# Seeds: tests/fuzz/corpus/json, tests/fuzz/corpus/ply (PLY headers after
# a 4-byte file size), tests/fuzz/corpus/gltf (written by
# tests/tools/gengltf) and tests/fuzz/corpus/obj (inputs starting with 'M'
# are MTL files); the binary-scene seeds are compiled now, so that
# they are always the current format, from the example scenes without
# meshes and from tests/fuzz/corpus/fbin/*.json (small scenes with image
# textures, bump and normal maps and a mesh).  The fuzzer reads at most
# MAX_LEN bytes of an input: example scenes that compile to more (their
# textures) are left out, and a corpus scene that does is an error.
cd "$(dirname "$0")/../.." || exit 1
SECS=${1:-60}
W=build/fuzz/run
rm -rf "$W"
mkdir -p "$W/seed-fbin"
MAX_LEN=65536
for s in scenes/*.json tests/fuzz/corpus/fbin/*.json; do
    case "$s" in scenes/*) grep -q '"mesh"' "$s" && continue ;; esac
    out="$W/seed-fbin/$(basename "$s" .json).fbin"
    bin/franja compile "$s" -o "$out" >/dev/null || exit 1
    size=$(wc -c <"$out")
    [ "$size" -le "$MAX_LEN" ] && continue
    rm -f "$out"
    case "$s" in
    scenes/*) echo "fuzz: $s left out of the fbin seeds ($size bytes > $MAX_LEN)" ;;
    *) echo "fuzz: seed $s compiles to $size bytes, more than the $MAX_LEN the fuzzer reads"; exit 1 ;;
    esac
done
echo "== fuzz: ${SECS} s per target, clang $(clang --version | sed -n 's/.*version \([0-9.]*\).*/\1/p;q'), ASan + UBSan"
rc=0
for t in fbin json obj gltf ply; do
    seeds=tests/fuzz/corpus/$t
    [ "$t" = fbin ] && seeds=$W/seed-fbin
    mkdir -p "$W/corpus-$t"
    bin/fuzz/fuzz_$t -max_total_time="$SECS" -timeout=10 -rss_limit_mb=2048 -max_len="$MAX_LEN" \
        -print_final_stats=1 -artifact_prefix="$W/$t-" "$W/corpus-$t" "$seeds" >"$W/$t.log" 2>&1
    status=$?
    execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$W/$t.log" | tail -n 1)
    inputs=$(ls "$W/corpus-$t" | wc -l)
    cov=$(grep -o 'cov: [0-9]*' "$W/$t.log" | tail -n 1)
    if [ "$status" -eq 0 ]; then
        echo "fuzz_$t: ${execs:-?} executions, $cov, corpus grew by $inputs inputs: nothing found"
    else
        rc=1
        echo "fuzz_$t: FOUND a problem after ${execs:-?} executions (exit $status); input: $(ls "$W/$t-"* 2>/dev/null)"
        grep -E 'ERROR|runtime error|SUMMARY' "$W/$t.log" | head -n 5
    fi
done
exit $rc
