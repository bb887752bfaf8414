#!/bin/sh
# it_coord_slowhost.sh -- tests hosts slow to be ready hold nobody up.
#
# Hosts that are slow to be ready hold nobody up: slabs start on each host
# as soon as it is ready.  A host that accepts TCP connections and never
# answers (its sshd stopped: the kernel still completes the handshake, as
# for a powered-off machine behind a live switch port, the time-out runs
# out) and a host whose worker's --version hangs (the probe waits three
# time-outs) must not add their time-outs to a render that the healthy
# host finishes in about a second.
. "$(dirname "$0")/support/fakehosts.sh"
fh_init
cd "$FH" || exit 1
SIZE="--size 32x32 --spp 4"
"$FRANJA" compile "$ROOT/scenes/cornell.json" -o scene.fbin 2>/dev/null
"$WORKER" --scene scene.fbin --rows 0:32 $SIZE -o ref.pfm

# The worker of host "stuck" hangs on --version.
mkdir -p "$FH/stuck"
cat >"$FH/stuck/worker.sh" <<SH
#!/bin/sh
case " \$* " in *" --version "*) exec sleep 600 ;; esac
exec "$WORKER" "\$@"
SH
chmod +x "$FH/stuck/worker.sh"

: >hosts
fh_start good 2 2
fh_start mute 3 2
fh_start stuck 4 2 "$FH/stuck/worker.sh"
fh_stop mute
TIMEOUT=8
t0=$(date +%s.%N)
env -u SSH_AUTH_SOCK "$FRANJA" render scene.fbin --known-hosts "$FH/known_hosts" --no-ssh-config \
    --timeout $TIMEOUT --hosts hosts -o out.pfm $SIZE 2>log
rc=$?
took=$(echo "$(date +%s.%N) - $t0" | bc)
check "render succeeds (status $rc: $(tail -n 2 log))" test $rc -eq 0
check "byte-identical" cmp -s out.pfm ref.pfm
check "done in ${took} s, less than the ${TIMEOUT} s time-out" sh -c "echo '$took < $TIMEOUT' | bc | grep -q 1"
check "the healthy host rendered every row" grep -Eq "^  good +2 +[0-9]+ +32 " log
check "the silent host is named as not ready" grep -q "host mute was not ready before the render ended" log
check "the host with a hung --version is named as not ready" grep -q "host stuck was not ready before the render ended" log
fh_cont mute

# A host that becomes ready late still joins: its probe waits 2 s, the
# render on the other (0.4 s a slab) takes longer than that, and the late
# one renders rows too.
mkdir -p "$FH/late"
cat >"$FH/late/worker.sh" <<SH
#!/bin/sh
case " \$* " in *" --version "*) sleep 2 ;; esac
exec "$WORKER" "\$@"
SH
chmod +x "$FH/late/worker.sh"
: >hosts
mkdir -p "$FH/slow"
fh_start slow 5 1 "$(fh_wrapper slow slow)"
fh_start late 6 1 "$FH/late/worker.sh"
fr render scene.fbin -o late.pfm --hosts hosts $SIZE --slab-rows 1 2>logl
rc=$?
check "late host: render succeeds (status $rc)" test $rc -eq 0
check "late host: byte-identical" cmp -s late.pfm ref.pfm
check "late host: it joined and rendered rows" grep -Eq "^  late +1 +[1-9]" logl
check "late host: the first host rendered rows too" grep -Eq "^  slow +1 +[1-9]" logl

summary
