#!/bin/sh
# install-deps.sh -- installs the Debian packages to build, test and benchmark.
#
# Install the Debian 12 packages Franja needs to build, test and cross-build
# (make deps), Blender among them: the tests open render passes in its
# compositor and export animations with its glTF exporter (which needs
# numpy), and Cycles, which the benchmarks and references compare with.
# Idempotent; run as root.  Edit only the package lists.
set -e
export DEBIAN_FRONTEND=noninteractive
apt-get update
apt-get install -y --no-install-recommends \
    build-essential pkg-config \
    libcjson-dev libxxhash-dev libzstd-dev zstd libassimp-dev libembree-dev clang libclang-rt-14-dev \
    libssh-dev libmicrohttpd-dev libopenimageio-dev openimageio-tools assimp-testmodels \
    openssh-server openssh-client iproute2 procps doxygen pandoc man-db groff-base jq chromium curl \
    libfuse3-dev fuse3 time python3 \
    slurmctld slurmd slurm-client munge \
    docker.io debootstrap qemu-user-static \
    gcc-aarch64-linux-gnu libc6-dev-arm64-cross \
    blender python3-numpy
