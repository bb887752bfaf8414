#!/bin/sh
# it_30_cluster.sh -- tests a mixed-architecture fake cluster renders alike.
#
# A mixed cluster of fake SSH hosts (tests/support/fakehosts.sh): host "arm"
# runs the static arm64 worker under qemu, "old" the Debian 11 amd64 build and
# "armdeb" the Debian 12 arm64 build under qemu against that release's own
# arm64 libraries.  The stitched image must be byte-identical to the
# one-process amd64 render, every host must have rendered slabs, and a host
# whose worker reports another version is left out by name while the others
# render.  The Docker builds
# come from it_20_docker.sh (in $CROSS).
. "$(dirname "$0")/lib.sh"
cross_fakehosts
SIZE="--size 64x64 --spp 4"

OLD="$CROSS/dist/bullseye-amd64/franja-worker"
ARMDEB="$CROSS/dist/bookworm-arm64/franja-worker"
SYSROOT="$CROSS/sysroot-bookworm-arm64"
for f in "$OLD" "$ARMDEB" "$SYSROOT/lib/ld-linux-aarch64.so.1"; do
    check "Docker build output $f present (run by it_20_docker.sh)" test -e "$f"
done

# Worker commands for the fake hosts: qemu runs the arm64 binaries (this
# machine has no binfmt_misc), with -L giving the dynamic one its OS's libs.
cat >"$FH/worker-arm.sh" <<SH
#!/bin/sh
exec "$(command -v "$QEMU")" "$ROOT/bin/static/arm64/franja-worker" "\$@"
SH
cat >"$FH/worker-armdeb.sh" <<SH
#!/bin/sh
exec "$(command -v "$QEMU")" -L "$SYSROOT" "$ARMDEB" "\$@"
SH
# The native host is slowed down so that the qemu hosts, several times
# slower, still win slabs (the first valid copy of a slab counts).
cat >"$FH/worker-old.sh" <<SH
#!/bin/sh
case " \$* " in *" --rows "*) sleep 0.4 ;; esac
exec "$OLD" "\$@"
SH
chmod +x "$FH/worker-arm.sh" "$FH/worker-armdeb.sh" "$FH/worker-old.sh"

# The reference: the whole image by one amd64 worker process.
"$FRANJA" compile "$ROOT/scenes/cornell.json" -o scene.fbin
check "scene compiles" test -s scene.fbin
"$WORKER" --scene scene.fbin --rows 0:64 $SIZE -o ref.pfm
check "one-process reference renders" test -s ref.pfm

fh_start arm 2 1 "$FH/worker-arm.sh"
fh_start old 3 1 "$FH/worker-old.sh"
fh_start armdeb 4 1 "$FH/worker-armdeb.sh"

fr hosts check --hosts hosts >check.out 2>&1
check "hosts check passes for the mixed cluster" test $? -eq 0
check "every host reports the same worker version" \
    test "$(grep -cF "$("$WORKER" --version | head -n 1)" check.out)" -eq 3

# 16 slabs of 4 rows over 3 single-slot hosts: every host gets work.
fr render scene.fbin -o out.pfm --hosts hosts $SIZE --slab-rows 4 2>log
check "mixed-cluster render succeeds" test $? -eq 0
check "mixed-cluster image is byte-identical to the one-process render" cmp out.pfm ref.pfm
for h in arm old armdeb; do
    check "$h rendered slabs" grep -Eq "^  $h +[0-9]+ +[1-9]" log
done

# A worker of another version, then one of another scene format, joins: the
# coordinator does not mix them: that host is left out, naming it and its
# version, and the others render the same image.
REAL=$("$WORKER" --version | head -n 1)
for bad in "$(echo "$REAL" | sed 's/^franja-worker [^ ]*/franja-worker 0.0.1/')" \
           "$(echo "$REAL" | sed 's/scene-format .*/scene-format 999/')"; do
    cat >"$FH/worker-other.sh" <<SH
#!/bin/sh
case "\$1" in --version) echo "$bad"; exit 0 ;; esac
exec "$WORKER" "\$@"
SH
    chmod +x "$FH/worker-other.sh"
    case " $FH_HOSTS " in *" other "*) ;; *) fh_start other 5 1 "$FH/worker-other.sh" ;; esac
    rm -f out2.pfm
    fr render scene.fbin -o out2.pfm --hosts hosts $SIZE 2>log2
    check "render beside a worker reporting '$bad' succeeds" test $? -eq 0
    check "and is byte-identical" cmp -s out2.pfm ref.pfm
    check "the host left out is named with its version" grep -q "host other is not used: its worker reports '$bad'" log2
    check "and rendered nothing" sh -c '! grep -Eq "^  other +[0-9]+ +[1-9]" log2'
done
summary
