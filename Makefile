# hausdorff -- the two commands a new user types are `make run` and `make test`.
# Everything builds with CMake into build/ (release) and build-asan/
# (AddressSanitizer + UndefinedBehaviorSanitizer).  Missing Debian packages
# are installed by scripts/deps.sh when run as root.

BUILD      ?= build
ASAN_BUILD ?= build-asan
JOBS       ?= 2
CMAKE_ARGS ?=

.PHONY: all deps configure cli run test test-release test-asan test-tsan install bench bench-c2m bench-m2m experiments fuzz python clean

# Quiet: no "make[1]: Entering/Leaving directory" pair around each step of
# every cmake --build (the sub-makes read MAKEFLAGS); errors still print.
MAKEFLAGS += --no-print-directory

all: $(BUILD)/hausdorff

deps:
	@scripts/deps.sh build extras mpi

# A finished configure: CMake writes CMakeCache.txt even when configuring
# fails, so the proof is a stamp written after it succeeded.  A failed try
# leaves no stamp, and the next `make` configures again (over the same cache,
# whose failed searches CMake repeats).
CONFIGURED = $(BUILD)/.hd-configured
$(CONFIGURED):
	@scripts/deps.sh build extras mpi
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release $(CMAKE_ARGS)
	@touch $@

$(BUILD)/hausdorff: $(CONFIGURED) FORCE
	cmake --build $(BUILD) -j$(JOBS)

FORCE:

# The command-line tool alone (`make` builds everything: tests, benchmarks,
# the Python module).
cli: $(CONFIGURED)
	cmake --build $(BUILD) -j$(JOBS) --target hausdorff_cli

# The main job: the exact Hausdorff distance between two bundled models.
run: cli
	$(BUILD)/hausdorff data/cgal_lion.ply data/cgal_lion_head.ply
	$(BUILD)/hausdorff data/wuson_obj.ply data/wuson_stl.ply

# Both halves run, whatever the first gives; each is reported, and the
# status is non-zero when either failed.
test:
	@release=passed; asan=passed; \
	$(MAKE) test-release || release=FAILED; \
	$(MAKE) test-asan || asan=FAILED; \
	echo "make test: release build $$release ($(BUILD)), sanitizer build $$asan ($(ASAN_BUILD))"; \
	[ $$release = passed ] && [ $$asan = passed ]

test-release:
	@scripts/deps.sh build extras test python mpi
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release $(CMAKE_ARGS)
	@touch $(CONFIGURED)
	cmake --build $(BUILD) -j$(JOBS)
	cd $(BUILD) && ctest --output-on-failure -j$(JOBS)

test-asan:
	@scripts/deps.sh build extras test fuzz mpi
	cmake -S . -B $(ASAN_BUILD) -DCMAKE_BUILD_TYPE=Debug -DHD_SANITIZE=ON -DHD_ASAN_BUILD=ON $(CMAKE_ARGS)
	cmake --build $(ASAN_BUILD) -j$(JOBS)
	cd $(ASAN_BUILD) && ASAN_OPTIONS=detect_leaks=1 ctest --output-on-failure -j$(JOBS)

