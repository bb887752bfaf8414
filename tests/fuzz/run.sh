#!/bin/sh
# run.sh -- runs each libFuzzer target for a while and reports findings.
#
# make fuzz, and the short pass of make test: run each libFuzzer target
# (bin/fuzz/fuzz_*, built with clang, ASan and UBSan) for SECONDS seconds
# (default 60) from its seeds, and print per target the executions, the
# coverage and what was found, then "N passed, N failed" (targets).  Work
# files, the grown corpora and any crashing input go to build/fuzz/run/.
# Exit status 1 if a target crashed, leaked, hit undefined behaviour, ran
# out of memory or time on one input, or a seed could not be made.
#
#   sh tests/fuzz/run.sh [SECONDS] [TARGET ...]    (default: every target)
#
# Targets (the parser each reads, the untrusted input it stands for):
#   fbin     the binary scene loader: a scene file from another machine
#   json     the JSON scene reader with OBJ meshes and image textures
#   obj      the OBJ and MTL readers and the mesh shape built from them
#   gltf     the glTF 2.0 reader (.gltf and .glb)
#   ply      the PLY header check before a mesh goes to Assimp
#   hosts    the host table (hosts_parse) and cache= sizes
#   partial  a worker's partial image as the coordinator checks it
#            (img_read_partial, job_check_partial, splats, sample sums)
#   remote   what hosts answer: the probe, --check, --version, the scene
#            cache's listings, os-release, a process's stdout and stderr
#   args     command-line and environment values: --frames, '#' patterns,
#            --crop, opt.h's values, a worker's command line,
#            SLURM_JOB_CPUS_PER_NODE
#   jobdir   a job directory on --resume and `franja stitch` (job file,
#            slab files, stitching, continuing from kept sums)
#   unpack   a packed scene or zstd frame a worker unpacks (--unpack)
#   patch    a scene patch a worker applies to its cached base (--unpack)
#
# Seeds: tests/fuzz/corpus/TARGET, written by hand (inputs of remote and
# args start with a byte that picks the reader; see each target's
# comment), and seeds made here from this build so that they are always
# of the current formats: binary scenes compiled from the example scenes
# without meshes and from tests/fuzz/corpus/fbin/*.json, and a frame of
# moving instances (moving.json across a shutter); partial images
# that franja-worker writes (path-traced with sums, bidirectional with
# splats, without sums, 8- and 16-bit P6); the binary scene seeds packed
# (bin/bench/packbench), as sent and with their frame open; job directories that franja
# render --keep-job leaves (path and bidirectional, and one whose slabs
# have fewer samples than its job file asks for, to be continued).  The
# fuzzer reads at most MAX_LEN bytes of an input: example scenes that
# compile to more (their textures) are left out, and a corpus scene that
# does is an error.  What the last long campaign ran and found: README.md,
# "Fuzzing".
cd "$(dirname "$0")/../.." || exit 1
SECS=${1:-60}
[ $# -gt 0 ] && shift
TARGETS=${*:-fbin json obj gltf ply hosts partial remote args jobdir unpack patch}
W=build/fuzz/run
MAX_LEN=65536
rm -rf "$W"
mkdir -p "$W/seed-fbin" "$W/seed-partial" "$W/seed-jobdir" "$W/seed-unpack" "$W/render"

fail_seed() { echo "fuzz: cannot make seeds: $*"; echo "0 passed, 1 failed"; exit 1; }

for s in scenes/*.json tests/fuzz/corpus/fbin/*.json; do
    case "$s" in scenes/*) grep -q '"mesh"' "$s" && continue ;; */moving.json) continue ;; esac
    out="$W/seed-fbin/$(basename "$s" .json).fbin"
    bin/franja compile "$s" -o "$out" >/dev/null || fail_seed "franja compile $s"
    size=$(wc -c <"$out")
    [ "$size" -le "$MAX_LEN" ] && continue
    rm -f "$out"
    case "$s" in
    scenes/*) echo "fuzz: $s left out of the fbin seeds ($size bytes > $MAX_LEN)" ;;
    *) fail_seed "seed $s compiles to $size bytes, more than the $MAX_LEN the fuzzer reads" ;;
    esac
done

# A frame of moving instances across a shutter (the inst_motions section),
# from the scene that franja render compiles for it.
bin/franja render tests/fuzz/corpus/fbin/moving.json --frames 1 --shutter 1 -o "$W/render/moving.#.pfm" \
    --keep-job -j 1 >/dev/null 2>&1 &&
    cp "$W/render/moving.1.pfm.franja-job/scene.fbin" "$W/seed-fbin/moving-frame.fbin" ||
    fail_seed "franja render tests/fuzz/corpus/fbin/moving.json --frames 1 --shutter 1"

# Partial images, as workers send them back.
S=$W/seed-fbin/spheres-point.fbin
P=$W/seed-partial
[ -f "$S" ] || fail_seed "$S was not compiled"
for args in "sums.pf --size 4x3 --rows 1:3 --spp 2 --sums" \
    "splat.pf --size 3x3 --rows 0:2 --spp 2 --integrator bdpt" \
    "plain.pf --size 5x2 --rows 0:1 --spp 1 --noise-threshold 0.5" \
    "p16.ppm --size 3x2 --rows 0:2 --spp 1 --format ppm16" \
    "p8.ppm --size 3x2 --rows 1:2 --spp 1 --format ppm8"; do
    set -- $args
    name=$1
    shift
    bin/franja-worker --scene "$S" "$@" -o "$P/$name" || fail_seed "franja-worker $*"
done

# Job directories: the job file, then its slab files, each after a line
# "--8<--" (fuzz_jobdir.c).
jobseed() { # OUT JOBDIR [JOBFILE]
    { cat "${3:-$2/job}"
      for f in "$2"/rows-*.pf; do printf '\n--8<--\n'; cat "$f"; done; } >"$1"
}
R=$W/render
render() { # JOBDIR ARGS...
    j=$1
    shift
    bin/franja render "$S" -o "$j.pfm" --job "$j" --keep-job --slab-rows 1 -j 1 --reproducible "$@" \
        >/dev/null 2>"$j.log" || fail_seed "franja render $* ($(tail -n 1 "$j.log"))"
}
render "$R/path" --size 4x3 --spp 2
render "$R/bdpt" --size 3x2 --spp 1 --integrator bdpt
render "$R/one" --size 4x3 --spp 1
jobseed "$W/seed-jobdir/path" "$R/path"
jobseed "$W/seed-jobdir/bdpt" "$R/bdpt"
jobseed "$W/seed-jobdir/continue" "$R/one" "$R/path/job"
# Packed scenes (fuzz_unpack.c): a first byte 0, then the file as sent; 1,
# then its header and its frame's content.
for f in "$W"/seed-fbin/*.fbin; do
    b="$W/seed-unpack/$(basename "$f" .fbin)"
    bin/bench/packbench "$f" -o "$b.pk" && bin/bench/packbench "$f" -O "$b.open" ||
        fail_seed "bin/bench/packbench $f"
    for m in 0:pk 1:open; do
        { printf "\\00${m%%:*}"; cat "$b.${m#*:}"; } >"$b.${m%%:*}"
        rm -f "$b.${m#*:}"
        [ "$(wc -c <"$b.${m%%:*}")" -le "$MAX_LEN" ] || rm -f "$b.${m%%:*}"
    done
done
[ -n "$(ls "$W/seed-unpack")" ] || fail_seed "no packed scene under $MAX_LEN bytes"
for f in "$P"/* "$W"/seed-jobdir/*; do
    [ "$(wc -c <"$f")" -le "$MAX_LEN" ] || fail_seed "$f is larger than $MAX_LEN bytes"
done

echo "== fuzz: ${SECS} s per target, clang $(clang --version | sed -n 's/.*version \([0-9.]*\).*/\1/p;q'), ASan + UBSan"
rc=0
pass=0
fails=0
for t in $TARGETS; do
    mkdir -p "$W/corpus-$t"
    seeds=
    for d in tests/fuzz/corpus/$t "$W/seed-$t"; do
        [ -d "$d" ] && seeds="$seeds $d"
    done
    [ -x "bin/fuzz/fuzz_$t" ] || { echo "fuzz_$t: not built (make bin/fuzz/fuzz_$t)"; rc=1; fails=$((fails + 1)); continue; }
    start=$(date +%s)
    # shellcheck disable=SC2086 # the seed directories are words
    "bin/fuzz/fuzz_$t" -max_total_time="$SECS" -timeout=10 -rss_limit_mb=2048 -max_len="$MAX_LEN" \
        -print_final_stats=1 -artifact_prefix="$W/$t-" "$W/corpus-$t" $seeds >"$W/$t.log" 2>&1
    status=$?
    took=$(($(date +%s) - start))
    execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$W/$t.log" | tail -n 1)
    inputs=$(ls "$W/corpus-$t" | wc -l)
    cov=$(grep -o 'cov: [0-9]*' "$W/$t.log" | tail -n 1)
    if [ "$status" -eq 0 ]; then
        pass=$((pass + 1))
        echo "fuzz_$t: ${execs:-?} executions in ${took} s, $cov, corpus grew by $inputs inputs: nothing found"
    else
        rc=1
        fails=$((fails + 1))
        echo "fuzz_$t: FOUND a problem after ${execs:-?} executions (exit $status); input: $(ls "$W/$t-"* 2>/dev/null)"
        grep -E 'ERROR|runtime error|SUMMARY' "$W/$t.log" | head -n 5
    fi
done
echo "$pass passed, $fails failed"
exit $rc
