#!/bin/sh
# it_cache.sh -- tests the SSH hosts' scene cache stays within its bound.
#
# The scene cache of SSH hosts stays bounded: with cache=SIZE
# in the host table, staging a scene removes the least recently used ones
# until the cache fits, keeping the scene just used, any scene a running
# worker has mapped and any scene a live render holds a lease on (between
# its slabs, when no worker has it mapped); a lease left by a render that
# died goes stale; `franja hosts clean` empties the cache (scenes in use
# stay) and removes cut-off uploads; a bad cache= is refused with its line.
. "$(dirname "$0")/support/fakehosts.sh"
fh_init
cd "$FH" || exit 1
SIZE="--size 16x12 --spp 1"

# Three scenes of the same size (a sphere in three places).
for i in 1 2 3; do
    sed "/\"shapes\": \[/a { \"type\": \"sphere\", \"center\": [$((100 * i + 150)), 100, 300], \"radius\": 80, \"material\": \"white\" }," \
        "$ROOT/scenes/cornell.json" >"s$i.json"
    "$FRANJA" compile "s$i.json" -o "s$i.fbin" >/dev/null 2>&1 || bad "compile s$i failed"
    eval "H$i=\$(\"\$WORKER\" --scene s$i.fbin --check)"
done
B=$(wc -c <s1.fbin)
check "the scenes are the same size" test "$(wc -c <s3.fbin)" -eq "$B"

