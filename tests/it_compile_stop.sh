#!/bin/sh
# it_compile_stop.sh -- tests an interrupted compile stops at once, leaving nothing.
#
# Ctrl-C (SIGINT) or SIGTERM during a long compile stops franja render and
# franja compile at once (the compile runs in a child process that is
# killed), leaves no partial scene.fbin, no private compile directory and
# no job directory; an uninterrupted compile still writes the same scene.
# SIGKILL of franja render ends its compiling child with it, so the job
# lock is free for the next render.
# A scene that fails to compile leaves no job directory.
cd "$(dirname "$0")/.." || exit 1
. tests/support/lib.sh
F=$PWD/bin/franja
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT

cat >"$T/big.json" <<'JSON'
{"image": {"width": 8, "height": 8, "spp": 1},
 "camera": {"position": [0, 0, -5], "target": [0, 0, 0], "fov": 40},
 "materials": {"m": {"type": "lambert", "albedo": [0.5, 0.5, 0.5]}},
 "lights": [{"type": "point", "position": [0, 3, -3], "intensity": [10, 10, 10]}],
 "shapes": [{"type": "mesh", "file": "big.obj", "material": "m"}]}
JSON

secs() { date +%s.%N; }
elapsed() { awk -v a="$1" -v b="$(secs)" 'BEGIN { printf "%.2f", b - a }'; }
less() { awk -v a="$1" -v b="$2" 'BEGIN { exit !(a < b) }'; }

# The whole compile, for its length: the interruptions below must come
# well before its end to mean anything, so the mesh doubles until its
# compile takes more than 3 s on this machine (8 M triangles at most).
tris=1000000
while :; do
    bin/gen/genmesh sphere --tris $tris -o "$T/big.obj" >/dev/null || bad "genmesh failed"
    t0=$(secs)
    "$F" compile "$T/big.json" -o "$T/full.fbin" >"$T/out" 2>"$T/err" || bad "compile: $(cat "$T/err")"
    full=$(elapsed "$t0")
    { less 3 "$full" || [ $tris -ge 8000000 ]; } && break
    tris=$((tris * 2))
done
grep -Eq " [0-9]{6,7} primitives" "$T/out" && ok || bad "compile summary: $(cat "$T/out")"
less 3 "$full" && ok || bad "the compile took $full s, too short to interrupt it reliably: enlarge the mesh"
[ -z "$(ls -A "$T" | grep compile-)" ] && ok || bad "compile left its private directory"

# until_compiling DIR: waits (30 s at most) for the child's private
# directory in DIR, proof that the compile is under way.
until_compiling() {
    i=0
    while [ $i -lt 600 ]; do
        ls -A "$1" 2>/dev/null | grep -q '\.compile-' && return 0
        sleep 0.05
        i=$((i + 1))
    done
    return 1
}

# stopped WHAT SIGNAL DIR CMD...: runs CMD in the background, sends SIGNAL
# once it is compiling into DIR, and expects exit status 130 within 1.5 s.
stopped() {
    what=$1 sig=$2 dir=$3
    shift 3
    "$@" >"$T/out" 2>"$T/err" &
    pid=$!
    if ! until_compiling "$dir"; then
        bad "$what: never seen compiling"
        kill -KILL $pid 2>/dev/null
        wait $pid
        return
    fi
    kill -"$sig" $pid
    t0=$(secs)
    wait $pid
    rc=$?
    took=$(elapsed "$t0")
    [ $rc -eq 130 ] && ok || bad "$what: exit status $rc, not 130: $(cat "$T/err")"
    less "$took" 1.5 && ok || bad "$what: ended $took s after the signal (the whole compile takes $full s)"
    grep -q "compile interrupted" "$T/err" && ok || bad "$what: no message: $(cat "$T/err")"
    ! grep -q "franja: host" "$T/err" && ok || bad "$what: went on to render"
}

stopped "render, SIGINT" INT "$T/out.png.franja-job" "$F" render "$T/big.json" -o "$T/out.png"
check "render, SIGINT: no job directory left" test ! -e "$T/out.png.franja-job"
check "render, SIGINT: no image" test ! -e "$T/out.png"

stopped "render, SIGTERM" TERM "$T/out.exr.franja-job" "$F" render "$T/big.json" -o "$T/out.exr"
check "render, SIGTERM: no job directory left" test ! -e "$T/out.exr.franja-job"

