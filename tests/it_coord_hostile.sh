#!/bin/sh
# it_coord_hostile.sh -- tests renders survive hostile and broken workers.
#
# Hostile and broken workers on fake SSH hosts: each render still finishes
# on the healthy host, in bounded time, byte-identical to the one-process
# render.
. "$(dirname "$0")/support/fakehosts.sh"
fh_init
cd "$FH" || exit 1
SIZE="--size 32x32 --spp 4"
"$FRANJA" render "$ROOT/scenes/cornell.json" -o local.pfm $SIZE --job job0 --keep-job 2>/dev/null
cp job0/scene.fbin scene.fbin
"$WORKER" --scene scene.fbin --rows 0:32 $SIZE -o ref.pfm

# A worker wrapper for host NAME that runs BODY for every slab (--version
# and --check go to the real worker); prints its path.
hostile() {
    name=$1 body=$2 w="$FH/$1/worker.sh"
    mkdir -p "$FH/$1"
    cat >"$w" <<SH
#!/bin/sh
case " \$* " in *" --rows "*) ;; *) exec "$WORKER" "\$@" ;; esac
$body
SH
    chmod +x "$w"
    echo "$w"
}

# A worker that writes one line to stderr and exits at once, on three of
# four hosts.
: >hosts
for i in 2 3 4; do
    fh_start "oom$i" $i 2 "$(hostile "oom$i" 'echo "cannot allocate memory" >&2; exit 1')"
done
fh_start good 5 2
timeout 30 env -u SSH_AUTH_SOCK "$FRANJA" render scene.fbin --known-hosts "$FH/known_hosts" \
    --no-ssh-config --timeout 3 -o oom.pfm --hosts hosts $SIZE 2>logo
rc=$?
check "stderr line then exit: render ends (no hang)" test $rc -ne 124
check "stderr line then exit: render succeeds" test $rc -eq 0
check "stderr line then exit: byte-identical" cmp -s oom.pfm ref.pfm
check "stderr line then exit: the worker's message is reported" grep -q "cannot allocate memory" logo

# A worker whose partial image is well formed but holds a NaN (or a
# negative value): refused, the host blamed, the rows rendered elsewhere.
# The value goes into the last pixels, before the sample sums that follow
# them (W x rows x 24 bytes, when the header says sums=).
poison() {
    f="$FH/$1/p"
    printf '"%s" "$@" >"%s.$$" || exit 1\n' "$WORKER" "$f"
    printf 'h=$(head -c 300 "%s.$$" | sed -n 2p); s=0\n' "$f"
    printf 'case $h in *" sums="*) s=$(echo "$h" | sed "s/.* rows=\\([0-9]*\\):\\([0-9]*\\) .* size=\\([0-9]*\\)x.*/\\3 * (\\2 - \\1) * 24/") ;; esac\n'
    printf 'printf %s | dd of="%s.$$" bs=1 seek=$(($(stat -c %%s "%s.$$") - $(($s)) - %s)) conv=notrunc 2>/dev/null\n' "'$2'" "$f" "$f" "$3"
    printf 'cat "%s.$$"; rm -f "%s.$$"\n' "$f" "$f"
}
: >hosts
fh_start nan 6 2 "$(hostile nan "$(poison nan '\000\000\300\177' 4)")"
fh_start neg 7 2 "$(hostile neg "$(poison neg '\000\000\200\277' 8)")"
fh_start good2 8 1
timeout 60 env -u SSH_AUTH_SOCK "$FRANJA" render scene.fbin --known-hosts "$FH/known_hosts" \
    --no-ssh-config --timeout 3 -o nan.pfm --hosts hosts $SIZE 2>logn
rc=$?
check "NaN/negative pixels: render succeeds" test $rc -eq 0
check "NaN/negative pixels: byte-identical" cmp -s nan.pfm ref.pfm
check "NaN pixel: partial refused" grep -q "failed on nan .*bad partial image.*not finite" logn
check "negative pixel: partial refused" grep -q "failed on neg .*bad partial image.*negative" logn
check "NaN/negative pixels: hosts blamed and dropped" sh -c 'grep -q "dropping host nan" logn && grep -q "dropping host neg" logn'

# Workers that write without end: on slabs (stdout), and on --version
# (the probe).  Each stream is capped at its expected size, so the
# process fails at once, the render ends on the healthy host and the
# coordinator stays small (its peak resident size is sampled while it runs).
endless() {
    name=$1 w="$FH/$1/worker.sh"
    mkdir -p "$FH/$1"
    printf '#!/bin/sh\ncase " $* " in *" %s "*) exec cat /dev/zero ;; esac\nexec "%s" "$@"\n' "$2" "$WORKER" >"$w"
    chmod +x "$w"
    echo "$w"
}
: >hosts
fh_start flood 9 2 "$(endless flood --rows)"
fh_start chatty 10 2 "$(endless chatty --version)"
fh_start good3 11 1
env -u SSH_AUTH_SOCK timeout 60 "$FRANJA" render scene.fbin --known-hosts "$FH/known_hosts" \
    --no-ssh-config --timeout 3 -o flood.pfm --hosts hosts $SIZE 2>logf &
pid=$!
peak=0
while kill -0 $pid 2>/dev/null; do
    kb=$(awk '/^VmRSS/ {print $2}' /proc/$pid/status 2>/dev/null)
    [ -n "$kb" ] && [ "$kb" -gt "$peak" ] && peak=$kb
    sleep 0.05
done
wait $pid
rc=$?
check "endless output: render succeeds" test $rc -eq 0
check "endless output: byte-identical" cmp -s flood.pfm ref.pfm
check "endless slab output: refused at its size" grep -q "failed on flood .*more than the .* bytes expected" logf
check "endless --version output: host not used" grep -q "host chatty is not used" logf
check "endless output: coordinator under 200 MB resident (peak ${peak} KB)" test "$peak" -lt 204800

summary
