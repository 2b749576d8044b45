# fuzz/fuzz.mk -- builds every libFuzzer target into $(OUT) (fuzz/run.sh
# calls it; run it from the repository's root):
#
#   make -f fuzz/fuzz.mk OUT=build-fuzz -j2            every target
#   make -f fuzz/fuzz.mk OUT=build-fuzz build-fuzz/fuzz_ply_sample
#
# The library's sources are compiled ONCE, with coverage instrumentation
# (-fsanitize=fuzzer-no-link) and AddressSanitizer + UndefinedBehaviorSanitizer,
# into $(OUT)/libhd_fuzz.a; the command line's sources but main.c likewise
# into $(OUT)/libcli_fuzz.a (with NIfTI support, without libpng).  Each
# target is then one small file compiled and linked against them:
#
#   fuzz_FORMAT         fuzz/fuzz_reader.c, a reader as points (9 formats)
#   fuzz_FORMAT_sample  fuzz/fuzz_reader.c, a mesh reader's faces (--sample)
#   fuzz_nifti          fuzz/fuzz_nifti.c, a NIfTI-1/2 mask through libnifti2
#                       and cli/nifti.c
#   fuzz_cli            fuzz/fuzz_cli.c, the command line's argument parser
#
# Needs clang (with its libFuzzer runtime, Debian: libclang-rt-14-dev) and
# the NIfTI library (libnifti2-dev): scripts/deps.sh fuzz installs them.

OUT     ?= build-fuzz
CC      := $(or $(FUZZ_CC),clang)
SAN     := -fsanitize=address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer
NIFTI_INC ?= /usr/include/nifti
# the exactness flags from the one file CMake and setup.py read too
EXACT   := $(shell sed -n '/^-/p' cmake/exactness-flags.txt)
CFLAGS  := -g -O1 -std=c11 -Wall -Wextra $(EXACT) \
           -D_POSIX_C_SOURCE=200809L -D_DEFAULT_SOURCE -Iinclude -Isrc $(SAN)
LIBS    := -lm -lpthread

READERS := ply obj off stl xyz pcd las npy laz
MESHES  := ply obj off stl
TARGETS := $(READERS:%=fuzz_%) $(MESHES:%=fuzz_%_sample) fuzz_nifti fuzz_cli

# src/mpi/ is the optional MPI library (cmake/mpi.cmake), not the core
LIB_SRC := $(filter-out src/mpi/%,$(wildcard src/*.c src/*/*.c))
CLI_SRC := $(filter-out cli/main.c,$(wildcard cli/*.c))
LIB_OBJ := $(LIB_SRC:%.c=$(OUT)/obj/%.o)
CLI_OBJ := $(CLI_SRC:%.c=$(OUT)/obj/%.o)

.PHONY: all
all: $(TARGETS:%=$(OUT)/%)

# Instrumented, not linked with libFuzzer's main: the library and the CLI.
$(OUT)/obj/src/%.o: src/%.c
	@mkdir -p $(@D)
	$(CC) $(CFLAGS) -fsanitize=fuzzer-no-link -MMD -MP -c $< -o $@
$(OUT)/obj/cli/%.o: cli/%.c
	@mkdir -p $(@D)
	$(CC) $(CFLAGS) -fsanitize=fuzzer-no-link -DHD_HAVE_NIFTI=1 -I$(NIFTI_INC) -MMD -MP -c $< -o $@

$(OUT)/libhd_fuzz.a: $(LIB_OBJ)
	@rm -f $@
	ar rcs $@ $^
$(OUT)/libcli_fuzz.a: $(CLI_OBJ)
	@rm -f $@
	ar rcs $@ $^

# One reader as points; float storage for odd-sized inputs (fuzz_reader.c).
$(OUT)/fuzz_%: fuzz/fuzz_reader.c $(OUT)/libhd_fuzz.a
	@mkdir -p $(OUT)/dep
	$(CC) $(CFLAGS) -fsanitize=fuzzer -MMD -MP -MF $(OUT)/dep/$(@F).d -DHD_FUZZ_FORMAT='"$*"' $< $(OUT)/libhd_fuzz.a $(LIBS) -o $@

# One mesh reader's faces: 64 points sampled on them.
$(MESHES:%=$(OUT)/fuzz_%_sample): $(OUT)/fuzz_%_sample: fuzz/fuzz_reader.c $(OUT)/libhd_fuzz.a
	@mkdir -p $(OUT)/dep
	$(CC) $(CFLAGS) -fsanitize=fuzzer -MMD -MP -MF $(OUT)/dep/$(@F).d -DHD_FUZZ_FORMAT='"$*"' -DHD_FUZZ_SAMPLE=64 $< \
	  $(OUT)/libhd_fuzz.a $(LIBS) -o $@

$(OUT)/fuzz_nifti: fuzz/fuzz_nifti.c $(OUT)/libcli_fuzz.a $(OUT)/libhd_fuzz.a
	@mkdir -p $(OUT)/dep
	$(CC) $(CFLAGS) -fsanitize=fuzzer -MMD -MP -MF $(OUT)/dep/$(@F).d -Icli -DHD_HAVE_NIFTI=1 -I$(NIFTI_INC) $< \
	  $(OUT)/libcli_fuzz.a $(OUT)/libhd_fuzz.a -lnifti2 -lznz -lz $(LIBS) -o $@

$(OUT)/fuzz_cli: fuzz/fuzz_cli.c $(OUT)/libcli_fuzz.a $(OUT)/libhd_fuzz.a
	@mkdir -p $(OUT)/dep
	$(CC) $(CFLAGS) -fsanitize=fuzzer -MMD -MP -MF $(OUT)/dep/$(@F).d -Icli $< \
	  $(OUT)/libcli_fuzz.a $(OUT)/libhd_fuzz.a -lnifti2 -lznz -lz $(LIBS) -o $@

-include $(LIB_OBJ:.o=.d) $(CLI_OBJ:.o=.d) $(TARGETS:%=$(OUT)/dep/%.d)
