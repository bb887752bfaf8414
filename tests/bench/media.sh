#!/bin/sh
# media.sh -- measures equiangular + MIS against distance sampling in fog.
#
# Participating media: equiangular + MIS against distance sampling alone on
# the foggy room (point light in fog), at equal samples per pixel, each
# against a high-sample reference; one thread.
cd "$(dirname "$0")/../.." || exit 1
echo "== media: equiangular sampling (Kulla & Fajardo 2012) + MIS vs distance sampling alone"
echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'), load $(cut -d' ' -f1-3 /proc/loadavg)"
echo "reproduce: bin/bench/media scenes/fog-room.json --size 64 --spp 32 --ref-spp 1024"
bin/bench/media scenes/fog-room.json --size 64 --spp 32 --ref-spp 1024
