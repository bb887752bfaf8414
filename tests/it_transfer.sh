#!/bin/sh
# it_transfer.sh -- tests that scenes travel to SSH hosts compressed.
#
# Scenes travel to SSH hosts compressed (a packed scene, FORMAT.md "Packed
# scenes") and are unpacked by the host's worker into its cache: the bytes
# sent per host are in the log and the summary and are fewer than the
# .fbin's for a compressible scene, the cached copy is byte-identical to
# the .fbin, no compressed file is left on either side, a damaged
# compressed transfer is refused (its checksum and hash checked by the
# worker) and sent again, then sent uncompressed, a worker that only
# unpacks zstd frames (an older one) gets one, and a worker that cannot
# unpack gets the scene as it is.
. "$(dirname "$0")/support/fakehosts.sh"
fh_init
cd "$FH" || exit 1
SIZE="--size 24x16 --spp 2"

# A textured scene: float texels compress well.
"$FRANJA" compile "$ROOT/scenes/cornell-textured.json" -o scene.fbin >/dev/null 2>&1 || bad "compile"
HASH=$("$WORKER" --scene scene.fbin --check)
FBIN=$(wc -c <scene.fbin)
"$WORKER" --scene scene.fbin --rows 0:16 $SIZE -o ref.pfm

# bytes TEXT: "123 B", "4.5 KiB", "1.2 MiB" as a number of bytes.
bytes() {
    echo "$1" | awk '{ m = $2 == "KiB" ? 1024 : $2 == "MiB" ? 1048576 : $2 == "GiB" ? 1073741824 : 1; printf "%d\n", $1 * m }'
}
# sent LOG HOST: the size the log says was uploaded to HOST, in bytes ("" if none).
sent() {
    t=$(sed -n "s/^franja: host $2: .*scene uploaded (\([0-9.]* [KMG]*i*B\)).*/\1/p" "$1" | head -n 1)
    [ -n "$t" ] && bytes "$t"
}

# Faults on the way: a worker that damages the compressed scene it is
# given to unpack, the first N times.
damaging() {
    mkdir -p "$FH/$1"
    w="$FH/$1/worker-damage.sh"
    cat >"$w" <<SH
#!/bin/sh
if [ "\$1" = --unpack ] && [ "\$(ls "$FH/$1" | grep -c '^damaged-')" -lt $2 ]; then
    mktemp "$FH/$1/damaged-XXXXXX" >/dev/null
    printf 'XXXX' | dd of="\$2" bs=1 seek=2000 conv=notrunc 2>/dev/null
fi
exec "$WORKER" "\$@"
SH
    chmod +x "$w"
    echo "$w"
}
# A worker that cannot unpack (as one built without libzstd).
cat >"$FH/old-worker.sh" <<SH
#!/bin/sh
[ "\$1" = --features ] && { echo; exit 0; }
exec "$WORKER" "\$@"
SH
chmod +x "$FH/old-worker.sh"
# A worker of before packed scenes: it unpacks zstd frames only.
cat >"$FH/zstd-worker.sh" <<SH
#!/bin/sh
[ "\$1" = --features ] && { echo unpack-zstd; exit 0; }
[ "\$1" = --unpack ] && { head -c 4 "\$2" | od -An -tx1 | grep -q '28 b5 2f fd' || { echo "not zstd" >&2; exit 1; }; }
exec "$WORKER" "\$@"
SH
chmod +x "$FH/zstd-worker.sh"

fh_start a 1 2
fh_start b 2 2 "$(damaging b 1)"
fh_start c 3 2 "$(damaging c 2)"
fh_start d 4 2 "$FH/old-worker.sh"
fh_start e 5 2 "$FH/zstd-worker.sh"

# One host a render, so that each is staged whatever the others do.
: >log1
for h in a b c d e; do
    grep "^$h " hosts >"hosts.$h"
    fr render scene.fbin -o "out-$h.pfm" --hosts "hosts.$h" $SIZE 2>"log-$h" && ok || bad "render on $h: $(cat "log-$h")"
    check "$h: the image equals the one-process render" cmp -s "out-$h.pfm" ref.pfm
    check "$h: the cached scene is the .fbin, byte for byte" cmp -s "$h/work/scenes/$HASH.fbin" scene.fbin
    check "$h: no compressed or temporary file is left" test -z "$(ls -A "$h/work/scenes" | grep -v "^$HASH.fbin")"
    cat "log-$h" >>log1
done
s=$(sent log1 a)
check "a: fewer bytes sent ($s) than the .fbin's $FBIN" test -n "$s" -a "${s:-0}" -lt "$FBIN" -a "${s:-0}" -gt 0
check "a: no note of a failed transfer" sh -c "! grep -q 'host a.*did not unpack' log1"
# b: damaged once, refused by the worker's check, sent again compressed.
check "b: the damaged transfer is refused" grep -q "b .*the compressed scene did not unpack (.*damaged packed scene.*); sending it again" log1
s=$(sent log1 b)
check "b: two compressed transfers sent ($s bytes)" test -n "$s" -a "${s:-0}" -lt "$FBIN"
# c: damaged twice: then sent as it is.
check "c: damaged twice" test "$(grep -c "c .*the compressed scene did not unpack" log1)" -eq 2
check "c: then sent uncompressed" grep -q "c .*sending the scene uncompressed" log1
s=$(sent log1 c)
check "c: the bytes sent count every attempt ($s)" test -n "$s" -a "${s:-0}" -gt "$FBIN"
# d: a worker that cannot unpack gets the .fbin as it is.
# As franja writes sizes: KiB, MiB ... with one decimal.
MIB=$(awk -v n="$FBIN" 'BEGIN { v = n / 1024; u = "KiB"; if (v >= 1024) { v /= 1024; u = "MiB" }
    printf "%.1f %s", v, u }')
check "d: the scene sent as it is ($MIB)" grep -q "host d: .*scene uploaded ($MIB)" log1
# The summary has the bytes sent per host.
check "the summary has a sent column" grep -q '^  host .* sent  state' log1
check "the summary says what went to d" grep -Eq "^  d .* $MIB +ok" log1
# e: an older worker gets a zstd frame, bigger than the packed scene.
se=$(sent log1 e)
check "e: a zstd frame sent ($se bytes, packed: $s)" test -n "$se" -a "${se:-0}" -lt "$FBIN" -a "${se:-0}" -gt "$(sent log1 a)"
check "e: no note of a failed transfer" sh -c "! grep -q 'host e.*did not unpack' log1"
check "no compressed copy is left on this machine" test -z "$(ls "${TMPDIR:-/tmp}" | grep "^franja-$HASH-.*\.\(zst\|fpak\)")"

# A second render finds the copy: nothing is sent.
fr render scene.fbin -o out2.pfm --hosts hosts.a $SIZE 2>log2 && ok || bad "render 2: $(cat log2)"
check "nothing sent the second time" grep -q 'host a: .*scene already there' log2
check "the summary says 0 B" grep -Eq '^  a .* 0 B +ok' log2
summary
