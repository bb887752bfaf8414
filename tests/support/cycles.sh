# cycles.sh -- helpers sourced by the comparisons with Cycles.
#
# Sourced by the comparisons with Cycles (tests/it_cycles_*.sh,
# after tests/support/lib.sh, with the scratch directory $T): renders one of the
# scenes of tests/data/cycles-*.json with Franja and compares it with
# Cycles' render of it (tests/data/cycles-NAME.exr and its RGB pixels as
# .pfm, made by `make refs` with tests/refs/cycles_scene.py).
#
#   cycles_render JSON SPP OUT.pfm
#                    compiles JSON and renders it at its own size as two
#                    worker slabs, stitched into one PFM; non-zero on failure
#   cycles_compare NAME SPP
#                    renders tests/data/cycles-NAME.json at SPP and checks
#                    the PFM copy against the EXR, then every channel's
#                    mean within 1.5 % of Cycles' and the worst 64x64
#                    block's mean within 3 % (the limits of issue 11)
#   cycles_differs JSON SPP NAME WHAT
#                    renders JSON (a changed scene) and checks that it does
#                    NOT pass against Cycles' NAME: the comparison can fail

CYCLES_LIMITS="--max-mean-rel 0.015 --max-block-rel 0.03 --block 64"

cycles_render() {
    # Some scenes share the sky of scenes/textures, outside their folder.
    bin/franja compile "$1" --allow-path scenes/textures -o "$T/c.fbin" >/dev/null 2>"$T/err" || { echo "compile $1: $(cat "$T/err")"; return 1; }
    # The partial image's comment names the scene's size.
    size=$(bin/franja-worker --scene "$T/c.fbin" --rows 0:1 --spp 1 -o - | head -c 200 | sed -n 's/.* size=//p')
    w=${size%x*} h=${size#*x}
    half=$((h / 2))
    R="--scene $T/c.fbin --spp $2"
    bin/franja-worker $R --rows 0:$half -o "$T/top.pfm" &
    bin/franja-worker $R --rows $half:$h -o "$T/bottom.pfm" || { wait; return 1; }
    wait $! || return 1
    # bottom row first: the lower slab's pixels come first
    { printf 'PF\n%d %d\n-1.0\n' "$w" "$h"; tail -c $(((h - half) * w * 12)) "$T/bottom.pfm"
      tail -c $((half * w * 12)) "$T/top.pfm"; } >"$3"
}

cycles_compare() {
    ref=tests/data/cycles-$1
    oiiotool $ref.exr --ch R,G,B $ref.pfm --diff >"$T/diff" 2>&1 && ok ||
        bad "$ref.pfm differs from the EXR: $(tail -n 3 "$T/diff")"
    if ! cycles_render $ref.json "$2" "$T/$1.pfm" >"$T/rerr" 2>&1; then
        bad "render $ref.json: $(cat "$T/rerr")"
        return
    fi
    bin/tools/imgcmp "$T/$1.pfm" $ref.pfm $CYCLES_LIMITS >"$T/cmp" 2>&1 && ok || bad "$1: $(cat "$T/cmp")"
    grep -v passed "$T/cmp" | sed 's/^/  /'
}

cycles_differs() {
    if ! cycles_render "$1" "$2" "$T/x.pfm" >"$T/rerr" 2>&1; then
        bad "render $1: $(cat "$T/rerr")"
    elif bin/tools/imgcmp "$T/x.pfm" tests/data/cycles-$3.pfm $CYCLES_LIMITS >"$T/xcmp" 2>&1; then
        bad "$4 passes the comparison with Cycles: $(cat "$T/xcmp")"
    else
        ok
    fi
}