# Installs the libraries, headers, tools, man page, pkg-config files and CMake
# package, the MPI library and hausdorff-mpi among them when MPI was found (PREFIX=/some/where for another prefix than the configured one,
# /usr/local by default; DESTDIR=/stage to stage).  Into /usr or /usr/local as
# root it runs ldconfig, so that programs find libhausdorff.so.0; otherwise it
# says what to set.  Builds only what it installs.
install: $(CONFIGURED)
	cmake --build $(BUILD) -j$(JOBS) --target hd_installed
	cmake --install $(BUILD) $(if $(PREFIX),--prefix $(PREFIX))
	@prefix='$(PREFIX)'; cache='$(BUILD)/CMakeCache.txt'; \
	[ -n "$$prefix" ] || prefix=$$(sed -n 's/^CMAKE_INSTALL_PREFIX:[A-Z]*=//p' "$$cache"); \
	prefix=$${prefix%/}; libdir=$$(sed -n 's/^CMAKE_INSTALL_LIBDIR:[A-Z]*=//p' "$$cache"); \
	case "$$libdir" in /*) ;; *) libdir="$$prefix/$$libdir" ;; esac; \
	if [ -n "$$DESTDIR" ]; then \
	  echo "Staged under $$DESTDIR for the prefix $$prefix (run ldconfig once it is in place)"; \
	elif [ "$$prefix" = /usr ] || [ "$$prefix" = /usr/local ]; then \
	  if [ "$$(id -u)" = 0 ]; then echo "ldconfig"; ldconfig; \
	  else echo "Now run ldconfig as root (su -c ldconfig), so that programs find libhausdorff.so.0"; fi; \
	else \
	  echo "Installed into $$prefix, which pkg-config, CMake and the dynamic linker do not search by themselves:"; \
	  echo "  export PKG_CONFIG_PATH=$$libdir/pkgconfig   # then: cc prog.c \$$(pkg-config --cflags --libs hausdorff)"; \
	  echo "  cmake -DCMAKE_PREFIX_PATH=$$prefix ...   # for find_package(hausdorff)"; \
	  echo "  export LD_LIBRARY_PATH=$$libdir   # to run what links libhausdorff.so, or link with -Wl,-rpath,$$libdir"; \
	fi

# The Python module alone, into $(BUILD)/python (docs/python.md); `make`
# builds it too whenever numpy, setuptools and Python.h are present.
python:
	@scripts/deps.sh build extras python
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release $(CMAKE_ARGS)
	@touch $(CONFIGURED)
	cmake --build $(BUILD) -j$(JOBS) --target hausdorff_python

# The threaded tests under ThreadSanitizer (clang's: gcc 12's fails to start
# on this kernel), in build-tsan/; not part of `make test` (a third build).
TSAN_BUILD ?= build-tsan
TSAN_TESTS ?= test_index|test_analysis|test_engine|test_algorithms|test_readers|test_io_mesh|test_oom|test_bvh|test_c2m
test-tsan:
	@scripts/deps.sh fuzz
	CC=clang cmake -S . -B $(TSAN_BUILD) -DCMAKE_BUILD_TYPE=RelWithDebInfo \
	  -DCMAKE_C_FLAGS=-fsanitize=thread -DCMAKE_EXE_LINKER_FLAGS=-fsanitize=thread $(CMAKE_ARGS)
	cmake --build $(TSAN_BUILD) -j$(JOBS)
	cd $(TSAN_BUILD) && TSAN_OPTIONS=halt_on_error=1 ctest --output-on-failure -j$(JOBS) -R '$(TSAN_TESTS)'

# libFuzzer targets (fuzz/run.sh, docs/formats.md "Fuzzing"): the readers as
# points and sampled, NIfTI masks, the argument parser; each run FUZZ_SECONDS
# from its seeds in tests/corpus/.  FUZZ_TARGETS picks some ("ply ply_sample
# nifti cli"; FUZZ_FORMATS is its older name).  Exits non-zero on a finding.
# `make test` runs every target for 3 s (tests/fuzz_smoke.cmake).
FUZZ_SECONDS ?= 60
FUZZ_FORMATS ?=
FUZZ_TARGETS ?= $(FUZZ_FORMATS)
fuzz:
	@scripts/deps.sh fuzz
	FUZZ_SECONDS=$(FUZZ_SECONDS) FUZZ_BUILD=build-fuzz fuzz/run.sh $(FUZZ_TARGETS)

# The engine benchmark (docs/benchmarks.md, "Engine"; not part of `make test`):
# installs the peers (nanoflann, PCL, SciPy, Open3D) and matplotlib, times
# every case and the scale curve up to 100M points per cloud (about 10 GB of
# memory), then regenerates the table and the plots.  BENCH_ARGS="--quick"
# for a short run without the scale curve.
BENCH_ARGS ?= --scale
bench:
	@scripts/deps.sh build extras bench plot
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release -DHD_BENCH_PEERS=ON $(CMAKE_ARGS)
	cmake --build $(BUILD) -j$(JOBS) --target hd_bench hausdorff_cli nanoflann_hd pcl_hd
	$(BUILD)/bench/hd_bench --peers $(BUILD)/bench --scripts bench/peers --data data \
	  --cli $(BUILD)/hausdorff --out $(BUILD)/bench/engine.jsonl $(BENCH_ARGS)
	/usr/bin/python3 bench/report.py $(BUILD)/bench/engine.jsonl --doc docs/benchmarks.md \
	  --plots docs/img --command "make bench$(if $(filter-out --scale,$(BENCH_ARGS)), BENCH_ARGS=\"$(BENCH_ARGS)\")"
	cmake --build $(BUILD) -j$(JOBS) --target field_bench percentile_bench
	/usr/bin/python3 bench/field_report.py --build $(BUILD) --doc docs/benchmarks.md --command "make bench"
	$(MAKE) bench-c2m C2M_ARGS="$(C2M_ARGS)"
	$(MAKE) bench-m2m

# The surface-to-surface benchmark (docs/benchmarks.md, "Surface to surface"; part of `make bench`, not of
# `make test`): hd_surface_hausdorff's enclosures against CGAL's bounded-error distances and the sampled
# estimates on every case of bench/m2m_cases.c, each checked by the dense check (tests/m2m_dense.c).
# M2M_ARGS="--quick" for the smaller cases (a few minutes).
M2M_ARGS ?=
bench-m2m:
	@scripts/deps.sh build cgal
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release -DHD_BENCH_CGAL=ON $(CMAKE_ARGS)
	cmake --build $(BUILD) -j$(JOBS) --target m2m_cases m2m_run m2m_cgal m2m_dense
	/usr/bin/python3 bench/m2m_bench.py --build $(BUILD) --data data --doc docs/benchmarks.md \
	  --surfaces docs/surfaces.md --command "make bench-m2m$(if $(strip $(M2M_ARGS)), M2M_ARGS=\"$(strip $(M2M_ARGS))\")" \
	  $(M2M_ARGS)

# The cloud-to-mesh benchmark (docs/benchmarks.md, "Cloud to mesh"): every
# mesh size (10^3, 10^5, 10^6 triangles), cloud size (10^5, 10^6, 10^7) and
# kind (near, far) at 1 and 2 threads against Open3D and CGAL in the same run,
# then its table in the doc.  C2M_ARGS=--quick leaves out the 10^7-point
# clouds and the 10^6-triangle mesh (`make bench BENCH_ARGS=--quick` implies it).
C2M_ARGS ?= $(if $(filter --quick,$(BENCH_ARGS)),--quick)
bench-c2m:
	@scripts/deps.sh build bench
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release -DHD_BENCH_CGAL=ON $(CMAKE_ARGS)
	cmake --build $(BUILD) -j$(JOBS) --target c2m_bench c2m_cgal tri_bench
	/usr/bin/python3 bench/c2m_run.py --build $(BUILD) --out $(BUILD)/bench/c2m.jsonl --doc docs/benchmarks.md \
	  --command "make bench-c2m$(if $(strip $(C2M_ARGS)), C2M_ARGS=$(strip $(C2M_ARGS)))" $(C2M_ARGS)

clean:
	rm -rf $(BUILD) $(ASAN_BUILD) $(TSAN_BUILD) build-fuzz

# The paper's experiments (Zhang et al., Section 6) rerun with this library's
# algorithms: writes docs/paper-reproduction.md and docs/img/paper-*.png (not
# part of `make test`).  QUICK=1 (or EXPERIMENTS_ARGS=--quick) for the quick
# mode, about a minute; the full mode takes a few minutes.
EXPERIMENTS_ARGS ?= $(if $(QUICK),--quick)
experiments:
	@scripts/deps.sh build extras plot
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release $(CMAKE_ARGS)
	cmake --build $(BUILD) -j$(JOBS) --target experiments
	$(BUILD)/bench/experiments --data data --out $(BUILD)/bench/experiments.jsonl $(EXPERIMENTS_ARGS)
	/usr/bin/python3 bench/plot_experiments.py $(BUILD)/bench/experiments.jsonl \
	  --doc docs/paper-reproduction.md --img docs/img --command "make experiments$(EXPERIMENTS_CMD)"
EXPERIMENTS_CMD = $(if $(filter file,$(origin EXPERIMENTS_ARGS)),$(if $(QUICK), QUICK=$(QUICK)),$(if \
  $(strip $(EXPERIMENTS_ARGS)), EXPERIMENTS_ARGS=\"$(strip $(EXPERIMENTS_ARGS))\"))
