#!/bin/sh
# base-image.sh -- makes a missing debian:SUITE base image with debootstrap.
#
# base-image.sh SUITE... -- give the Docker engine the base image debian:SUITE
# when it has none, built from Debian's repository with debootstrap (for
# machines that reach Debian's mirror but no image registry).  An engine that
# already has debian:SUITE (pulled or imported) is left alone.
#
# The minbase root of each suite is cached as a tarball under
# $FRANJA_CACHE/debootstrap (default /var/cache/franja) so later runs skip
# debootstrap; delete the tarball to refresh it.  Needs root and debootstrap.
# Environment: DOCKER (client, default docker), FRANJA_CACHE,
# FRANJA_DEBIAN_MIRROR (default http://deb.debian.org/debian).
set -eu
DOCKER=${DOCKER:-docker}
CACHE=${FRANJA_CACHE:-/var/cache/franja}/debootstrap
MIRROR=${FRANJA_DEBIAN_MIRROR:-http://deb.debian.org/debian}

[ $# -gt 0 ] || { echo "usage: $0 SUITE..." >&2; exit 2; }
mkdir -p "$CACHE"
for suite in "$@"; do
    if $DOCKER image inspect "debian:$suite" >/dev/null 2>&1; then
        continue
    fi
    tarball="$CACHE/$suite.tar"
    if [ ! -s "$tarball" ]; then
        # Build under a temporary name and rename, so an interrupted run never
        # leaves a truncated root behind.
        tmp=$(mktemp -d "$CACHE/$suite.XXXXXX")
        echo "base-image: debootstrap --variant=minbase $suite" >&2
        if ! debootstrap --variant=minbase "$suite" "$tmp/root" "$MIRROR" \
                >"$tmp/log" 2>&1; then
            tail -n 20 "$tmp/log" >&2
            rm -rf "$tmp"
            echo "base-image: debootstrap of $suite failed" >&2
            exit 1
        fi
        # Keep the image free of the host's resolver settings and apt lists.
        rm -rf "$tmp/root/var/lib/apt/lists/"* "$tmp/root/var/cache/apt/"*.bin
        : >"$tmp/root/etc/resolv.conf"
        tar -C "$tmp/root" --numeric-owner -cf "$tmp/root.tar" .
        mv "$tmp/root.tar" "$tarball"
        rm -rf "$tmp"
    fi
    echo "base-image: docker import debian:$suite" >&2
    $DOCKER import --change 'CMD ["bash"]' "$tarball" "debian:$suite" >/dev/null
done