fh_start a 2 1
# Room for two scenes and a half.
LIMIT=$((B * 5 / 2))
sed "s/\$/ cache=$LIMIT/" hosts >hosts.lim
C=a/work/scenes
fr render s1.fbin -o o1.pfm --hosts hosts.lim $SIZE 2>log1 && ok || bad "render s1: $(cat log1)"
sleep 1.1
fr render s2.fbin -o o2.pfm --hosts hosts.lim $SIZE 2>log2 && ok || bad "render s2: $(cat log2)"
check "two scenes fit" test -f "$C/$H1.fbin" -a -f "$C/$H2.fbin"
sleep 1.1
# s1 used again: now s2 is the least recently used.
fr render s1.fbin -o o1b.pfm --hosts hosts.lim $SIZE 2>log1b
check "s1 comes from the cache" grep -q "scene already there" log1b
sleep 1.1
fr render s3.fbin -o o3.pfm --hosts hosts.lim $SIZE 2>log3 && ok || bad "render s3: $(cat log3)"
check "the least recently used scene (s2) was removed" test ! -e "$C/$H2.fbin"
check "the most recently used one (s1) stays" test -f "$C/$H1.fbin"
check "the scene just staged (s3) stays" test -f "$C/$H3.fbin"
total=$(cat "$C"/*.fbin | wc -c)
check "the cache ($total bytes) is within its limit ($LIMIT)" test "$total" -le "$LIMIT"
check "the removal is said" grep -q "scene cache over its limit ($LIMIT B\\|[0-9.]* KiB): removed 1 least recently used scene ($B B\\|[0-9.]* KiB)" log3
"$FRANJA" render s3.fbin -o o3b.pfm $SIZE 2>/dev/null
check "the render after the removal is right" cmp -s o3.pfm o3b.pfm

# A limit smaller than one scene keeps the scene being staged.
sed "s/\$/ cache=1K/" hosts >hosts.tiny
fr render s2.fbin -o o2b.pfm --hosts hosts.tiny $SIZE 2>log4 && ok || bad "render s2 with cache=1K: $(cat log4)"
check "a tiny cache keeps the scene in use" test -f "$C/$H2.fbin"
check "a tiny cache removed the others" test "$(ls "$C" | grep -c '\.fbin$')" -eq 1

# A scene mapped by a running worker is never removed.
fr render s1.fbin -o o1c.pfm --hosts hosts.lim $SIZE 2>/dev/null
"$WORKER" --scene "$C/$H1.fbin" --rows 0:12 --size 16x12 --spp 1000000 -o /dev/null &
WPID=$!
fh_until grep -q "$H1.fbin" /proc/$WPID/maps
fr render s3.fbin -o o3c.pfm --hosts hosts.tiny $SIZE 2>log5 && ok || bad "render s3 with cache=1K: $(cat log5)"
check "a scene a worker has mapped stays" test -f "$C/$H1.fbin"
check "the unmapped older scene went" test ! -e "$C/$H2.fbin"

# hosts clean: scenes go (not the one in use), cut-off uploads go, a fresh one stays.
: >"$C/$H3.fbin.part-1-2"
touch -d '2000-01-01' "$C/$H3.fbin.part-1-2"
: >"$C/.check-old"
touch -d '2000-01-01' "$C/.check-old"
: >"$C/$H2.fbin.part-3-4"
fr hosts clean --hosts hosts >clean1 2>&1
check "hosts clean succeeds" test $? -eq 0
check "hosts clean keeps the scene in use" test -f "$C/$H1.fbin"
check "hosts clean removes the others" test ! -e "$C/$H3.fbin"
check "hosts clean says what it did" grep -Eq "^a +ok +removed 1 scene .*2 temporary files; kept 1 in use" clean1
check "hosts clean removes a stale upload" test ! -e "$C/$H3.fbin.part-1-2"
check "hosts clean removes a stale check file" test ! -e "$C/.check-old"
check "hosts clean keeps an upload in progress" test -e "$C/$H2.fbin.part-3-4"
kill $WPID 2>/dev/null
wait $WPID 2>/dev/null
fr hosts clean --hosts hosts >clean2 2>&1
check "a second clean empties the cache" test "$(ls "$C" | grep -c '\.fbin$')" -eq 0
check "a second clean removes the scene no longer in use" grep -Eq "^a +ok +removed 1 scene " clean2
fr hosts clean --hosts hosts >clean3 2>&1
check "cleaning an empty cache is fine" grep -Eq "^a +ok +removed 0 scenes " clean3

# Leases: one changed within ten minutes keeps its scene, an older one (a
# render that died) does not, and goes too.
fr render s1.fbin -o o1d.pfm --hosts hosts.lim $SIZE 2>/dev/null
fr render s2.fbin -o o2d.pfm --hosts hosts.lim $SIZE 2>/dev/null
check "a finished render leaves no lease" sh -c "! ls '$C' | grep -q lease"
: >"$C/$H1.fbin.lease-dead-1-1"
touch -d '20 minutes ago' "$C/$H1.fbin.lease-dead-1-1"
: >"$C/$H2.fbin.lease-live-1-1"
fr render s3.fbin -o o3d.pfm --hosts hosts.tiny $SIZE 2>log6 && ok || bad "render s3 beside leases: $(cat log6)"
check "a scene with a live lease stays" test -f "$C/$H2.fbin"
check "a scene whose lease is stale goes" test ! -e "$C/$H1.fbin"
check "its stale lease goes with it" test ! -e "$C/$H1.fbin.lease-dead-1-1"
fr hosts clean --hosts hosts >clean5 2>&1
check "hosts clean keeps a leased scene" test -f "$C/$H2.fbin"
check "hosts clean counts it in use" grep -Eq "^a +ok +removed 1 scene .*kept 1 in use" clean5
rm -f "$C/$H2.fbin.lease-live-1-1"

# A real render between two slabs: its worker for rows of s1 waits for
# "go" before it starts (so nothing has s1 mapped), while a render of s2
# on the same host, with room for one scene only, trims the cache.  s1
# stays, and the first render ends with the right image.
cat >gate.sh <<SH
#!/bin/sh
case " \$* " in *" --rows "*"$H1.fbin"*|*"$H1.fbin"*" --rows "*)
    : >"$FH/held"
    while [ ! -e "$FH/go" ]; do sleep 0.05; done ;;
esac
exec "$WORKER" "\$@"
SH
chmod +x gate.sh
fh_start g 4 1 "$FH/gate.sh"
G=g/work/scenes
grep '^g ' hosts | sed "s/\$/ cache=1K/" >hosts.g
fr_bg render s1.fbin -o o1g.pfm --hosts hosts.g $SIZE
fh_until test -e held
check "the gated render is between slabs" test -e held
check "it holds a lease on its scene" sh -c "ls '$G' | grep -q '^$H1.fbin.lease-'"
fr render s2.fbin -o o2g.pfm --hosts hosts.g $SIZE 2>log7 && ok || bad "render s2 beside a leased scene: $(cat log7)"
check "the scene of the render between slabs stays" test -f "$G/$H1.fbin"
: >go
fr_wait
check "the render between slabs finishes" test "$rc" -eq 0
check "with the image of s1" cmp -s o1g.pfm o1.pfm
check "and both renders removed their leases" sh -c "! ls '$G' | grep -q lease"
sed -i '/^g /d' hosts

# An unreachable host: status 1 and its reason.
echo "gone 127.0.0.9:9 $FH_USER 1 identity=$FH/client_key workdir=$FH/gone" >>hosts
fr hosts clean --hosts hosts --timeout 1 >clean4 2>&1
check "an unreachable host makes clean fail" test $? -eq 1
check "an unreachable host is named" grep -q "^gone .*FAIL" clean4

# Bad cache= values.
for v in abc 0 10X 5GiBx; do
    printf 'h local - 1 cache=%s\n' "$v" >bad.hosts
    expect_error "cache=$v" "bad.hosts:1: cache='$v': expected a size" "$FRANJA" hosts list --hosts bad.hosts
done
printf 'h local - 1 cache=10GiB\n' >ok.hosts
check "cache=10GiB is a size" sh -c "'$FRANJA' hosts list --hosts ok.hosts >/dev/null"
summary
