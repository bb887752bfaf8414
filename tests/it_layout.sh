#!/bin/sh
# The shape of common/, checked on the sources and on the built objects:
#   - no circle among its modules (a module is x.c with x.h), neither in
#     #include lines nor in who-calls-whom (nm on build/common/*.o);
#   - the render path (a worker's way from .fbin to pixels) touches no
#     compile-time module: no render-side file includes a compile-time
#     header, no render-side object calls into one, and the worker links
#     and renders from the render-side objects alone;
#   - no test compiles a common/ source into itself (#include "x.c");
#   - every common/ header is documented in the comment style Doxygen reads
#     (/** @file NAME ... */, no plain /* comments), and `make docs` (the
#     same Doxyfile) shows the renderer's header contracts.
# The compile-time modules are listed below; every other module of common/
# is render-side.  A new module that builds scenes belongs in the list (it
# fails the checks otherwise, since it calls the builder).
cd "$(dirname "$0")/.." || exit 1
. tests/lib.sh
need nm tsort cc doxygen
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT

COMPILE_TIME="budget builder builder_light freeze freeze_light bvh_build bvh2 bvh_reinsert scene_hooks scene_json scene_appear scene_light scene_microfacet jsonval gltf_doc gltf_mat gltf_scene scene_gltf"
B=build

is_compile_time() {
    case " $COMPILE_TIME " in *" $1 "*) return 0 ;; esac
    return 1
}

# include_edges DIR: "from to" for every #include "x.h" between files of DIR.
include_edges() {
    for f in "$1"/*.c "$1"/*.h; do
        [ -e "$f" ] || continue
        m=$(basename "$f"); m=${m%.*}
        sed -n 's/^[[:space:]]*#[[:space:]]*include[[:space:]]*"\([^"]*\)\.h".*/\1/p' "$f" | while read -r h; do
            [ -e "$1/$h.h" ] && [ "$h" != "$m" ] && echo "$m $h"
        done
    done
    return 0
}

# circles NAME EDGEFILE: fails with the modules of a loop, if there is one.
circles() {
    if tsort "$2" >/dev/null 2>"$T/loop"; then
        ok
    else
        bad "$1 circle among: $(sed -n 's/^tsort: \([^:]*\)$/\1/p' "$T/loop" | tr '\n' ' ')"
    fi
}

# The detector itself finds a planted circle (a.h -> b.h -> c.c -> a.h).
mkdir "$T/plant"
printf '#include "b.h"\n' >"$T/plant/a.h"
printf '#include "c.h"\n' >"$T/plant/b.h"
printf '#include "a.h"\n' >"$T/plant/c.c"
: >"$T/plant/c.h"
include_edges "$T/plant" >"$T/plant.edges"
if tsort "$T/plant.edges" >/dev/null 2>&1; then bad "a planted include circle goes unnoticed"; else ok; fi

# (a) Include circles among common/ files.
include_edges common | sort -u >"$T/inc.edges"
check "include lines of common/ found" test -s "$T/inc.edges"
circles include "$T/inc.edges"

# Every listed compile-time module exists (a renamed file must be renamed here).
for m in $COMPILE_TIME; do
    [ -e "common/$m.h" ] || [ -e "common/$m.c" ] && ok || bad "compile-time module $m: no common/$m.h or .c"
done

# (b) No render-side file includes a compile-time header.
while read -r from to; do
    if ! is_compile_time "$from" && is_compile_time "$to"; then
        bad "render-side $from includes compile-time $to.h"
    fi
done <"$T/inc.edges"
ok

