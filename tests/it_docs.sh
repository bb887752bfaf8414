#!/bin/sh
# it_docs.sh -- tests the documentation's examples run and show what they say.
#
# The documentation's examples run, and show what they say.
#
# Every fenced example (```lang ... ```) of the Markdown files of the
# repository (README.md, scenes/README.md, coordinator/README.md ..., any
# *.md outside bin/, build/ and dist/), and every .nf/.fi or .EX/.EE block of
# the man pages (*/man/*.[1-9]), carries an annotation on the line(s) just
# before it (blank lines may come between) saying what it shows:
#
#     <!-- expect: CHECK -->          in Markdown
#     .\" expect: CHECK               in a man page
#
# Several checks may share a line, separated by ';', except skip:, run and
# template, which take the rest of their line.  An example without an
# annotation, with an unknown check, that fails to run or that does not show
# what it says fails this test, which names the file and line.
#
# Shell examples (```sh, and man page blocks) run as written, with `sh -e`,
# in a scratch copy of the repository (scenes/ and hosts/ copied, the rest
# linked), with bin/ first on PATH and FRANJA_MAX_SPP=4 (franja(1): renders
# take at most that many samples per pixel).  They must exit 0, unless
# `exit N` or `error` says otherwise, and show one of:
#   error TEXT           exits non-zero with TEXT in its standard error
#   stdout TEXT          TEXT in its standard output (stderr TEXT likewise)
#   file PATH...         it creates PATH (not empty)
#   same PATH...         it creates PATH byte for byte as the repository has it
#   image PATH WxH       it creates the image PATH, W x H pixels
#   mean PATH > X        the mean of PATH's pixels and channels is above X
#                        (or `< X`; linear values for .pfm .exr .hdr, the
#                        stored values / 255 for 8-bit files)
#   template CMD         the block is not a command but a template of lines:
#                        CMD's output has a line matching each, where <...>
#                        stands for any non-blank text
#   write FILE           the block is not a command but the text of FILE;
#   run CMD              ... and CMD (any shell line) is what runs, checked
#                        as above
#   exit N               the exit status is N
# JSON examples (```json) are read as files of scenes/; they are one of
#   scene                a complete scene
#   in top               top-level fields ("image": {...}, ...), dropped
#                        into tests/data/doc-room.json (materials, textures
#                        and media merged entry by entry)
#   in materials         entries of "materials", dropped into the room
#   in shapes            shapes, one after another, added to the room
# and are rendered at 64x64 and 16 samples per pixel, with these checks:
#   dark                 the room's own light is taken away first
#   mean > X             the image's mean is above X (or `< X`)
#   differs > X          the mean absolute difference from the room without
#                        the example, over the room's mean, is above X
#   texture X0 Y0 X1 Y1  a texture appears in the pixels [X0,X1) x [Y0,Y1)
#                        (y = 0 at the top): the image over the room's,
#                        pixel by pixel, varies there with a standard
#                        deviation above 0.15 of its mean (a plain colour
#                        gives 0.03 to 0.09)
#   triangles > N        the example adds more than N triangles
#   spheres              each material of the example, on a sphere in the
#                        middle of the room, changes the image (differs > 0.02)
#   from FILE            the example is a piece of scene FILE: each field,
#                        entry or shape it has is in FILE with the same values
# Any example may instead be
#   skip: REASON         not run, for the REASON given (say a real cluster
#                        is needed); still checked where it can be: sh -n,
#                        the options of franja and franja-worker against
#                        their --help, repository paths and make targets
#                        that it names, JSON syntax (`...` may elide text)
#
#   sh tests/it_docs.sh [DOC...]     (default: the files above)
cd "$(dirname "$0")/.." || exit 1
. tests/support/lib.sh
need awk oiiotool timeout cmp
ROOT=$(pwd)
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
unset MAKEFLAGS MFLAGS MAKELEVEL
F="$ROOT/bin/franja"
DJ="$ROOT/bin/tools/docjson"
IS="$ROOT/bin/tools/imgstat"
for tool in "$F" "$ROOT/bin/franja-worker" "$DJ" "$IS"; do
    [ -x "$tool" ] || { bad "$tool is not built (make test builds it)"; summary; exit 1; }
done

