#!/bin/sh
# it_cli.sh -- tests franja's version, help and default output names.
#
# franja's command line: version, help, the outputs named after
# the scene when -o is omitted.
cd "$(dirname "$0")/.." || exit 1
. tests/support/lib.sh
need cmp oiiotool
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
same_pixels "$T/named.png" "$T/here/cornell.png" && ok || bad "render without -o differs from the same render with -o"
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
"$F" stitch --tonemap=none "$J" -o "$T/st.png" >/dev/null 2>&1 && same_pixels "$T/st.png" "$T/full.png" && ok ||
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
# --- options: getopt_long everywhere ---
# --opt=value and --opt value, options before or after the scene, -jN.
(cd "$T/here" && "$F" render --size=12x8 --spp=3 -j2 -o eq.pfm "$ROOT/scenes/spheres.json") >"$T/out" 2>&1 &&
    grep -q "(12x8, 3 spp)" "$T/out" && ok || bad "--size=12x8 --spp=3: $(tail -n 2 "$T/out")"
(cd "$T/here" && "$F" render "$ROOT/scenes/spheres.json" -o sp.pfm --size 12x8 --spp 3 -j 2) >/dev/null 2>&1
cmp -s "$T/here/eq.pfm" "$T/here/sp.pfm" && ok || bad "--opt=value and --opt value give different images"
# An unambiguous abbreviation is the option.
(cd "$T/here" && "$F" render "$ROOT/scenes/spheres.json" -o ab.pfm --si 12x8 --sp 3 -j 2) >/dev/null 2>&1
cmp -s "$T/here/eq.pfm" "$T/here/ab.pfm" && ok || bad "--si/--sp abbreviations do not work"
# -- ends the options: a scene whose name starts with a dash.
cp scenes/spheres.json "$T/here/-dash.json"
(cd "$T/here" && "$F" render --size 8x8 --spp 1 -j 1 -o dash.png -- -dash.json) >"$T/out" 2>&1 &&
    [ -s "$T/here/dash.png" ] && ok || bad "render -- -dash.json: $(tail -n 2 "$T/out")"
# Bad values say what is allowed.
expect_error "--spp 0" "--spp: '0' is not an integer in 1..1048576" "$F" render scenes/spheres.json --spp 0
expect_error "--spp=x" "--spp: 'x' is not an integer in 1..1048576" "$F" render scenes/spheres.json --spp=x
expect_error "--tonemap aces" "--tonemap: 'aces' is not one of: none, filmic" "$F" render scenes/spheres.json --tonemap aces
expect_error "--integrator" "--integrator: 'bidir' is not one of: path, bdpt, mlt" "$F" render scenes/spheres.json --integrator=bidir
expect_error "--size 64" "--size: '64' is not WxH" "$F" render scenes/spheres.json --size 64
expect_error "-j 0" "-j: '0' is not an integer in 1..4096" "$F" render scenes/spheres.json -j 0
expect_error "--exposure x" "--exposure: 'x' is not a number in -64..64" "$F" render scenes/spheres.json --exposure x
expect_error "--timeout 0" "--timeout: '0' is not an integer in 1..3600" "$F" hosts check --hosts hosts/local.hosts --timeout 0
expect_error "--retries" "--retries: '1001' is not an integer in 1..1000" "$F" render scenes/spheres.json --retries=1001
expect_error "--stitch --tonemap" "is not one of: none, filmic" "$F" stitch "$J" -o "$T/x.png" --tonemap=aces
# A missing value, a value for a flag, an ambiguous abbreviation.
expect_error "--spp at the end" "--spp needs a value" "$F" render scenes/spheres.json --spp
expect_error "--resume=1" "--resume takes no value" "$F" render scenes/spheres.json --resume=1
expect_error "--s" "--s is ambiguous" "$F" render scenes/spheres.json --s 1
# Unknown options: the nearest known one, in every command.
expect_error "render --samples" "unknown option '--samples'; did you mean --spp?" "$F" render scenes/spheres.json --samples 8
expect_error "render --szie" "did you mean --size?" "$F" render scenes/spheres.json --szie 8x8
expect_error "render --threads" "did you mean -j?" "$F" render scenes/spheres.json --threads 8
expect_error "compile --camra" "did you mean --camera?" "$F" compile scenes/spheres.json --camra x
expect_error "hosts --hots" "did you mean --hosts?" "$F" hosts check --hots hosts/local.hosts
expect_error "deploy --dst" "did you mean --dist?" "$F" deploy --hosts hosts/local.hosts --dst x
expect_error "stitch --exposre" "did you mean --exposure?" "$F" stitch "$J" -o x.png --exposre 1
expect_error "render --zzzz" "unknown option '--zzzz' (see franja render --help)" "$F" render scenes/spheres.json --zzzz
expect_error "hosts: two verbs" "unexpected 'list'" "$F" hosts check list --hosts hosts/local.hosts

summary
