#!/bin/sh
# build-in-image.sh -- builds the workers and franja inside a Dockerfile image.
#
# build-in-image.sh OUT -- run inside a docker/Dockerfile.* image, in a copy of
# the source tree: builds franja-worker for amd64 (native) and arm64 (Debian's
# cross compiler, against the image's libcjson-dev:arm64), and franja for
# amd64 (with its image plug-in, franja-imageio.so, which it finds beside it)
# when the image has its libraries.  Binaries land in OUT/amd64 and
# OUT/arm64, with BUILDINFO files naming the OS and compiler.
set -eu
out=$1
jobs=$(nproc)
. /etc/os-release

mkdir -p "$out/amd64" "$out/arm64"
make -j"$jobs" B=build/amd64 bin/franja-worker
cp bin/franja-worker "$out/amd64/"
if pkg-config --exists libcjson libssh OpenImageIO assimp; then
    make -j"$jobs" B=build/amd64 bin/franja bin/franja-imageio.so
    cp bin/franja bin/franja-imageio.so "$out/amd64/"
fi
rm -rf bin

# -ffp-contract=off comes with the Makefile's CSTD: without it aarch64 gcc
# fuses multiply-adds and the images differ from amd64's.
make -j"$jobs" B=build/arm64 CC=aarch64-linux-gnu-gcc AR=aarch64-linux-gnu-ar \
    bin/franja-worker
cp bin/franja-worker "$out/arm64/"
rm -rf bin

for arch in amd64 arm64; do
    cc=gcc; [ $arch = arm64 ] && cc=aarch64-linux-gnu-gcc
    printf 'os=%s\nos_version=%s\narch=%s\ncompiler=%s\n' \
        "$VERSION_CODENAME" "$VERSION_ID" "$arch" "$($cc --version | head -n 1)" \
        >"$out/$arch/BUILDINFO"
done