if [ $# -gt 0 ]; then
    DOCS="$*"
else
    DOCS=$(find . \( -path ./.git -o -path ./bin -o -path ./build -o -path ./dist \) -prune -o \
        \( -name '*.md' -o -path '*/man/*.[1-9]' \) -type f -print | sed 's|^\./||' | sort)
fi
E="$T/ex"
mkdir -p "$E"
n=0
for d in $DOCS; do
    n=$(awk -v out="$E" -v first="$n" -f tests/support/docex.awk "$d") || { bad "$d: cannot be read"; summary; exit 1; }
done
if [ -s "$E/errors" ]; then
    while IFS= read -r line; do bad "$line"; done <"$E/errors"
fi
[ "$n" -gt 0 ] && ok || bad "no examples found in $DOCS"

# --- helpers ---------------------------------------------------------------

# fail MESSAGE: a failed check of the current example, named by its place.
fail() { bad "$where: $*"; }

# arg KIND: the argument of the current example's first KIND check.
arg() { awk -F '\t' -v k="$1" '$1 == k { sub(/^[^\t]*\t/, ""); print; exit }' "$checks"; }
has() { cut -f1 "$checks" | grep -qx -- "$1"; }
# unquote TEXT: TEXT without one pair of surrounding double quotes.
unquote() { printf '%s' "$1" | sed 's/^"\(.*\)"$/\1/'; }

# stat_of IMAGE FIELD: FIELD (size, mean, sd) of an image; PFM through
# bin/tools/imgstat, other formats through oiiotool.
stat_of() {
    case "$1" in
    *.pfm) "$IS" "$1" | tr ' ' '\n' | sed -n "s/^$2=//p" ;;
    *)
        oiiotool --stats "$1" 2>/dev/null | awk -v f="$2" '
            NR == 1 { w = $3; h = $5; sub(/,$/, "", h) }
            /Stats Avg:/ { s = $3 + $4 + $5; d = ($0 ~ /of 255/) ? 255 : ($0 ~ /of 65535/) ? 65535 : 1; m = s / 3 / d }
            END { if (f == "size") print w "x" h; else if (f == "mean") print m }' ;;
    esac
}

# compare A OP B: numeric comparison (OP is > or <); false if either is not a number.
compare() {
    awk -v a="$1" -v b="$3" -v op="$2" 'BEGIN {
        if (a !~ /^-?[0-9.]+(e[-+]?[0-9]+)?$/ || b !~ /^-?[0-9.]+(e[-+]?[0-9]+)?$/) exit 1
        exit !(op == ">" ? a + 0 > b + 0 : a + 0 < b + 0) }'
}