# The objects of common/'s sources (not stale ones of removed files).
objs=""
for c in common/*.c; do
    o=$B/common/$(basename "$c" .c).o
    if [ -e "$o" ]; then objs="$objs $o"; else bad "$o missing (run make first)"; fi
done

# Symbols: which module defines each global symbol, which ones each uses.
: >"$T/defs"
: >"$T/uses"
n_obj=0
for o in $objs; do
    n_obj=$((n_obj + 1))
    m=$(basename "$o" .o)
    nm -g --defined-only "$o" | awk -v m="$m" 'NF == 3 { print $3, m }' >>"$T/defs"
    nm -u "$o" | awk -v m="$m" '{ print $NF, m }' >>"$T/uses"
done
check "objects of common/ found" test "$n_obj" -gt 5
check "nm sees bld_push defined by builder" grep -q '^bld_push builder$' "$T/defs"
sort -u "$T/defs" >"$T/defs.s"
sort -u "$T/uses" >"$T/uses.s"
# "user definer" for every use of a symbol that a common/ object defines.
join "$T/uses.s" "$T/defs.s" | awk '$2 != $3 { print $2, $3, $1 }' | sort -u >"$T/calls"
check "calls between common/ objects found" test -s "$T/calls"
awk '{ print $1, $2 }' "$T/calls" | sort -u >"$T/call.edges"
circles call "$T/call.edges"

# (b) No render-side object uses a symbol that a compile-time module defines.
while read -r user definer sym; do
    if ! is_compile_time "$user" && is_compile_time "$definer"; then
        bad "render-side $user.o uses $sym from compile-time $definer.o"
    fi
done <"$T/calls"
ok

# (b) The worker links from the render-side objects alone (a worker built
# for binary scenes only, as the static ones are) and renders the same
# bytes as bin/franja-worker.
render_objs=""
for o in $objs; do
    is_compile_time "$(basename "$o" .o)" || render_objs="$render_objs $o"
done
if cc -std=c17 -D_GNU_SOURCE -DFRANJA_NO_JSON -ffp-contract=off -fno-math-errno -Icommon \
    -o "$T/worker" worker/*.c $render_objs -lm 2>"$T/link"; then
    ok
    if bin/franja compile scenes/spheres.json -o "$T/s.fbin" >/dev/null 2>"$T/log" &&
        bin/franja-worker --scene "$T/s.fbin" --rows 2:6 --size 24x8 --spp 4 -o "$T/a.pf" 2>"$T/log" &&
        "$T/worker" --scene "$T/s.fbin" --rows 2:6 --size 24x8 --spp 4 -o "$T/b.pf" 2>"$T/log"; then
        check "the render-side-only worker renders the same bytes" cmp -s "$T/a.pf" "$T/b.pf"
    else
        bad "render with the render-side-only worker: $(cat "$T/log")"
    fi
else
    bad "the worker does not link from render-side objects alone: $(head -5 "$T/link")"
fi

# (c) No test compiles a common/ source into itself.
grep -n '^[[:space:]]*#[[:space:]]*include[[:space:]]*"[^"]*\.c"' tests/*.c tests/*/*.c 2>/dev/null >"$T/cinc"
while IFS= read -r line; do
    f=$(printf '%s\n' "$line" | sed 's/.*"\([^"]*\)".*/\1/')
    [ -e "common/$(basename "$f")" ] && bad "test includes a common/ source: $line"
done <"$T/cinc"
ok

# (d) Header comments Doxygen reads, and the documentation it makes.
for h in common/*.h; do
    head -n 1 "$h" | grep -qx "/\*\* @file $(basename "$h")" || bad "$h does not open with /** @file $(basename "$h")"
    grep -n '/\*[^*]' "$h" | grep -v '/\*\*' >"$T/plain" && bad "$h: plain /* comments: $(head -2 "$T/plain")"
done
ok
mkdir -p "$T/docs"
if { cat coordinator/Doxyfile; echo "OUTPUT_DIRECTORY = $T/docs"; echo "WARN_LOGFILE = $T/docs/warnings.log"; } |
    doxygen - >"$T/doxygen.log" 2>&1; then
    # A function's contract from pathtrace.h and a field's from scene.h.
    check "docs: pt_render_rows with its contract" grep -rqs "caller-owned, width" "$T/docs/html"
    check "docs: fr_camera's fields" grep -rqs "lens radius, scene units" "$T/docs/html"
else
    bad "doxygen failed: $(tail -3 "$T/doxygen.log")"
fi

summary
