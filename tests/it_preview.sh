#!/bin/sh
# it_preview.sh -- tests --preview writes the image so far.
#
# franja render --preview FILE: the image so far, written
# atomically every few seconds while the render runs (rows not yet done as
# a grey checkerboard), and the whole image at the end; --progress json:
# one JSON object a line on stdout.
cd "$(dirname "$0")/.." || exit 1
. tests/support/lib.sh
need cmp jq oiiotool
T=$(mktemp -d)
trap 'kill $pid 2>/dev/null; rm -rf "$T"' EXIT
ROOT=$(pwd)
F="$ROOT/bin/franja"
IS="$ROOT/bin/tools/imgstat"
pid=""

# A render of some seconds even on a fast machine: many slabs, one worker,
# previews every second.
"$F" render scenes/cornell.json -o "$T/out.pfm" --size 64x64 --spp 768 -j 1 --slab-rows 2 \
    --preview "$T/pre.pfm" --preview-every 1 >"$T/log" 2>&1 &
pid=$!
# Copy every preview that appears while it runs.
n=0 last=""
while kill -0 $pid 2>/dev/null; do
    if [ -e "$T/pre.pfm" ]; then
        sum=$(cksum <"$T/pre.pfm")
        if [ "$sum" != "$last" ]; then
            n=$((n + 1)); cp "$T/pre.pfm" "$T/seen.$n.pfm"; last=$sum
        fi
    fi
    sleep 0.1
done
wait $pid && ok || bad "render with --preview failed: $(tail -n 3 "$T/log")"
pid=""
[ "$n" -ge 2 ] && ok || bad "only $n distinct previews seen while rendering"
# Each preview seen is a whole image of the render's size (written atomically),
# and a preview before the end has rows shown as the checkerboard.
partial=0
for k in $(seq 1 "$n"); do
    st=$("$IS" "$T/seen.$k.pfm" 2>&1)
    case $st in size=64x64*) ok ;; *) bad "preview $k is not a whole 64x64 image: $st" ;; esac
    # The bottom row band: the checkerboard (0.02 and 0.08, mean 0.05) until rendered.
    b=$("$IS" "$T/seen.$k.pfm" --rect 0 56 64 64)
    case $b in *"mean=0.05 "*"min=0.02 max=0.08"*) partial=$((partial + 1)) ;; esac
done
[ "$partial" -ge 1 ] && ok || bad "no preview showed rows not yet rendered"
# Rows a preview shows as rendered are the final image's rows.
for k in $(seq 1 "$n"); do
    d=$("$IS" "$T/seen.$k.pfm" --rect 0 0 64 2 --diff "$T/out.pfm")
    b=$("$IS" "$T/seen.$k.pfm" --rect 0 0 64 2)
    case $b in *"min=0.02 max=0.08"*) continue ;; esac
    case $d in *" max=0 "*) ok ;; *) bad "preview $k: the top rows differ from the final image: $d" ;; esac
done
# At the end the preview is the whole image.
cmp -s "$T/pre.pfm" "$T/out.pfm" && ok || bad "the last preview is not the final image"
ls "$T" | grep -q 'tmp' && bad "temporary files left: $(ls "$T")" || ok

# A PNG preview of a PFM render: tone-mapped like an output.
"$F" render scenes/spheres.json -o "$T/s.pfm" --size 16x16 --spp 2 -j 1 --preview "$T/s.png" >/dev/null 2>&1 &&
    "$F" render scenes/spheres.json -o "$T/s2.png" --size 16x16 --spp 2 -j 1 >/dev/null 2>&1 &&
    same_pixels "$T/s.png" "$T/s2.png" && ok || bad "a PNG preview's last image is not the PNG render"

# A bidirectional render: the last preview has the light-traced splats too.
"$F" render scenes/spheres.json --integrator bdpt -o "$T/b.pfm" --size 24x16 --spp 2 -j 2 --preview "$T/bp.pfm" \
    >/dev/null 2>&1 && cmp -s "$T/b.pfm" "$T/bp.pfm" && ok || bad "a bidirectional render's last preview is not its image"

