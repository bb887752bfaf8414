#!/bin/sh
# it_metadata.sh -- tests the final image records what made it.
#
# A final image says what made it: Franja's version
# (Software), the scene's hash, the samples per pixel, the integrator, the
# render time and the hosts that rendered rows (ImageDescription, and as
# franja:* attributes in OpenEXR), read back with oiiotool from .png
# (text chunks), .tif (tags), .exr and .jpg; franja stitch says the same
# but for the time and the hosts, which it does not know.
cd "$(dirname "$0")/.." || exit 1
. tests/support/lib.sh
need oiiotool
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
F="$(pwd)/bin/franja"
"$F" compile scenes/cornell.json -o "$T/c.fbin" >"$T/compile" 2>&1 && ok || bad "compile failed: $(cat "$T/compile")"
hash=$(sed -n 's/.*: scene \([0-9a-f]\{16\}\),.*/\1/p' "$T/compile")
[ -n "$hash" ] && ok || bad "no scene hash in: $(cat "$T/compile")"
version=$("$F" --version | awk '{print $2}')
# Two hosts, both this machine, so that the list has two names.
printf 'left  local - 1\nright local - 1\n' >"$T/two.hosts"

info() { oiiotool --info -v "$1" 2>&1; }
for ext in png tif exr jpg; do
    # Rows enough (64 slabs of one row) that both hosts render some even
    # when one of them starts late on a busy machine.
    "$F" render "$T/c.fbin" -o "$T/m.$ext" --size 64x64 --spp 3 --slab-rows 1 --hosts "$T/two.hosts" \
        2>"$T/log" && ok || { bad "render to .$ext failed: $(tail -n 3 "$T/log")"; continue; }
    info "$T/m.$ext" >"$T/i"
    grep -q "Software: \"Franja $version\"" "$T/i" && ok || bad ".$ext: no Software \"Franja $version\": $(cat "$T/i")"
    d=$(sed -n 's/^ *ImageDescription: "\(.*\)"$/\1/p' "$T/i")
    for want in "Franja $version render" "scene $hash" "3 spp" "integrator path" "hosts left,right"; do
        case $d in *"$want"*) ok ;; *) bad ".$ext: ImageDescription '$d' lacks '$want'" ;; esac
    done
    # The render time: a number of seconds, no more than the wall time of the run.
    t=$(printf '%s\n' "$d" | sed -n 's/.*render time \([0-9.]*\) s.*/\1/p')
    wall=$(sed -n 's/.* in \([0-9.]*\) s$/\1/p' "$T/log" | tail -n 1)
    [ -n "$t" ] && [ -n "$wall" ] && awk -v t="$t" -v w="$wall" 'BEGIN { exit !(t > 0 && t <= w + 0.01) }' && ok ||
        bad ".$ext: render time '$t' (the run says '$wall')"
done
# OpenEXR keeps each figure as its own attribute.
info "$T/m.exr" >"$T/i"
for kv in "franja:version: \"$version\"" "franja:scene: \"$hash\"" 'franja:spp: "3"' 'franja:integrator: "path"' \
    'franja:hosts: "left,right"'; do
    grep -qF "$kv" "$T/i" && ok || bad ".exr lacks $kv: $(cat "$T/i")"
done
grep -q 'franja:render_time: "[0-9.]*"' "$T/i" && ok || bad ".exr lacks franja:render_time"

# The integrator named is the one that rendered.
"$F" render "$T/c.fbin" -o "$T/b.exr" --size 16x16 --spp 1 -j 2 --integrator bdpt 2>"$T/log" && ok ||
    bad "bdpt render failed: $(tail -n 3 "$T/log")"
info "$T/b.exr" | grep -qF 'franja:integrator: "bdpt"' && ok || bad "a bdpt render is not marked bdpt"
info "$T/b.exr" | grep -qF 'franja:hosts: "local"' && ok || bad "a local render does not name host local"

# franja stitch: version, scene, spp, integrator; no time, no hosts.
"$F" render "$T/c.fbin" -o "$T/k.png" --size 16x16 --spp 2 -j 2 --keep-job 2>"$T/log" && ok ||
    bad "render --keep-job failed: $(tail -n 3 "$T/log")"
"$F" stitch "$T/k.png.franja-job" -o "$T/s.tif" >"$T/log" 2>&1 && ok || bad "stitch failed: $(cat "$T/log")"
info "$T/s.tif" >"$T/i"
grep -q "ImageDescription: \"Franja $version render; scene $hash; 2 spp; integrator path\"" "$T/i" && ok ||
    bad "stitch's .tif description: $(cat "$T/i")"
# --reproducible: no time, no hosts, and two renders split differently on
# other hosts write the same bytes in every format.
printf 'a local - 2\nb local - 1\n' >"$T/other.hosts"
for ext in png tif exr jpg; do
    "$F" render "$T/c.fbin" -o "$T/r1.$ext" --size 32x32 --spp 3 --slab-rows 4 --hosts "$T/two.hosts" \
        --reproducible 2>"$T/log" && ok || bad "--reproducible .$ext failed: $(tail -n 3 "$T/log")"
    "$F" render "$T/c.fbin" -o "$T/r2.$ext" --size 32x32 --spp 3 --slab-rows 7 --hosts "$T/other.hosts" \
        --reproducible 2>"$T/log" && ok || bad "--reproducible .$ext failed: $(tail -n 3 "$T/log")"
    cmp -s "$T/r1.$ext" "$T/r2.$ext" && ok || bad ".$ext with --reproducible: two renders write other bytes"
    d=$(info "$T/r1.$ext" | sed -n 's/^ *ImageDescription: "\(.*\)"$/\1/p')
    [ "$d" = "Franja $version render; scene $hash; 3 spp; integrator path" ] && ok ||
        bad ".$ext with --reproducible: ImageDescription '$d'"
done
info "$T/r1.exr" | grep -q 'franja:render_time\|franja:hosts' && bad ".exr with --reproducible keeps a time or hosts" || ok
info "$T/r1.tif" | grep -q 'DateTime: "1970:01:01 00:00:00"' && ok || bad ".tif with --reproducible: $(info "$T/r1.tif" | grep DateTime)"
SOURCE_DATE_EPOCH=1700000000 "$F" render "$T/c.fbin" -o "$T/e.exr" --size 8x8 --spp 1 --reproducible 2>"$T/log" && ok ||
    bad "--reproducible with SOURCE_DATE_EPOCH failed: $(tail -n 3 "$T/log")"
info "$T/e.exr" | grep -q 'DateTime: "2023:11:14 22:13:20"' && ok || bad "SOURCE_DATE_EPOCH: $(info "$T/e.exr" | grep DateTime)"
summary
