#!/bin/sh
# it_40_deploy.sh -- tests franja deploy puts the matching build on each host.
#
# franja deploy over fake SSH hosts (tests/support/fakehosts.sh): each host gets
# the build that matches the os= and arch= of its table line, or what it
# reports, falling back to the static build; the installed worker is checked
# through the host's worker command (qemu for the arm64 hosts), and the
# deployed cluster renders the one-process image.  A host with no build, a
# build of another version and a missing dist directory are refused.
. "$(dirname "$0")/lib.sh"
cross_fakehosts
SIZE="--size 64x64 --spp 4"
SYSROOT="$CROSS/sysroot-bookworm-arm64"

# A dist directory with some builds only, so that the fallback is exercised.
mkdir -p dist/bullseye-amd64 dist/bookworm-arm64 dist/static-amd64 dist/static-arm64
cp "$CROSS/dist/bullseye-amd64/franja-worker" dist/bullseye-amd64/
cp "$CROSS/dist/bookworm-arm64/franja-worker" dist/bookworm-arm64/
cp "$ROOT/bin/static/amd64/franja-worker" dist/static-amd64/
cp "$ROOT/bin/static/arm64/franja-worker" dist/static-arm64/
check "builds from the Docker and static tests present" \
    test -s dist/bullseye-amd64/franja-worker -a -s dist/bookworm-arm64/franja-worker \
         -a -s dist/static-amd64/franja-worker -a -s dist/static-arm64/franja-worker

# Hosts: d1 declares Debian 11 on x86_64; d2 Debian 12 on aarch64 and d3 an
# OS without a build on aarch64 (both run their work directory's worker
# under qemu); d4 declares nothing (the host reports this machine).
fh_start d1 2 1
fh_start d2 3 1
fh_start d3 4 1
fh_start d4 5 1
qemu=$(command -v "$QEMU")
printf '#!/bin/sh\nexec %s -L %s %s/d2/work/franja-worker "$@"\n' "$qemu" "$SYSROOT" "$FH" >d2/qemu.sh
printf '#!/bin/sh\nexec %s %s/d3/work/franja-worker "$@"\n' "$qemu" "$FH" >d3/qemu.sh
chmod +x d2/qemu.sh d3/qemu.sh
# The table fh_start wrote, with os=/arch= and without worker= where the
# default (WORKDIR/franja-worker) is meant.
sed -e 's/ worker=[^ ]*$//' \
    -e '/^d1 /s/$/ os=bullseye arch=x86_64/' \
    -e "/^d2 /s|\$| os=bookworm arch=aarch64 worker=$FH/d2/qemu.sh|" \
    -e "/^d3 /s|\$| os=sid arch=aarch64 worker=$FH/d3/qemu.sh|" hosts >deploy.hosts
echo "here local - 1" >>deploy.hosts

fr deploy --hosts deploy.hosts --dist dist >out 2>err
check "deploy succeeds" test $? -eq 0
VERSION=$("$WORKER" --version)
check "d1 gets the Debian 11 amd64 build" grep -q "^d1: bullseye-amd64 -> .*: $VERSION" out
check "d2 gets the Debian 12 arm64 build" grep -q "^d2: bookworm-arm64 -> .*: $VERSION" out
check "d3 (no build for its OS) gets the static arm64 build" grep -q "^d3: static-arm64 -> .*: $VERSION" out
check "d4 (OS reported, no build) gets the static amd64 build" grep -q "^d4: static-amd64 -> .*: $VERSION" out
check "the local host is skipped" grep -q "^here: local host" out
check "summary" grep -q "^deployed to 4 of 4 SSH hosts" out
check "d2's mismatch of declared and real arch is noted" grep -q "^d2: .*the table says arch=aarch64" out
for pair in d1:bullseye-amd64 d2:bookworm-arm64 d3:static-arm64 d4:static-amd64; do
    h=${pair%%:*} b=${pair#*:}
    check "$h/work/franja-worker is the $b build" cmp -s "$h/work/franja-worker" "dist/$b/franja-worker"
    check "$h/work/franja-worker is executable" test -x "$h/work/franja-worker"
done
check "no temporary file left" test -z "$(ls d1/work d2/work d3/work d4/work | grep part)"

# The deployed cluster renders the one-process image.
"$FRANJA" compile "$ROOT/scenes/cornell.json" -o scene.fbin 2>/dev/null
"$WORKER" --scene scene.fbin --rows 0:64 $SIZE -o ref.pfm
grep -v '^here ' deploy.hosts >render.hosts
fr render scene.fbin -o out.pfm --hosts render.hosts $SIZE --slab-rows 4 2>log
check "render on the deployed hosts is byte-identical to the one-process render" cmp -s out.pfm ref.pfm

# Deploying again replaces the installed workers.
fr deploy --hosts deploy.hosts --dist dist >out2 2>&1
check "a second deploy replaces the workers" grep -q "^deployed to 4 of 4 SSH hosts" out2

# A host for which there is no build.
printf 'r1 %s arch=riscv64\n' "$(grep '^d4 ' hosts | cut -d' ' -f2-6)" >riscv.hosts
fr deploy --hosts riscv.hosts --dist dist >out3 2>&1
check "a host without a build fails the deploy" test $? -eq 1
check "and says which builds were looked for" grep -q "^r1: FAILED: .*static-riscv64" out3

# A build that reports another version is installed but refused.
mkdir -p bad/static-amd64
printf '#!/bin/sh\necho "franja-worker 0.0.1 scene-format 1"\n' >bad/static-amd64/franja-worker
fr deploy --hosts riscv.hosts --dist bad >/dev/null 2>&1
grep '^d4 ' deploy.hosts >d4.hosts
fr deploy --hosts d4.hosts --dist bad >out4 2>&1
check "a worker of another version fails the deploy" test $? -eq 1
check "and the message names the host and both versions" \
    grep -q "^d4: FAILED: .*'franja-worker 0.0.1 scene-format 1', not '$VERSION'" out4

fr deploy --hosts deploy.hosts --dist "$FH/nowhere" >/dev/null 2>out5
check "a missing dist directory is a usage error" test $? -eq 2
check "and says so" grep -q "nowhere: not a directory" out5
summary
