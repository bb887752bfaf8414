#!/bin/sh
# it_coord_netns.sh -- tests a host whose link goes silent is dropped.
#
# A link that goes silent: one fake host lives in its own network namespace
# behind a veth pair; mid-render the veth is taken down, so packets vanish
# without any reset.  The coordinator notices the silence (keepalive
# requests go unanswered), drops the host, re-runs its slabs elsewhere and
# still writes a byte-identical image.  Needs root (network namespaces).
. "$(dirname "$0")/support/fakehosts.sh"
if [ "$(id -u)" != 0 ] || ! command -v ip >/dev/null; then
    echo "FAIL: network namespaces need root and iproute2 (tests/install-deps.sh)"
    echo "0 passed, 1 failed"
    exit 1
fi
fh_init
cd "$FH" || exit 1
NS=franja-fh-$$
VH=frh$$
VN=frn$$
NET=10.213.$(($$ % 250))
netns_cleanup() {
    fh_cleanup
    ip link del "$VH" 2>/dev/null
    ip netns del "$NS" 2>/dev/null
}
trap netns_cleanup EXIT
ip netns add "$NS" &&
    ip link add "$VH" type veth peer name "$VN" &&
    ip link set "$VN" netns "$NS" &&
    ip addr add "$NET.1/30" dev "$VH" &&
    ip link set "$VH" up &&
    ip netns exec "$NS" ip addr add "$NET.2/30" dev "$VN" &&
    ip netns exec "$NS" ip link set "$VN" up &&
    ip netns exec "$NS" ip link set lo up
check "namespace and veth pair set up" test $? -eq 0

SIZE="--size 32x32 --spp 4"
"$FRANJA" render "$ROOT/scenes/cornell.json" -o local.pfm $SIZE --job job0 --keep-job 2>/dev/null
cp job0/scene.fbin scene.fbin
"$WORKER" --scene scene.fbin --rows 0:32 $SIZE -o ref.pfm

mkdir -p near far
fh_start near 2 2 "$(fh_wrapper near slow)"
FH_ADDR=$NET.2 FH_NETNS=$NS fh_start far 3 2 "$(fh_wrapper far slow)"
fr render scene.fbin -o both.pfm --hosts hosts $SIZE 2>log0
check "render across the veth works" cmp -s both.pfm ref.pfm
check "the far host took slabs" grep -Eq "^  far +2 +[1-9]" log0

fr_bg render scene.fbin -o cut.pfm --hosts hosts $SIZE --slab-rows 1 2>logc
fh_until fh_busy far
ip link set "$VH" down
t0=$(date +%s)
fr_wait
check "render with a cut link succeeds" test $rc -eq 0
check "render with a cut link is byte-identical" cmp -s cut.pfm ref.pfm
check "the silent host is dropped" grep -q "dropping host far: .*no answer for" logc
check "the silence is noticed within a few time-outs" test $(($(date +%s) - t0)) -lt 20

summary