# sandbox DIR: a scratch copy of the repository for one shell example.
sandbox() {
    mkdir -p "$1"
    for e in "$ROOT"/* "$ROOT"/.[!.]*; do
        [ -e "$e" ] || continue
        b=$(basename "$e")
        case $b in
        .git) ;;
        scenes | hosts) cp -R "$e" "$1/" ;;
        *) if [ -d "$e" ]; then ln -s "$e" "$1/$b"; else cp "$e" "$1/"; fi ;;
        esac
    done
}

# help_of PROGRAM [SUBCOMMAND...]: the --help text the example's options are
# checked against.
help_of() {
    case "$1" in
    franja-worker) "$ROOT/bin/franja-worker" --help ;;
    *) shift; "$F" "$@" --help ;;
    esac 2>&1
}

# lint FILE: what can be checked of a shell example that is not run.
lint() {
    sh -n "$1" 2>"$T/lint" || { fail "not valid sh: $(cat "$T/lint")"; return; }
    # One command a line (pipes, && and ; split further), with its line.
    awk '{ sub(/#.*/, ""); gsub(/&&|\|\||[;|]/, "\n"); n = split($0, c, "\n"); for (j = 1; j <= n; j++) print NR, c[j] }' \
        "$1" >"$T/cmds"
    file=${where%:*} at=${where##*:}
    while read -r l cmd rest; do
        [ -n "$cmd" ] || continue
        here="$file:$((at + l))"
        set -- $rest
        case "$cmd" in
        franja | */franja | franja-worker | */franja-worker)
            prog=$(basename "$cmd") sub=""
            if [ "$prog" = franja ]; then
                case "${1:-}" in render | compile | deploy | stitch) sub=$1; shift ;; hosts) sub="hosts ${2:-}"; shift 2 ;; esac
            fi
            help_of "$prog" $sub >"$T/help"
            for w in "$@"; do
                case "$w" in
                -*) grep -qE -- "(^|[[:space:][])$w([[:space:]=]|$)" "$T/help" ||
                        bad "$here: '$prog $sub' has no option $w (not in its --help)" ;;
                */*) first=${w%%/*}
                    [ ! -e "$ROOT/$first" ] || [ -e "$ROOT/$w" ] || bad "$here: $w does not exist" ;;
                esac
            done
            ;;
        make)
            for target in "$@"; do
                case "$target" in -* | *=*) continue ;; esac
                grep -qE "^$target:" "$ROOT/Makefile" || bad "$here: the Makefile has no target $target"
            done
            ;;
        esac
    done <"$T/cmds"
}

# tmatch TEMPLATE OUTPUT: every line of TEMPLATE matches a line of OUTPUT,
# <...> standing for non-blank text.
tmatch() {
    while IFS= read -r line; do
        [ -n "$line" ] || continue
        re=$(printf '%s' "$line" | sed 's/[][\.*^$+?(){}|/]/\\&/g; s/<[^>]*>/[^[:space:]]+/g')
        grep -Eqx -- "$re" "$2" || fail "no line of the output matches the template line '$line'"
    done <"$1"
}

# --- shell examples --------------------------------------------------------

shell_example() {
    run="$T/run/$i"
    sandbox "$run"
    script="$T/script.$i"
    if has template; then
        printf '%s\n' "$(arg template)" >"$script"
    elif has run; then
        has write || { fail "run needs write FILE (the block is that file's text)"; return; }
        printf '%s\n' "$(arg run)" >"$script"
    else
        has write && { fail "write FILE needs run CMD"; return; }
        cp "$body" "$script"
    fi
    if has write; then
        w=$(arg write)
        cp "$body" "$run/$w" || { fail "cannot write $w"; return; }
    fi
    # What the example must create, it must create: no copy from the repository.
    for k in file same image mean; do
        awk -F '\t' -v k="$k" '$1 == k { n = split($2, a, /[ \t]+/); for (j = 1; j <= n; j++) if (k == "file" || k == "same" || j == 1) print a[j] }' "$checks"
    done | while read -r p; do rm -f "$run/$p"; done
    (cd "$run" && PATH="$run/bin:$PATH" FRANJA_MAX_SPP="${FRANJA_MAX_SPP:-4}" timeout 600 sh -e "$script") \
        >"$T/out" 2>"$T/err" </dev/null
    rc=$?
    tail_err=$(tail -n 3 "$T/err" | tr '\n' ' ')
    if has error; then
        text=$(unquote "$(arg error)")
        [ "$rc" -ne 0 ] || fail "should fail with '$text' but exits 0"
        grep -qF -- "$text" "$T/err" || fail "standard error lacks '$text': $tail_err"
    elif has exit; then
        [ "$rc" = "$(arg exit)" ] || fail "exit status $rc, expected $(arg exit): $tail_err"
    else
        [ "$rc" -eq 0 ] || fail "exit status $rc: $tail_err"
    fi
    while IFS="$(printf '\t')" read -r kind a; do
        case "$kind" in
        error | exit | write | run | template) ;;
        stdout | stderr)
            text=$(unquote "$a")
            f="$T/out"; [ "$kind" = stderr ] && f="$T/err"
            grep -qF -- "$text" "$f" || fail "$kind lacks '$text': $(tail -n 3 "$f" | tr '\n' ' ')" ;;
        file)
            for p in $a; do [ -s "$run/$p" ] || fail "did not create $p"; done ;;
        same)
            for p in $a; do
                if [ ! -s "$run/$p" ]; then fail "did not create $p"
                elif ! cmp -s "$run/$p" "$ROOT/$p"; then fail "$p differs from the repository's"; fi
            done ;;
        image)
            set -- $a
            if [ ! -s "$run/$1" ]; then fail "did not create $1"
            else s=$(stat_of "$run/$1" size); [ "$s" = "$2" ] || fail "$1 is ${s:-not an image}, expected $2"; fi ;;
        mean)
            set -- $a
            if [ ! -s "$run/$1" ]; then fail "did not create $1"
            else m=$(stat_of "$run/$1" mean); compare "$m" "$2" "$3" || fail "$1: mean ${m:-unreadable}, expected $2 $3"; fi ;;
        *) fail "unknown check '$kind' for a shell example" ;;
        esac
    done <"$checks"
    has template && tmatch "$body" "$T/out"
    cut -f1 "$checks" | grep -qxE 'error|stdout|stderr|file|same|image|mean|template' ||
        fail "the annotation says nothing the example shows: add error, stdout, file, same, image, mean or template"
}

# --- JSON examples ---------------------------------------------------------

# render SCENE OUT.pfm: a small render of a JSON scene of $T/scenes, by one
# worker (scenes with files, meshes or textures, compiled first).
render() {
    src=$1
    if grep -qE '"(file|lod)"' "$1"; then
        src=${2%.pfm}.fbin
        "$F" compile "$1" -o "$src" >/dev/null 2>"$T/rerr" || return 1
    fi
    env -u FRANJA_MAX_SPP "$ROOT/bin/franja-worker" --scene "$src" --rows 0:64 --size 64x64 --spp 16 -o "$2" 2>"$T/rerr"
}

# room IMAGE: renders the room alone (room-lit.pfm, or room-dark.pfm without
# its light), once.
room() {
    [ -s "$1" ] && return 0
    r=$(basename "$1" .pfm)
    d=""; [ "$r" = room-dark ] && d=--dark
    "$DJ" merge tests/data/doc-room.json top "$T/nothing" "$T/scenes/$r.json" $d 2>"$T/rerr" &&
        render "$T/scenes/$r.json" "$1" && return 0
    fail "the room alone does not render (dark rooms have no light: use mean): $(tail -n 1 "$T/rerr")"
    return 1
}

json_fail_at() {
    # docjson's "line L: ..." becomes a line of the document.
    file=${where%:*} line=${where##*:}
    sed -n 's/^line \([0-9]*\): \(.*\)/\1 \2/p' "$T/jerr" >"$T/jlines"
    while read -r l msg; do
        bad "$file:$((line + l)): $msg"
    done <"$T/jlines"
    [ -s "$T/jlines" ] || fail "$(cat "$T/jerr")"
}

json_example() {
    place=""
    if has scene; then place=scene; kind=value
    elif has in; then place=$(arg in); kind=members; [ "$place" = shapes ] && kind=seq
    else fail "say what the JSON is: scene, in top, in materials or in shapes"; return; fi
    case "$place" in scene | top | materials | shapes) ;; *) fail "in $place: expected top, materials or shapes"; return ;; esac
    "$DJ" parse "$kind" "$body" >/dev/null 2>"$T/jerr" || { json_fail_at; return; }
    dark=""; has dark && dark=--dark
    light=lit; [ -n "$dark" ] && light=dark
    s="$T/scenes/ex$i.json"
    if [ "$place" = scene ]; then
        cp "$body" "$s"
    else
        "$DJ" merge tests/data/doc-room.json "$place" "$body" "$s" $dark 2>"$T/jerr" || { fail "$(cat "$T/jerr")"; return; }
    fi
    if ! render "$s" "$T/ex$i.pfm"; then
        fail "does not render: $(tail -n 2 "$T/rerr" | tr '\n' ' ')"
        return
    fi
    mean=$(stat_of "$T/ex$i.pfm" mean)
    compare "$mean" ">" -1 || { fail "the image has non-finite pixels (mean $mean)"; return; }
    base="$T/room-$light.pfm"
    while IFS="$(printf '\t')" read -r k a; do
        case "$k" in
        scene | in | dark) ;;
        mean)
            set -- $a
            compare "$mean" "$1" "$2" || fail "mean $mean, expected $1 $2" ;;
        differs)
            set -- $a
            room "$base" || continue
            rel=$("$IS" "$T/ex$i.pfm" --diff "$base" | tr ' ' '\n' | sed -n 's/^rel=//p')
            compare "$rel" "$1" "$2" || fail "differs from the room by $rel, expected $1 $2" ;;
        texture)
            set -- $a
            room "$base" || continue
            cv=$("$IS" "$T/ex$i.pfm" --rect "$@" --ratio "$base" | awk '{
                for (f = 1; f <= NF; f++) { split($f, kv, "="); v[kv[1]] = kv[2] }
                print (v["mean"] > 0 ? v["sd"] / v["mean"] : 0) }')
            compare "$cv" ">" 0.15 || fail "no texture in $*: the ratio to the room varies by $cv of its mean" ;;
        triangles)
            set -- $a
            room "$base" || continue
            t1=$("$F" compile "$s" -o "$T/t.fbin" 2>&1 | sed -n 's/.*primitives (\([0-9]*\) triangles).*/\1/p')
            t0=$("$F" compile "$T/scenes/room-$light.json" -o "$T/t.fbin" 2>&1 | sed -n 's/.*primitives (\([0-9]*\) triangles).*/\1/p')
            added=$(( ${t1:-0} - ${t0:-0} ))
            compare "$added" "$1" "$2" || fail "adds $added triangles, expected $1 $2" ;;
        spheres)
            [ "$place" = materials ] || { fail "spheres is for 'in materials'"; continue; }
            mkdir -p "$T/sph$i"
            "$DJ" merge tests/data/doc-room.json materials "$body" "$T/scenes/sph$i-none.json" &&
                render "$T/scenes/sph$i-none.json" "$T/sph$i-none.pfm" || { fail "the room with the materials does not render"; continue; }
            "$DJ" spheres tests/data/doc-room.json "$body" "$T/scenes" 278 165 280 150 >"$T/names" 2>"$T/jerr" ||
                { fail "$(cat "$T/jerr")"; continue; }
            while read -r name; do
                if ! render "$T/scenes/$name.json" "$T/sph$i-$name.pfm"; then
                    fail "material $name on a sphere does not render: $(tail -n 1 "$T/rerr")"
                    continue
                fi
                rel=$("$IS" "$T/sph$i-$name.pfm" --diff "$T/sph$i-none.pfm" | tr ' ' '\n' | sed -n 's/^rel=//p')
                compare "$rel" ">" 0.02 || fail "a sphere of material $name does not show (differs by $rel)"
            done <"$T/names" ;;
        from)
            "$DJ" from "$([ "$place" = scene ] && echo top || echo "$place")" "$body" "$ROOT/$a" 2>"$T/jerr" ||
                fail "not the same as in $a: $(cat "$T/jerr")" ;;
        *) fail "unknown check '$k' for a JSON example" ;;
        esac
    done <"$checks"
    cut -f1 "$checks" | grep -qxE 'mean|differs|texture|triangles|spheres|from' ||
        fail "the annotation says nothing the example shows: add mean, differs, texture, triangles, spheres or from"
}

