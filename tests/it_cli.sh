#!/bin/sh
# it_cli.sh -- franja's command line: version, help, the outputs named after
# the scene when -o is omitted.
cd "$(dirname "$0")/.." || exit 1
. tests/lib.sh
need cmp
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
ROOT=$(pwd)
F="$ROOT/bin/franja"

# --- version: three spellings, one answer ---
v=$("$F" --version) && ok || bad "franja --version exits non-zero"
case $v in "franja "[0-9]*) ok ;; *) bad "franja --version: '$v'" ;; esac
for spelling in -V version; do
    w=$("$F" $spelling) && ok || bad "franja $spelling exits non-zero"
    [ "$w" = "$v" ] && ok || bad "franja $spelling says '$w', --version '$v'"
done
expect_error "version with an argument" "takes no arguments" "$F" version render

# --- help ---
for c in render compile hosts deploy; do
    "$F" $c --help >"$T/a" 2>&1 && ok || bad "franja $c --help exits non-zero"
    "$F" help $c >"$T/b" 2>&1 && ok || bad "franja help $c exits non-zero"
    cmp -s "$T/a" "$T/b" && ok || bad "franja help $c differs from franja $c --help"
    grep -q "^usage: franja $c" "$T/b" && ok || bad "franja help $c: no usage line"
done
"$F" help >"$T/a" && grep -q "franja help \[COMMAND\]" "$T/a" && ok || bad "franja help: no usage"
expect_error "help for no command" "no command 'paint'" "$F" help paint
"$F" >/dev/null 2>"$T/err"; [ $? -eq 2 ] && grep -q "^usage: franja render" "$T/err" && ok ||
    bad "franja alone: usage on stderr, status 2"

# --- -o omitted: SCENE.png here; compile: SCENE.fbin here ---
mkdir "$T/here"
(cd "$T/here" && "$F" render "$ROOT/scenes/cornell.json" --size 24x16 --spp 2 -j 2) >"$T/out" 2>&1 && ok ||
    bad "render without -o failed: $(tail -n 3 "$T/out")"
[ -s "$T/here/cornell.png" ] && ok || bad "render without -o did not write cornell.png in the current directory"
[ ! -e "$ROOT/scenes/cornell.png" ] && ok || bad "render without -o wrote beside the scene"
grep -q "wrote cornell.png" "$T/out" && ok || bad "render without -o does not say what it wrote: $(tail -n 1 "$T/out")"
"$F" render scenes/cornell.json -o "$T/named.png" --size 24x16 --spp 2 -j 1 >/dev/null 2>&1
cmp -s "$T/named.png" "$T/here/cornell.png" && ok || bad "render without -o differs from the same render with -o"
(cd "$T/here" && "$F" compile "$ROOT/scenes/spheres.json" >/dev/null) && [ -s "$T/here/spheres.fbin" ] && ok ||
    bad "compile without -o did not write spheres.fbin in the current directory"
(cd "$T/here" && "$F" render spheres.fbin --size 16x16 --spp 1 -j 1) >"$T/out" 2>&1 && [ -s "$T/here/spheres.png" ] &&
    ok || bad "render of an .fbin without -o: no spheres.png: $(tail -n 2 "$T/out")"
expect_error "no name to derive" "give -o OUT" "$F" render scenes/.json

# --- stitch: an image from whatever a job directory holds ---
IS="$ROOT/bin/tools/imgstat"
J="$T/full.pfm.franja-job"
"$F" render scenes/cornell.json -o "$T/full.pfm" --size 32x16 --spp 2 -j 2 --slab-rows 4 --keep-job >"$T/out" 2>&1 &&
    [ -d "$J" ] && ok || bad "render --keep-job: $(tail -n 2 "$T/out")"
"$F" stitch "$J" -o "$T/st.pfm" >"$T/out" 2>&1 && ok || bad "stitch of a whole job failed: $(cat "$T/out")"
cmp -s "$T/st.pfm" "$T/full.pfm" && ok || bad "stitch of a whole job differs from the render's image"
grep -q "16 of 16 rows present" "$T/out" && ok || bad "stitch does not count the rows: $(cat "$T/out")"
"$F" render scenes/cornell.json -o "$T/full.png" --size 32x16 --spp 2 -j 2 >/dev/null 2>&1
"$F" stitch --tonemap=none "$J" -o "$T/st.png" >/dev/null 2>&1 && cmp -s "$T/st.png" "$T/full.png" && ok ||
    bad "stitch to PNG (the scene's tone mapping) differs from the render's PNG"
# Take two slabs away, and spoil a third: those rows show as a checkerboard.
rm "$J"/rows-00004-00008.pf "$J"/rows-00012-00016.pf
printf 'PF\n# not a slab\n' >"$J/rows-00008-00012.pf"
ls -l "$J" >"$T/before"
"$F" stitch "$J" -o "$T/part.pfm" >"$T/out" 2>&1 && ok || bad "stitch of a partial job failed: $(cat "$T/out")"
grep -q "4 of 16 rows present" "$T/out" && grep -q "missing rows 4:16" "$T/out" && ok ||
    bad "stitch of a partial job: $(cat "$T/out")"
grep -q "1 slab file.* left out" "$T/out" && ok || bad "stitch does not say a slab was left out: $(cat "$T/out")"
ls -l "$J" >"$T/after"
cmp -s "$T/before" "$T/after" && ok || bad "stitch changed the job directory"
st=$("$IS" "$T/part.pfm" --rect 0 4 32 16)
case $st in *"mean=0.05 "*"min=0.02 max=0.08"*) ok ;; *) bad "missing rows are not the checkerboard: $st" ;; esac
d=$("$IS" "$T/part.pfm" --rect 0 0 32 4 --diff "$T/full.pfm")
case $d in *" max=0 "*) ok ;; *) bad "present rows differ from the render: $d" ;; esac
expect_error "stitch of no job" "not a job directory" "$F" stitch "$T/here" -o "$T/x.png"
printf 'franja job\nscene=zz\n' >"$T/here/job"
expect_error "stitch of a bad job file" "not a job file" "$F" stitch "$T/here" -o "$T/x.png"
expect_error "stitch without -o" "-o OUT is required" "$F" stitch "$J"
expect_error "stitch to an unknown format" ".xyz" "$F" stitch "$J" -o "$T/x.xyz"
summary