expect_error "preview to the output" "is the output itself" "$F" render scenes/spheres.json -o "$T/a.png" --preview "$T/a.png"
expect_error "preview type" "xyz" "$F" render scenes/spheres.json -o "$T/a.png" --preview "$T/a.xyz"
expect_error "preview-every 0" "--preview-every: '0' is not an integer in 1..3600" "$F" render scenes/spheres.json --preview-every 0
# A preview that cannot be written says so once, and the render goes on.
"$F" render scenes/spheres.json -o "$T/ok.png" --size 16x16 --spp 1 -j 1 --preview "$T/no/such/dir/p.png" \
    >"$T/log" 2>&1 && [ -s "$T/ok.png" ] && ok || bad "an unwritable preview stopped the render: $(tail -n 2 "$T/log")"
c=$(grep -c "preview .*not written" "$T/log")
[ "$c" -eq 1 ] && ok || bad "an unwritable preview is reported $c times, not once: $(cat "$T/log")"

# --- --progress json ---
# Long enough (a few seconds even on a fast machine) for progress events
# at their half-second pace.
"$F" render scenes/cornell.json -o "$T/j.png" --size 48x48 --spp 128 -j 1 --slab-rows 2 --progress json \
    >"$T/events" 2>"$T/log" && ok || bad "render --progress json failed: $(tail -n 2 "$T/log")"
jq -e . "$T/events" >/dev/null 2>&1 && ok || bad "--progress json: not one JSON object a line: $(head -n 3 "$T/events")"
[ "$(head -n 1 "$T/events" | jq -r '.event + " " + .output + " " + (.width|tostring) + " " + (.spp|tostring)')" = \
    "start $T/j.png 48 128" ] && ok || bad "first event: $(head -n 1 "$T/events")"
[ "$(tail -n 1 "$T/events" | jq -r '.event + " " + .status + " " + (.rows_done|tostring)')" = "done ok 48" ] && ok ||
    bad "last event: $(tail -n 1 "$T/events")"
# Progress: rows done only grow, end at every row, each event with an ETA.
jq -r 'select(.event == "progress") | .rows_done' "$T/events" >"$T/rows"
[ "$(wc -l <"$T/rows")" -ge 2 ] && ok || bad "fewer than two progress events: $(cat "$T/events")"
sort -n -c "$T/rows" 2>/dev/null && ok || bad "rows_done goes down: $(tr '\n' ' ' <"$T/rows")"
[ "$(tail -n 1 "$T/rows")" = 48 ] && ok || bad "the last progress event is not every row"
[ "$(jq -r 'select(.event == "progress") | has("eta_s") and has("elapsed_s") and has("rows_per_s")' "$T/events" | sort -u)" = true ] &&
    ok || bad "a progress event lacks eta_s, elapsed_s or rows_per_s"
grep -q '^{' "$T/log" && bad "JSON events on stderr" || ok
expect_error "--progress bad" "--progress: 'xml' is not one of: auto, json" "$F" render scenes/spheres.json --progress xml
# Interrupted: the done event says so.
"$F" render scenes/cornell.json -o "$T/i.png" --size 64x64 --spp 1024 -j 1 --slab-rows 1 --progress json \
    >"$T/ievents" 2>"$T/log" &
pid=$!
k=0
while [ $k -lt 300 ] && ! grep -q '"progress"' "$T/ievents"; do sleep 0.1; k=$((k + 1)); done
kill -INT $pid
wait $pid
rc=$?
pid=""
[ $rc -eq 130 ] && ok || bad "interrupted render: exit status $rc"
[ "$(tail -n 1 "$T/ievents" | jq -r .status)" = interrupted ] && ok || bad "interrupted: last event $(tail -n 1 "$T/ievents")"
summary
