#!/bin/sh
# profile.sh -- counts a scene's instructions a sample by part (callgrind).
#
# Where a sample's time goes, in instructions (callgrind counts them
# exactly, whatever else loads the machine): SCENE (scenes/cornell.json by
# default; scenes/metals.json and scenes/sky-spheres.json are the other two
# of the speed goal) at 64x64 and 16 spp in one worker process, the cost of each function (with
# the code inlined into it) summed by part and divided by the number of
# samples, the branch mispredictions of callgrind's branch simulator per
# sample beside it, and the rays a sample traces (calls of trace_closest and
# trace_occluded, or of the walks they call where they are inlined).  WORKER=path profiles another build of the worker (the
# one before a change, say); SIZE and SPP change the slab; CG=path keeps the
# raw profile there (for callgrind_annotate).
cd "$(dirname "$0")/../.." || exit 1
command -v valgrind >/dev/null || { echo "profile: valgrind is not installed" >&2; exit 1; }
W=${WORKER:-bin/franja-worker} SIZE=${SIZE:-64} SPP=${SPP:-16} SCENE=${SCENE:-scenes/cornell.json}
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
bin/franja compile "$SCENE" -o "$T/scene.fbin" >/dev/null || exit 1
valgrind --tool=callgrind --branch-sim=yes --callgrind-out-file="$T/cg" "$W" --scene "$T/scene.fbin" \
    --size "${SIZE}x$SIZE" --spp "$SPP" --rows "0:$SIZE" -o /dev/null 2>"$T/log" || { cat "$T/log" >&2; exit 1; }
N=$((SIZE * SIZE * SPP))
[ -z "$CG" ] || cp "$T/cg" "$CG"
echo "== profile: $SCENE ${SIZE}x$SIZE, $SPP spp, $W (callgrind, $N samples)"
echo "reproduce: SCENE=$SCENE WORKER=$W sh tests/bench/profile.sh"
# Exclusive cost per function: Ir, then the branch columns (Bc Bcm Bi Bim),
# a '.' where a count is 0; the function is the first field naming a file.
callgrind_annotate --auto=no --threshold=100 "$T/cg" 2>/dev/null | awk -v n=$N '
BEGIN {
    T = "1|BVH traversal (trace_closest, trace_occluded, trace_walk.inc)"
    H = "2|hit points and BSDFs (trace_surface, geom, bsdf, microfacet, texture)"
    S = "3|sampler (sampler.c)"
    L = "4|light sampling (light.c, vtx_direct_*)"
    I = "5|integrator and camera (pathtrace.c, vtx_next, vtx_scatter_*)"
    M = "6|own math (fmath.c)"
    E = "7|environment map (envmap.c)"
}
/PROGRAM TOTALS/ { t = $1; gsub(",", "", t); total = t; next }
/^ *[0-9,]+ \(/ {
    line = $0; gsub(/\([^)]*\)/, "", line); k = split(line, v, " +")
    if (v[1] == "") for (i = 1; i < k; i++) v[i] = v[i + 1]
    f = ""; for (i = 1; i <= k; i++) if (v[i] ~ /[a-z]:[A-Za-z_]/) { f = v[i]; break }
    if (f == "") next
    ir = v[1]; gsub(",", "", ir); bm = v[3]; gsub(",", "", bm); if (bm !~ /^[0-9]+$/) bm = 0
    fn = f; sub(/^.*:/, "", fn); file = f; sub(/:[^:]*$/, "", file); sub(/^.*\//, "", file)
    # Code inlined into another function (link-time optimisation inlines
    # across modules) is charged to the module its source lines come from;
    # lines from shared headers (vec.h, simd4.h, intrinsics) and from
    # modules that hold more than one part go by the function they run in.
    if (file == "trace_walk.inc")
        p = T
    else if (file == "sampler.c")
        p = S
    else if (file == "fmath.c")
        p = M
    else if (file == "light.c")
        p = L
    else if (file == "envmap.c" || fn ~ /^(env_|lookup|density)/)
        p = E
    else if (file ~ /^(bsdf|microfacet|geom|texture|medium)\.c$/)
        p = H
    else if (file ~ /^(pathtrace|camera)\.c$/)
        p = I
    else if (fn ~ /^(trace_closest|trace_occluded|ray_setup|walk|node_hits|leaf_test|block_test|closest_|occluded_)/)
        p = T
    else if (fn ~ /^(trace_surface|geo_|push|bsdf_|mf_|smooth_eval|micro_|tex_|med_|quad)/)
        p = H
    else if (fn ~ /^smp_/)
        p = S
    else if (fn ~ /^(lgt_|vtx_direct|prim_point|aim|textured)/)
        p = L
    else if (file == "trace.c" && fn ~ /^vtx_next/)
        p = H                  # the hit point (trace_surface_uv), inlined there beside the walk entry
    else if (file == "trace.c")
        p = T                  # the entry points, inlined where they are called
    else if (fn ~ /^(pt_|vtx_|roulette|light_numbers|emission|escaped)/ || file == "vertex.c")
        p = I
    else if (fn ~ /^fm_/)
        p = M
    else
        p = "8|start-up, output and the rest"
    ins[p] += ir; mis[p] += bm; all += bm
}
END {
    printf "| part | instructions per sample | share | mispredicted branches per sample |\n|---|---|---|---|\n"
    for (p in ins) {
        name = p; sub(/^[0-9]\|/, "", name)
        printf "%s|| %s | %d | %.1f %% | %.2f |\n", substr(p, 1, 1), name, ins[p] / n, 100 * ins[p] / total, mis[p] / n | "sort | cut -c3-"
    }
    close("sort | cut -c3-")
    printf "| total | %d | | %.2f |\n", total / n, all / n
}'
# Rays: calls of the two traversal entry points, summed from the raw
# profile's call records (cfn= names the callee, compressed to "(id)" after
# its first mention in an fn= or cfn= line; calls= follows with the count).
# Where an entry point is inlined into its callers (link-time optimisation),
# the walk it calls is counted instead: per kind of ray, the largest count
# among trace_closest and closest_* (trace_occluded and occluded_*), names
# taken without the compiler's .lto_priv / .constprop suffixes.
awk -v n=$N '
/^c?fn=/ { id = $1; sub(/^c?fn=/, "", id); if (NF > 1) name[id] = $2; if ($1 ~ /^cfn/) callee = name[id]; next }
/^calls=/ { c = $1; sub(/^calls=/, "", c); b = callee; sub(/\..*$/, "", b); calls[b] += c }
END {
    for (f in calls) {
        if ((f == "trace_closest" || f ~ /^closest_/) && calls[f] > closest) closest = calls[f]
        if ((f == "trace_occluded" || f ~ /^occluded_/) && calls[f] > shadow) shadow = calls[f]
    }
    printf "rays per sample: %.2f closest-hit, %.2f shadow (any-hit)\n", closest / n, shadow / n
}' "$T/cg"