# --- every example ---------------------------------------------------------

cp -R scenes "$T/scenes"
cp tests/data/doc-room.json "$T/scenes/doc-room.json"
printf '' >"$T/nothing"
i=0
while [ "$i" -lt "$n" ]; do
    where=$(cat "$E/$i.where") lang=$(cat "$E/$i.lang") before=$FAILED
    checks="$E/$i.checks" body="$E/$i.body"
    if [ ! -s "$checks" ]; then
        case "$lang" in
        roff) how='a line .\" expect: CHECK just before its .nf or .EX' ;;
        *) how='a line <!-- expect: CHECK --> just before its opening fence' ;;
        esac
        fail "this $lang example has no annotation saying what it shows: add $how (the checks are listed at the top of tests/it_docs.sh)"
    elif has skip; then
        if [ -z "$(arg skip)" ]; then
            fail "skip: needs a reason"
        else
            case "$lang" in
            json) "$DJ" parse outline "$body" >/dev/null 2>"$T/jerr" || json_fail_at ;;
            sh | shell | roff) lint "$body" ;;
            esac
        fi
    else
        case "$lang" in
        json) json_example ;;
        sh | shell | roff | none) shell_example ;;
        *) fail "a '$lang' example cannot be run: use sh or json, or skip: REASON" ;;
        esac
    fi
    # One pass per example that showed all it says; each failure counted.
    [ "$FAILED" -eq "$before" ] && ok
    i=$((i + 1))
done
summary