stopped "compile, SIGINT" INT "$T" "$F" compile "$T/big.json" -o "$T/part.fbin"
check "compile, SIGINT: no scene written" test ! -e "$T/part.fbin"
cp "$T/full.fbin" "$T/keep.fbin"
stopped "compile, SIGTERM" TERM "$T" "$F" compile "$T/big.json" -o "$T/full.fbin"
check "compile, SIGTERM: the older scene is left as it was" cmp -s "$T/full.fbin" "$T/keep.fbin"
left=$(ls -A "$T" | grep -v -e '^big\.' -e '^full\.fbin$' -e '^keep\.fbin$' -e '^out$' -e '^err$')
[ -z "$left" ] && ok || bad "left behind: $left"
# SIGKILL, which franja cannot catch: the compiling child ends with it
# (it must not go on compiling, nor keep the job lock it inherited), so a
# second render of the same image starts at once.
compiling_child() { # the pid of franja's compiling child, once there is one
    for c in $(pgrep -P "$1" 2>/dev/null); do
        [ "$(cat /proc/"$c"/comm 2>/dev/null)" = franja ] && { echo "$c"; return 0; }
    done
    return 1
}
"$F" render "$T/big.json" -o "$T/k.png" >"$T/out" 2>"$T/err" &
pid=$!
i=0
while [ $i -lt 600 ] && ! child=$(compiling_child $pid); do sleep 0.05; i=$((i + 1)); done
if [ -z "$child" ]; then
    bad "render, SIGKILL: never seen compiling"
    kill -KILL $pid 2>/dev/null
else
    until_compiling "$T/k.png.franja-job" && ok || bad "render, SIGKILL: no private compile directory"
    kill -KILL $pid
    t0=$(secs)
    i=0
    # Gone means no longer running: a zombie waits for a late reaper.
    running() { [ -r /proc/"$1"/stat ] && ! grep -Eq '^[0-9]+ \(.*\) [ZX] ' /proc/"$1"/stat; }
    while [ $i -lt 100 ] && running "$child"; do sleep 0.05; i=$((i + 1)); done
    took=$(elapsed "$t0")
    ! running "$child" && ok || bad "render, SIGKILL: the compiling child $child is still running $took s later"
    less "$took" 1.5 && ok || bad "render, SIGKILL: the compiling child ended $took s after its parent"
    # Its private directory is what a SIGKILL leaves; the next render of
    # the image, holding the lock, removes it.
    stale=$(ls -A "$T/k.png.franja-job" | grep '\.compile-')
    [ -n "$stale" ] && ok || bad "render, SIGKILL: no private compile directory left to sweep"
    # A second render of the same image takes the job lock and compiles.
    "$F" render "$T/big.json" -o "$T/k.png" >"$T/out2" 2>"$T/err2" &
    pid2=$!
    i=0
    while [ $i -lt 600 ] && ! compiling_child $pid2 >/dev/null && kill -0 $pid2 2>/dev/null; do
        sleep 0.05
        i=$((i + 1))
    done
    compiling_child $pid2 >/dev/null && ok || bad "render after SIGKILL: not compiling: $(cat "$T/err2")"
    ! grep -q "being rendered by another franja" "$T/err2" && ok || bad "render after SIGKILL: $(cat "$T/err2")"
    [ -n "$stale" ] && [ ! -e "$T/k.png.franja-job/$stale" ] && ok ||
        bad "render after SIGKILL: the killed compile's directory $stale is still there"
    kill -INT $pid2 2>/dev/null
    wait $pid2
fi
wait $pid 2>/dev/null
rm -rf "$T/k.png.franja-job" "$T/out2" "$T/err2"
# A scene that fails to compile leaves no job directory either.
printf '{"image": {"width": 8, "height": 8, "spp": 1},\n "camera": 3}\n' >"$T/bad.json"
expect_error "render of a scene that fails to parse" "bad.json: camera: missing or not an object" "$F" render "$T/bad.json" -o "$T/bad.png"
check "a failed parse leaves no job directory" test ! -e "$T/bad.png.franja-job"
rm -f "$T/bad.json"
sleep 0.2
[ -z "$(pgrep -f "$T/big.json")" ] && ok || bad "a compiling process outlived the interruption"

summary
