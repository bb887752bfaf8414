# Franja -- one entry point: build, test, bench, docs, dist.
#
#   make            bin/franja-worker and bin/franja
#   make deps       install the Debian packages the project needs, Blender too (root)
#   make check      build and run every test
#   make bench      benchmarks (see tests/bench/)
#   make pgo        bin/franja-worker again with profile feedback (same bits, faster)
#   make render     render scenes/cornell.json to cornell.png on this machine
#   make install    bin/, man pages and bash completion under PREFIX (DESTDIR)
#   make docs       the user guide and the API documentation (HTML) in build/docs
#   make refs       the Cycles references in tests/data (needs blender)

CC      ?= cc
CXX     ?= c++
PKG     ?= pkg-config
# The render path must give the same bits on every host: no contraction into
# fused multiply-adds, no fast-math.  -fno-math-errno only lets sqrtf be the
# (exactly rounded) machine instruction.
FPFLAGS  = -ffp-contract=off -fno-math-errno
OPT     ?= -O2
CFLAGS  ?= $(OPT) -g
CSTD     = -std=c17 -D_GNU_SOURCE -Wall -Wextra -Werror -Wno-format-truncation $(FPFLAGS) -Icommon
CXXSTD   = -std=c++17 -Wall -Wextra -Werror $(FPFLAGS) -Icommon

CJSON_CFLAGS := $(shell $(PKG) --cflags libcjson 2>/dev/null)
CJSON_LIBS   := $(shell $(PKG) --libs libcjson 2>/dev/null || echo -lcjson)
SSH_LIBS     := $(shell $(PKG) --libs libssh 2>/dev/null || echo -lssh)
OIIO_CFLAGS  := $(shell $(PKG) --cflags OpenImageIO 2>/dev/null)
OIIO_LIBS    := $(shell $(PKG) --libs OpenImageIO 2>/dev/null)
ASSIMP_LIBS  := $(shell $(PKG) --libs assimp 2>/dev/null || echo -lassimp)
MHD_LIBS     := $(shell $(PKG) --libs libmicrohttpd 2>/dev/null || echo -lmicrohttpd)
ZSTD_LIBS    := $(shell $(PKG) --libs libzstd 2>/dev/null || echo -lzstd)

