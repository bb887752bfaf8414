#!/bin/sh
# it_layout.sh -- the shape of the tree, checked on the sources and objects.
#
#   - compile-time code is what lives in a compile/ folder (common/compile/,
#     coordinator/compile/); everything else in common/ is the render path;
#   - every project include names its path from the root of common/ or
#     coordinator/ ("compile/builder.h", "transport/hosts.h"), never a
#     sibling of a subfolder by its bare name, and no name is ambiguous;
#   - no circle among common/'s modules, in #include lines or in
#     who-calls-whom (nm on the objects);
#   - the render path touches no compile-time module: no render-side file
#     includes a compile/ header, no render-side object calls into one, and
#     the worker links and renders from the render-side objects alone;
#   - coordinator/compile/ and coordinator/transport/ do not use each other;
#   - every exported symbol is used by another object or by a test, tool,
#     benchmark or fuzz target (an allow-list names the entry points);
#   - no test compiles a project source into itself (#include "x.c");
#   - every common/ header is documented in the comment style Doxygen reads
#     (/** @file NAME ... */), and `make docs` shows the header contracts;
#   - every source, header and script opens with a line saying what it is
#     ("/* NAME -- ...", "/** @file NAME", "# NAME -- ..." after a shebang).
cd "$(dirname "$0")/.." || exit 1
. tests/support/lib.sh
need nm tsort cc doxygen
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
B=build

# Exported symbols that no other object needs to use: program entry points.
ALLOW_UNUSED="main"

# The project's C sources and headers, as paths from the repository root.
git ls-files 'common/*.[ch]' 'common/*.inc' 'coordinator/*.[ch]' 'coordinator/*.cpp' 'worker/*.[ch]' >"$T/files" 2>/dev/null ||
    find common coordinator worker -name '*.[ch]' -o -name '*.inc' -o -name '*.cpp' >"$T/files"
check "sources found" test "$(wc -l <"$T/files")" -gt 50

is_compile_time() { # PATH relative to its top folder, or a module stem
    case "$1" in compile/*) return 0 ;; esac
    return 1
}

# includes FILE: the quoted include names of FILE.
includes() {
    sed -n 's/^[[:space:]]*#[[:space:]]*include[[:space:]]*"\([^"]*\)".*/\1/p' "$1"
}

