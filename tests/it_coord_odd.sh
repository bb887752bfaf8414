#!/bin/sh
# it_coord_odd.sh -- tests odd hosts are left out or tamed, with a message.
#
# Odd hosts on fake SSH hosts: each is left out or tamed, with a message,
# and the render ends on the others, byte-identical to the one-process
# render.  An absurd processor count (clamped), a worker of another version
# (that host dropped, not the render), escape sequences in a worker's
# stderr and version line (never reach the terminal), a work directory the
# login may not create (the mkdir's own error), and `franja deploy` to a
# host whose uname -m is a path (refused).
. "$(dirname "$0")/support/fakehosts.sh"
fh_init
cd "$FH" || exit 1
SIZE="--size 32x32 --spp 4"
"$FRANJA" compile "$ROOT/scenes/cornell.json" -o scene.fbin 2>/dev/null
"$WORKER" --scene scene.fbin --rows 0:32 $SIZE -o ref.pfm
ESC=$(printf '\033')
BEL=$(printf '\007')

# A worker wrapper for host NAME: BODY runs for --version (VERSION) or for
# slabs (ROWS); everything else goes to the real worker.  Prints its path.
wrap() {
    name=$1 when=$2 body=$3 w="$FH/$1/worker.sh"
    mkdir -p "$FH/$1"
    cat >"$w" <<SH
#!/bin/sh
case " \$* " in *" $when "*) $body ;; esac
exec "$WORKER" "\$@"
SH
    chmod +x "$w"
    echo "$w"
}

# A host that says it has 2000000000 processors (GNU nproc believes
# OMP_NUM_THREADS), with cores=auto in the table.
: >hosts
FH_SSHD_EXTRA="SetEnv SHLVL=1 OMP_NUM_THREADS=2000000000" fh_start many 2 auto
fr render scene.fbin -o many.pfm --hosts hosts -j 2 $SIZE 2>logm
rc=$?
check "absurd core count: render succeeds (status $rc)" test $rc -eq 0
check "absurd core count: byte-identical" cmp -s many.pfm ref.pfm
check "absurd core count: clamped with a message" grep -q "host many reports 2000000000 processors; using 4096" logm

# A host whose worker is another version, beside a good one.
: >hosts
fh_start old 3 2 "$(wrap old --version 'echo "franja-worker 0.0.1-old scene-format 1"; exit 0')"
fh_start good 4 2
fr render scene.fbin -o ver.pfm --hosts hosts $SIZE 2>logv
rc=$?
check "other version: render succeeds (status $rc)" test $rc -eq 0
check "other version: byte-identical" cmp -s ver.pfm ref.pfm
check "other version: that host is left out, naming both versions" \
    grep -q "host old is not used: its worker reports 'franja-worker 0.0.1-old scene-format 1', this franja needs" logv
check "other version: the good host rendered" grep -q "^  good .* ok" logv

# Escape sequences from a host: in a failing worker's stderr, and in a
# version line.
: >hosts
fh_start loud 5 1 "$(wrap loud --rows 'printf "\\033[2J\\033]0;owned\\007boom\\n" >&2; exit 1')"
fh_start vt 6 1 "$(wrap vt --version 'printf "franja-worker \\033[31m9 scene-format 1\\n"; exit 0')"
fh_start good2 7 1
fr render scene.fbin -o esc.pfm --hosts hosts $SIZE 2>loge
rc=$?
check "escape sequences: render succeeds (status $rc)" test $rc -eq 0
check "escape sequences: byte-identical" cmp -s esc.pfm ref.pfm
check "escape sequences: the worker's message is reported" grep -q "failed on loud .*boom" loge
check "escape sequences: the odd version is reported" grep -q "host vt is not used: .*franja-worker ?\[31m9" loge
check "escape sequences: no ESC or BEL byte reaches stderr" sh -c "! grep -q '[$ESC$BEL]' loge"

# A work directory the login may not create: the mkdir's error is kept.
# As root, a throwaway ordinary user logs in (root may create anything).
: >hosts
if [ "$(id -u)" -eq 0 ]; then
    LT=franjaod$$
    trap 'fh_cleanup; [ -n "${LT_MADE:-}" ] && userdel "$LT" 2>/dev/null' EXIT
    if useradd -M -d "$FH" -s /bin/sh -p '*' "$LT" 2>useradd.err; then
        LT_MADE=1
        saved=$FH_USER
        FH_USER=$LT
        # A worker the throwaway user can reach wherever the checkout is.
        mkdir -p "$FH/bin" && cp "$WORKER" "$FH/bin/" && chmod 755 "$FH/bin" "$FH/bin/franja-worker"
        fh_start denied 8 1 "$FH/bin/franja-worker"
        FH_USER=$saved
    else
        bad "cannot create a throwaway user: $(cat useradd.err)"
    fi
else
    fh_start denied 8 1
fi
sed -i "s|workdir=[^ ]*|workdir=/root/franja-denied-$$/w|" hosts
fh_start good3 9 1
fr render scene.fbin -o den.pfm --hosts hosts $SIZE 2>logd
rc=$?
check "unwritable work dir: render succeeds (status $rc)" test $rc -eq 0
check "unwritable work dir: byte-identical" cmp -s den.pfm ref.pfm
check "unwritable work dir: the mkdir's error is reported" \
    grep -q "host denied is not used: .*mkdir /root/franja-denied-$$: permission denied" logd
check "unwritable work dir: nothing created" test ! -e "/root/franja-denied-$$"

# franja deploy to a host whose uname -m is a path out of the dist
# directory (a uname of its own first in the PATH sshd gives).
mkdir -p evilbin dist/static-x evil
printf '#!/bin/sh\n[ "$1" = -m ] && { echo "x/../../evil"; exit 0; }\nexec /bin/uname "$@"\n' >evilbin/uname
chmod +x evilbin/uname
cp "$WORKER" evil/franja-worker
: >hosts
FH_SSHD_EXTRA="SetEnv SHLVL=1 PATH=$FH/evilbin:/usr/bin:/bin" fh_start odd 10 1
fr deploy --hosts hosts --dist "$FH/dist" >logy 2>&1
rc=$?
check "deploy, uname -m a path: fails (status $rc)" test $rc -ne 0
check "deploy, uname -m a path: refused as not a plain name" grep -q "architecture 'x/../../evil' it reports is not a plain name" logy
check "deploy, uname -m a path: nothing installed" test ! -e "$FH/odd/work/franja-worker"

summary
