#!/bin/sh
# Hostile and broken workers on fake SSH hosts: each render still finishes
# on the healthy host, in bounded time, byte-identical to the one-process
# render.
. "$(dirname "$0")/coord/fakehosts.sh"
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

summary