# (1) Includes name their folder from the root of common/ or coordinator/.
# resolves TOP NAME: the file NAME is under the include root TOP.
while read -r f; do
    top=${f%%/*}
    dir=$(dirname "$f")
    includes "$f" | while read -r h; do
        if [ -e "common/$h" ] || { [ "$top" = coordinator ] && [ -e "coordinator/$h" ]; } ||
            { [ "$top" = worker ] && [ -e "worker/$h" ]; }; then
            :
        elif [ -e "$dir/$h" ]; then
            echo "$f includes \"$h\" by its place beside it: name it from the root of $top/"
        fi
    done
done <"$T/files" >"$T/relative"
if [ -s "$T/relative" ]; then bad "$(head -5 "$T/relative")"; else ok; fi

# A planted sibling include is caught by the same test.
mkdir -p "$T/plant/common/compile"
printf '#include "b.h"\n' >"$T/plant/common/compile/a.c"
: >"$T/plant/common/compile/b.h"
(cd "$T/plant" && f=common/compile/a.c && h=$(includes "$f") && [ ! -e "common/$h" ] && [ -e "$(dirname "$f")/$h" ]) &&
    ok || bad "a planted sibling include goes unnoticed"

# No header is reachable under two names: the compile folders of common/
# and coordinator/ share no file name, nor do common/ and coordinator/.
(cd common && find . -name '*.h' | sed 's|^\./||') | sort >"$T/common.h"
(cd coordinator && find . -name '*.h' | sed 's|^\./||') | sort >"$T/coord.h"
comm -12 "$T/common.h" "$T/coord.h" >"$T/both"
if [ -s "$T/both" ]; then bad "headers in both common/ and coordinator/: $(tr '\n' ' ' <"$T/both")"; else ok; fi

# (2) Include circles among common/'s modules (a module is x.c with x.h;
# its name is its path from common/ without the extension).
include_edges() { # TOP: "from to" for every include between files of TOP
    grep "^$1/" "$T/files" | while read -r f; do
        m=${f#"$1"/}
        m=${m%.*}
        includes "$f" | while read -r h; do
            [ -e "$1/$h" ] && [ "${h%.*}" != "$m" ] && echo "$m ${h%.*}"
        done
    done
    return 0
}
circles() { # NAME EDGEFILE: fails with the modules of a loop, if there is one
    if tsort "$2" >/dev/null 2>"$T/loop"; then
        ok
    else
        bad "$1 circle among: $(sed -n 's/^tsort: \([^:]*\)$/\1/p' "$T/loop" | tr '\n' ' ')"
    fi
}
printf 'a b\nb c\nc a\n' >"$T/plant.edges"
if tsort "$T/plant.edges" >/dev/null 2>&1; then bad "a planted include circle goes unnoticed"; else ok; fi
include_edges common | sort -u >"$T/inc.edges"
check "include lines of common/ found" test -s "$T/inc.edges"
circles include "$T/inc.edges"
check "compile-time modules found" grep -q ' compile/builder$' "$T/inc.edges"

# (3) No render-side file of common/ includes a compile-time header.
while read -r from to; do
    if ! is_compile_time "$from" && is_compile_time "$to"; then
        bad "render-side common/$from includes compile-time $to.h"
    fi
done <"$T/inc.edges"
ok

# coordinator/compile/ and coordinator/transport/ do not use each other.
include_edges coordinator | sort -u >"$T/coord.edges"
check "include lines of coordinator/ found" grep -q '^transport/' "$T/coord.edges"
awk '($1 ~ /^compile\// && $2 ~ /^transport\//) || ($1 ~ /^transport\// && $2 ~ /^compile\//)' "$T/coord.edges" >"$T/cross"
if [ -s "$T/cross" ]; then bad "coordinator's compile/ and transport/ include each other: $(head -3 "$T/cross")"; else ok; fi

# Symbols: which object defines each global symbol, which ones each uses.
# A module is named by its path from the repository root.
: >"$T/defs"
: >"$T/uses"
n_obj=0
for c in $(grep '\.c$' "$T/files"); do
    o=$B/${c%.c}.o
    if [ ! -e "$o" ]; then bad "$o missing (run make first)"; continue; fi
    n_obj=$((n_obj + 1))
    m=${c%.c}
    nm -g --defined-only "$o" | awk -v m="$m" 'NF == 3 && $2 ~ /[TDBRV]/ { print $3, m }' >>"$T/defs"
    nm -u "$o" | awk -v m="$m" '{ print $NF, m }' >>"$T/uses"
done
check "objects found" test "$n_obj" -gt 50
check "nm sees bld_push defined by common/compile/builder" grep -q '^bld_push common/compile/builder$' "$T/defs"
sort -u "$T/defs" >"$T/defs.s"
sort -u "$T/uses" >"$T/uses.s"
# "user definer symbol" for every use of a symbol that another object defines.
join "$T/uses.s" "$T/defs.s" | awk '$2 != $3 { print $2, $3, $1 }' | sort -u >"$T/calls"
check "calls between objects found" test -s "$T/calls"
grep '^common/.* common/' "$T/calls" | awk '{ sub("common/", "", $1); sub("common/", "", $2); print $1, $2 }' |
    sort -u >"$T/call.edges"
circles call "$T/call.edges"

# (3) No render-side object of common/ uses a symbol of a compile-time one.
grep '^common/' "$T/calls" | while read -r user definer sym; do
    if ! is_compile_time "${user#common/}" && case "$definer" in common/compile/*) true ;; *) false ;; esac then
        echo "render-side $user.o uses $sym from compile-time $definer.o"
    fi
done >"$T/render_uses"
if [ -s "$T/render_uses" ]; then bad "$(head -5 "$T/render_uses")"; else ok; fi

# (4) Every exported symbol has a user: another object, or a test, tool,
# benchmark or fuzz target that names it.
awk '{ print $1 }' "$T/calls" >/dev/null
awk '{ print $3 }' "$T/calls" | sort -u >"$T/used"
find tests -name '*.[ch]' -exec cat {} + >"$T/testsrc"
tr -c 'A-Za-z0-9_' '\n' <"$T/testsrc" | sort -u >"$T/testwords"
awk '{ print $1 }' "$T/defs.s" | sort -u | comm -23 - "$T/used" | comm -23 - "$T/testwords" >"$T/unused"
for a in $ALLOW_UNUSED; do grep -vx "$a" "$T/unused" >"$T/u2"; mv "$T/u2" "$T/unused"; done
if [ -s "$T/unused" ]; then
    while read -r s; do bad "$s ($(awk -v s="$s" '$1 == s { print $2 }' "$T/defs.s")) is exported but nothing else uses it"; done <"$T/unused"
else
    ok
fi
# The same pipeline flags a planted function that nobody calls.
printf 'int planted_unused_fn(void) { return 1; }\n' >"$T/p.c"
if cc -c -o "$T/p.o" "$T/p.c" && nm -g --defined-only "$T/p.o" | awk 'NF == 3 { print $3 }' | comm -23 - "$T/used" |
    comm -23 - "$T/testwords" | grep -qx planted_unused_fn; then ok; else bad "a planted unused export goes unnoticed"; fi

# (3) The worker links from the render-side objects alone (a worker built
# for binary scenes only, as the static ones are) and renders the same
# bytes as bin/franja-worker.  libzstd is the one library besides libm: the
# worker unpacks scenes sent compressed (common/unpack.h).
render_objs=""
for c in $(grep '^common/.*\.c$' "$T/files"); do
    is_compile_time "${c#common/}" || render_objs="$render_objs $B/${c%.c}.o"
done
if cc -std=c17 -D_GNU_SOURCE -DFRANJA_NO_JSON -ffp-contract=off -fno-math-errno -Icommon \
    -o "$T/worker" worker/*.c $render_objs -lzstd -lm 2>"$T/link"; then
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

# (5) No test compiles a project source into itself.
grep -rn '^[[:space:]]*#[[:space:]]*include[[:space:]]*"[^"]*\.c"' tests --include='*.c' --include='*.h' >"$T/cinc"
if [ -s "$T/cinc" ]; then bad "a test includes a source: $(head -3 "$T/cinc")"; else ok; fi

# (6) Every source, header and script opens with a line saying what it is.
opening() { # FILE: succeeds when FILE opens as the rule says
    b=$(basename "$1")
    case "$1" in
    *.h) head -n 1 "$1" | grep -qE "^/\*\*? (@file $b\$|$b --)" ;;
    *.sh) sed -n '1,2p' "$1" | grep -q "^# $b -- " ;;
    *) head -n 1 "$1" | grep -q "^/\* $b -- " ;;
    esac
}
{ git ls-files 'common/*' 'coordinator/*' 'worker/*' 'tests/*' 'docker/*' 2>/dev/null ||
    find common coordinator worker tests docker -type f; } | grep -E '\.(c|cpp|inc|h|sh)$' >"$T/all"
check "sources and scripts found" test "$(wc -l <"$T/all")" -gt 150
while read -r f; do opening "$f" || echo "$f"; done <"$T/all" >"$T/noopen"
if [ -s "$T/noopen" ]; then bad "files without an opening line: $(head -5 "$T/noopen" | tr '\n' ' ')"; else ok; fi
printf '#include <stdio.h>\n' >"$T/plant.c"
if opening "$T/plant.c"; then bad "a planted file without an opening line goes unnoticed"; else ok; fi

# (7) Header comments Doxygen reads, and the documentation it makes.
for h in $(grep '^common/.*\.h$' "$T/files"); do
    head -n 1 "$h" | grep -qx "/\*\* @file $(basename "$h")" || bad "$h does not open with /** @file $(basename "$h")"
    grep -n '/\*[^*]' "$h" | grep -v '/\*\*' >"$T/plain" && bad "$h: plain /* comments: $(head -2 "$T/plain")"
done
ok
mkdir -p "$T/docs"
if { cat coordinator/Doxyfile; echo "OUTPUT_DIRECTORY = $T/docs"; echo "WARN_LOGFILE = $T/docs/warnings.log"; } |
    doxygen - >"$T/doxygen.log" 2>&1; then
    # A function's contract from pathtrace.h, a field's from scene.h, and a
    # compile-time header's from compile/builder.h.
    check "docs: pt_render_rows with its contract" grep -rqs "caller-owned, width" "$T/docs/html"
    check "docs: fr_camera's fields" grep -rqs "lens radius, scene units" "$T/docs/html"
    check "docs: compile/builder.h" grep -rqs "bld_push" "$T/docs/html"
    if [ -s "$T/docs/warnings.log" ]; then bad "doxygen warns: $(head -3 "$T/docs/warnings.log")"; else ok; fi
else
    bad "doxygen failed: $(tail -3 "$T/doxygen.log")"
fi

summary