B = build
COMMON_SRC  = $(wildcard common/*.c common/compile/*.c)
COMMON_OBJ  = $(COMMON_SRC:%.c=$(B)/%.o)
WORKER_SRC  = $(wildcard worker/*.c)
WORKER_OBJ  = $(WORKER_SRC:%.c=$(B)/%.o)
COORD_SRC   = $(wildcard coordinator/*.c coordinator/*/*.c)
COORD_OBJ   = $(COORD_SRC:%.c=$(B)/%.o)
# OpenImageIO's bridge, a plug-in that franja loads when it first reads or
# writes an image other than PFM (coordinator/imageio_load.c).
IIO_PLUGIN  = bin/franja-imageio.so
IIO_OBJ     = $(B)/pic/coordinator/imageio.o $(B)/pic/common/error.o
# The coordinator's modules (all but main.c) as a library that the tests link.
COORD_LIB_OBJ = $(filter-out $(B)/coordinator/main.o,$(COORD_OBJ))
COORD_LIB   = $(B)/libfranja-coord.a
# Test support code (fake backends ...) linked into every test program.
TESTSUP_SRC = $(wildcard tests/support/*.c)
TESTSUP_OBJ = $(TESTSUP_SRC:%.c=$(B)/%.o)
TESTSUP_LIB = $(B)/libfranja-testsup.a
TEST_SRC    = $(wildcard tests/test_*.c)
TEST_BIN    = $(TEST_SRC:tests/%.c=bin/tests/%)
# Test utilities (tests/tools/) and the generators of files the project
# ships (tests/gen/: example meshes, textures, the sky, glTF scenes, the
# microfacet albedo tables), which the tests use too.
TOOL_SRC    = $(wildcard tests/tools/*.c)
TOOL_BIN    = $(TOOL_SRC:tests/tools/%.c=bin/tools/%) $(GEN_BIN)
GEN_SRC     = $(wildcard tests/gen/*.c)
GEN_BIN     = $(GEN_SRC:tests/gen/%.c=bin/gen/%)
BENCH_SRC   = $(wildcard tests/bench/*.c)
BENCH_BIN   = $(BENCH_SRC:tests/bench/%.c=bin/bench/%)
LIB         = $(B)/libfranja.a

WORKER_LIBS = $(CJSON_LIBS) $(ZSTD_LIBS) -lm -pthread
COORD_LIBS  = $(CJSON_LIBS) $(SSH_LIBS) $(ASSIMP_LIBS) $(MHD_LIBS) $(ZSTD_LIBS) -ldl -lm -pthread

.PHONY: all deps check test bench render clean docs guide fuzz static dist check-cross refs install uninstall pgo
all: bin/franja-worker bin/franja $(IIO_PLUGIN)

# The modules a pixel sample runs through are built at -O3 (more inlining
# and unrolling: fewer instructions a sample on the Cornell box,
# tests/bench/README.md, "-O3 on the render path"; the same bits, since
# -ffp-contract=off and no fast-math keep every rounding where the source
# puts it); the rest stays at $(OPT).
HOT_SRC = $(addprefix common/,bsdf.c camera.c envmap.c fmath.c geom.c light.c medium.c microfacet.c motion.c \
          pathtrace.c sampler.c spherical.c texture.c trace.c vertex.c)
# They also carry GCC's intermediate code beside the machine code (fat LTO
# objects), and the two programs are linked with link-time optimisation:
# calls from one of these modules into another (the sampler, the own
# math, a hit point's offset, a light sample) are inlined across files,
# for fewer instructions a sample (tests/bench/README.md, "Link-time optimisation"),
# again the same bits (the link step repeats the floating-point flags).
# Tests, tools and benchmarks link the machine code as before (-fno-lto:
# GCC's linker plugin would otherwise optimise them at link time too,
# slowly, and under their -Werror).
# make LTO= builds without it.
LTO     ?= -flto=auto
LTO_OBJ  = $(if $(LTO),$(LTO) -ffat-lto-objects)
LTO_LINK = $(if $(LTO),$(LTO) $(FPFLAGS))
NO_LTO   = $(if $(LTO),-fno-lto)
# PGO: GCC's profile flags for the render-path modules and the link
# (`make pgo` below sets them; empty otherwise).
PGO     ?=
$(HOT_SRC:%.c=$(B)/%.o): HOT = -O3 $(LTO_OBJ) $(PGO)

$(B)/%.o: %.c
	@mkdir -p $(dir $@)
	$(CC) $(CSTD) $(CFLAGS) $(HOT) $(CJSON_CFLAGS) -MMD -MP -c $< -o $@

$(B)/pic/%.o: %.cpp
	@mkdir -p $(dir $@)
	$(CXX) $(CXXSTD) $(CFLAGS) $(OIIO_CFLAGS) -fPIC -MMD -MP -c $< -o $@

$(B)/pic/%.o: %.c
	@mkdir -p $(dir $@)
	$(CC) $(CSTD) $(CFLAGS) -fPIC -MMD -MP -c $< -o $@

$(IIO_PLUGIN): $(IIO_OBJ)
	@mkdir -p bin
	$(CXX) $(CFLAGS) -shared -Wl,-z,defs -o $@ $(IIO_OBJ) $(OIIO_LIBS) -lstdc++ -lm

$(LIB): $(COMMON_OBJ)
	@mkdir -p $(dir $@)
	rm -f $@ && $(AR) rcs $@ $^

bin/franja-worker: $(WORKER_OBJ) $(LIB)
	@mkdir -p bin
	$(CC) $(CFLAGS) $(LTO_LINK) $(PGO) -o $@ $(WORKER_OBJ) $(LIB) $(WORKER_LIBS)

# make pgo: bin/franja-worker built again with GCC's profile feedback, its
# render-path modules laid out and inlined by where a training render
# spends (the Cornell box, the rough metals and the sky scene, small).
# The same bits as the plain build (only code placement and inlining
# change; -ffp-contract=off and no fast-math still fix every rounding),
# 3-6 % less CPU time on this project's benches (tests/bench/README.md,
# "Profile feedback").  Its objects live in $(B)/pgo; a later plain `make`
# keeps this worker until a source changes.
PGO_SCENES = scenes/cornell.json scenes/metals.json scenes/sky-spheres.json
pgo: bin/franja $(IIO_PLUGIN)
	rm -rf $(B)/pgo
	$(MAKE) --no-print-directory B=$(B)/pgo PGO='-fprofile-generate -fprofile-update=atomic' bin/franja-worker
	for f in $(PGO_SCENES); do \
	    bin/franja compile $$f -o $(B)/pgo/train.fbin >/dev/null && \
	    bin/franja-worker --scene $(B)/pgo/train.fbin --size 96x96 --spp 16 --rows 0:96 -o /dev/null || exit 1; \
	done
	find $(B)/pgo -name '*.o' -delete
	rm -f $(B)/pgo/libfranja.a bin/franja-worker
	$(MAKE) --no-print-directory B=$(B)/pgo PGO='-fprofile-use -fprofile-partial-training -Wno-missing-profile' \
	    bin/franja-worker

$(COORD_LIB): $(COORD_LIB_OBJ)
	@mkdir -p $(dir $@)
	rm -f $@ && $(AR) rcs $@ $^

# The coordinator's sources (and the code that uses them) name its headers
# from coordinator/, as common's from common/: "transport/hosts.h".
$(COORD_OBJ) $(TESTSUP_OBJ): CSTD += -iquote coordinator
$(TESTSUP_OBJ): CSTD += -Itests/support

$(TESTSUP_LIB): $(TESTSUP_OBJ)
	@mkdir -p $(dir $@)
	rm -f $@ && $(AR) rcs $@ $^

bin/franja: $(B)/coordinator/main.o $(COORD_LIB) $(LIB)
	@mkdir -p bin
	$(CC) $(CFLAGS) $(LTO_LINK) -o $@ $(B)/coordinator/main.o $(COORD_LIB) $(LIB) $(COORD_LIBS)

# Tests see the headers of common/, coordinator/ and tests/support/, and link the
# coordinator's library too; shared libraries that a test does not use are
# dropped (--as-needed).
bin/tests/%: tests/%.c $(TESTSUP_LIB) $(COORD_LIB) $(LIB)
	@mkdir -p bin/tests
	$(CC) $(CSTD) $(CFLAGS) $(NO_LTO) $(CJSON_CFLAGS) -iquote coordinator -Itests/support -o $@ $< $(TESTSUP_LIB) $(COORD_LIB) $(LIB) \
	    -Wl,--as-needed $(COORD_LIBS)

bin/gen/%: tests/gen/%.c $(LIB)
	@mkdir -p bin/gen
	$(CC) $(CSTD) $(CFLAGS) $(NO_LTO) $(CJSON_CFLAGS) -o $@ $< $(LIB) $(CJSON_LIBS) -lm -pthread

bin/tools/%: tests/tools/%.c tests/tools/pfmread.h $(LIB)
	@mkdir -p bin/tools
	$(CC) $(CSTD) $(CFLAGS) $(NO_LTO) $(CJSON_CFLAGS) -o $@ $< $(LIB) $(CJSON_LIBS) -lm -pthread

# nolockfs, a FUSE file system that refuses locks (tests/it_joblock.sh).
bin/tools/nolockfs: tests/tools/nolockfs.c
	@mkdir -p bin/tools
	$(CC) $(CSTD) $(CFLAGS) $(shell $(PKG) --cflags fuse3) -o $@ $< $(shell $(PKG) --libs fuse3 2>/dev/null || echo -lfuse3)

# Benchmark programs; only these link Embree (the reference they measure against).
# Their segments are aligned to 2 MiB, so the kernel places them at a random
# multiple of 2 MiB and the low 21 bits of each code address are the link's.
# At the default 4 KiB those bits were random per process, and so was the
# walk's speed in bvhbench: some processes ran its closest hits on the
# 100 k terrain slower than the rest, while none did with the code placed
# alike (tests/bench/README.md, "Benchmarks linked with 2 MiB segments").
# The code is the same; the file is sparse where it is padded.
BENCH_LDFLAGS = -Wl,-z,max-page-size=0x200000
# packbench packs scenes as the coordinator does: its library and zstd.
bin/bench/packbench: tests/bench/packbench.c $(COORD_LIB) $(LIB)
	@mkdir -p bin/bench
	$(CC) $(CSTD) $(CFLAGS) $(NO_LTO) -iquote coordinator -o $@ $< $(COORD_LIB) $(LIB) -Wl,--as-needed $(COORD_LIBS)
bin/bench/%: tests/bench/%.c $(wildcard tests/bench/*.h) $(LIB)
	@mkdir -p bin/bench
	$(CC) $(CSTD) $(CFLAGS) $(NO_LTO) $(CJSON_CFLAGS) $(BENCH_LDFLAGS) -o $@ $< $(LIB) $(CJSON_LIBS) -lembree3 -lm -pthread

# Fuzzing: libFuzzer targets tests/fuzz/fuzz_*.c, built with clang, ASan
# and UBSan over the common sources, each run for FUZZ_SECONDS
# (tests/fuzz/run.sh; it makes seeds with bin/franja, bin/franja-worker and
# bin/bench/packbench).
# make test builds them too and runs each for a few seconds (tests/run.sh).
# FUZZ_TARGETS names some (hosts partial ...); default: all.
FUZZ_SECONDS ?= 60
FUZZ_TARGETS ?=
FUZZ_CC      ?= clang
FUZZ_CFLAGS   = -std=c17 -D_GNU_SOURCE -g -O1 $(FPFLAGS) -Icommon $(CJSON_CFLAGS) -fno-sanitize-recover=all
FUZZ_SRC      = $(wildcard tests/fuzz/fuzz_*.c)
FUZZ_BIN      = $(FUZZ_SRC:tests/fuzz/%.c=bin/fuzz/%)
FUZZ_OBJ      = $(COMMON_SRC:%.c=$(B)/fuzz/%.o)
# The coordinator's C modules, for the targets of its readers (obj.c): an
# archive, so a target links only the members it uses.
FUZZ_COORD_LIB = $(B)/fuzz/libfranja-coord.a
FUZZ_COORD_OBJ = $(filter-out $(B)/fuzz/coordinator/main.o,$(COORD_SRC:%.c=$(B)/fuzz/%.o))
.SECONDARY: $(FUZZ_OBJ) $(FUZZ_COORD_OBJ)

$(FUZZ_COORD_OBJ): FUZZ_CFLAGS += -iquote coordinator
$(B)/fuzz/%.o: %.c
	@mkdir -p $(dir $@)
	$(FUZZ_CC) $(FUZZ_CFLAGS) -fsanitize=fuzzer-no-link,address,undefined -MMD -MP -c $< -o $@

$(FUZZ_COORD_LIB): $(FUZZ_COORD_OBJ)
	rm -f $@ && $(AR) rcs $@ $^

bin/fuzz/%: tests/fuzz/%.c $(FUZZ_OBJ) $(FUZZ_COORD_LIB)
	@mkdir -p bin/fuzz
	$(FUZZ_CC) $(FUZZ_CFLAGS) -iquote coordinator -fsanitize=fuzzer,address,undefined -MMD -MP -MT $@ -MF $(B)/fuzz/$(@F).d \
	    -o $@ $< $(FUZZ_COORD_LIB) \
	    $(FUZZ_OBJ) $(CJSON_LIBS) $(ZSTD_LIBS) -Wl,--as-needed $(ASSIMP_LIBS) $(SSH_LIBS) $(MHD_LIBS) -ldl -lm -pthread

fuzz: all $(FUZZ_BIN) bin/bench/packbench
	sh tests/fuzz/run.sh $(FUZZ_SECONDS) $(FUZZ_TARGETS)

deps:
	sh tests/install-deps.sh

# make check runs everything: the renderer's and coordinator's tests, then
# the cross-build tests (Docker images, qemu, mixed clusters; needs root).
# make test runs the first part alone.
check: test check-cross

test: all $(TEST_BIN) $(TOOL_BIN) $(FUZZ_BIN) bin/bench/packbench
	sh tests/run.sh

bench: all $(TOOL_BIN) $(BENCH_BIN)
	sh tests/bench/run.sh

render: all
	bin/franja render scenes/cornell.json -o cornell.png

# The small Cycles renders in tests/data that tests/it_conventions.sh,
# tests/it_envlight.sh, tests/it_cycles_*.sh and tests/it_lightunits.sh
# compare against (and the glTF files Blender's exporter writes for the
# last), made again with Debian's blender (make deps installs it and
# python3-numpy, which its glTF exporter needs).  The tests read the
# committed files: only this target and the benchmarks need blender.
refs:
	blender -b --factory-startup --python tests/refs/cycles_furnace.py -- tests/data
	blender -b --factory-startup --python tests/refs/cycles_env.py -- scenes/textures/sky.hdr tests/data
	for s in rough metals principled; do blender -b --factory-startup --python tests/refs/cycles_scene.py -- \
	    tests/data/cycles-$$s.json tests/data cycles-$$s 256; done
	blender -b --factory-startup --python tests/refs/cycles_lights.py -- tests/data
	for s in glass fog; do blender -b --factory-startup --python tests/refs/cycles_noise.py -- \
	    tests/bench/scenes/cornell-$$s.json tests/data/cycles-noise-$$s.pfm 1024 7; done

# make install [PREFIX=/usr/local] [DESTDIR=staging]: the two programs, the image plug-in, their
# manual pages and bash completion; make uninstall removes exactly those files.
# franja finds the franja-worker installed beside it.
PREFIX     ?= /usr/local
BINDIR     ?= $(PREFIX)/bin
# franja finds its image plug-in in ../lib/franja from its own directory.
PLUGINDIR   = $(BINDIR)/../lib/franja
MANDIR     ?= $(PREFIX)/share/man
BASHCOMPDIR ?= $(PREFIX)/share/bash-completion/completions
MAN1 = $(wildcard coordinator/man/*.1)
MAN5 = $(wildcard coordinator/man/*.5)
INSTALLED = $(BINDIR)/franja $(BINDIR)/franja-worker $(PLUGINDIR)/franja-imageio.so $(MAN1:coordinator/man/%=$(MANDIR)/man1/%) \
	    $(MAN5:coordinator/man/%=$(MANDIR)/man5/%) $(BASHCOMPDIR)/franja $(BASHCOMPDIR)/franja-worker

install: all
	install -d '$(DESTDIR)$(BINDIR)' '$(DESTDIR)$(MANDIR)/man1' '$(DESTDIR)$(MANDIR)/man5' '$(DESTDIR)$(BASHCOMPDIR)'
	install -m 755 bin/franja bin/franja-worker '$(DESTDIR)$(BINDIR)/'
	install -d '$(DESTDIR)$(PLUGINDIR)'
	install -m 644 $(IIO_PLUGIN) '$(DESTDIR)$(PLUGINDIR)/'
	install -m 644 $(MAN1) '$(DESTDIR)$(MANDIR)/man1/'
	install -m 644 $(MAN5) '$(DESTDIR)$(MANDIR)/man5/'
	install -m 644 coordinator/completion/franja.bash '$(DESTDIR)$(BASHCOMPDIR)/franja'
	install -m 644 coordinator/completion/franja.bash '$(DESTDIR)$(BASHCOMPDIR)/franja-worker'

uninstall:
	rm -f $(INSTALLED:%='$(DESTDIR)%')

# make docs [DOCDIR=build/docs]: the user guide in DOCDIR/guide (the
# READMEs and the manual pages as linked HTML pages, by pandoc:
# coordinator/guide/build.sh) and the API documentation of the headers in
# DOCDIR/html (Doxygen).  make guide builds the guide alone.
DOCDIR ?= $(B)/docs
docs: guide
	@mkdir -p '$(DOCDIR)'
	{ cat coordinator/Doxyfile; echo 'OUTPUT_DIRECTORY = $(DOCDIR)'; echo 'WARN_LOGFILE = $(DOCDIR)/warnings.log'; } | doxygen -
	@echo "API documentation: $(DOCDIR)/html/index.html"

guide:
	sh coordinator/guide/build.sh '$(DOCDIR)/guide' '$(DOCDIR)/html'

# Fully static workers, bin/static/<arch>/franja-worker: they run on any Linux
# of their architecture.  Debian ships no static cJSON, so they are built with
# -DFRANJA_NO_JSON and read binary scenes only.  libzstd.a is linked where the
# arch's compiler finds one (libzstd-dev, libzstd-dev:arm64); without it the
# worker is built with -DFRANJA_NO_ZSTD, cannot unpack, and is sent scenes
# uncompressed.  Each arch has its own objects.
STATIC_ARCHS = amd64 arm64
STATIC_CC_amd64 = x86_64-linux-gnu-gcc
STATIC_CC_arm64 = aarch64-linux-gnu-gcc
static: $(STATIC_ARCHS:%=bin/static/%/franja-worker)

static_zstd = $(filter /%,$(shell $(STATIC_CC_$(1)) -print-file-name=libzstd.a 2>/dev/null))
bin/static/%/franja-worker: $(COMMON_SRC) $(WORKER_SRC) $(wildcard common/*.h common/compile/*.h worker/*.h)
	$(MAKE) --no-print-directory B=$(B)/static-$* CC=$(STATIC_CC_$*) \
	    AR=$(STATIC_CC_$*:-gcc=-ar) CJSON_CFLAGS= \
	    CFLAGS='$(CFLAGS) -DFRANJA_NO_JSON $(if $(call static_zstd,$*),,-DFRANJA_NO_ZSTD)' \
	    $(B)/static-$*/libfranja.a $(WORKER_SRC:%.c=$(B)/static-$*/%.o)
	@mkdir -p $(dir $@)
	$(STATIC_CC_$*) $(CFLAGS) $(LTO_LINK) -static -o $@ $(WORKER_SRC:%.c=$(B)/static-$*/%.o) \
	    $(B)/static-$*/libfranja.a $(call static_zstd,$*) -lm

# dist/<os>-<arch>/ from the docker/Dockerfile.* images (docker/build.sh; see
# docker/README.md), plus dist/static-<arch>/.  DIST_TARGETS: bullseye bookworm
# trixie (default all); DIST_FLAGS e.g. --own-engine where no Docker runs.
dist: static
	sh docker/build.sh $(DIST_FLAGS) -o dist $(DIST_TARGETS)
	for a in $(STATIC_ARCHS); do mkdir -p dist/static-$$a && \
	    cp bin/static/$$a/franja-worker dist/static-$$a/; done

# Cross-architecture and cross-distribution tests (qemu, Docker; root).
check-cross: all static
	sh tests/run.sh tests/cross/it_*.sh

clean:
	rm -rf $(B) bin

-include $(COMMON_OBJ:.o=.d) $(WORKER_OBJ:.o=.d) $(COORD_OBJ:.o=.d) $(TESTSUP_OBJ:.o=.d) $(IIO_OBJ:.o=.d) \
    $(FUZZ_OBJ:.o=.d) $(FUZZ_COORD_OBJ:.o=.d) $(FUZZ_BIN:bin/fuzz/%=$(B)/fuzz/%.d)
