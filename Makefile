# hausdorff -- the two commands a new user types are `make run` and `make test`.
# Everything builds with CMake into build/ (release) and build-asan/
# (AddressSanitizer + UndefinedBehaviorSanitizer).  Missing Debian packages
# are installed by scripts/deps.sh when run as root.

BUILD      ?= build
ASAN_BUILD ?= build-asan
JOBS       ?= 2
CMAKE_ARGS ?=

.PHONY: all deps configure run test test-release test-asan install bench experiments fuzz python clean

all: $(BUILD)/hausdorff

deps:
	@scripts/deps.sh build extras

$(BUILD)/CMakeCache.txt:
	@scripts/deps.sh build extras
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release $(CMAKE_ARGS)

$(BUILD)/hausdorff: $(BUILD)/CMakeCache.txt FORCE
	cmake --build $(BUILD) -j$(JOBS)

FORCE:

# The main job: the exact Hausdorff distance between two bundled models.
run: all
	./$(BUILD)/hausdorff data/cgal_lion.ply data/cgal_lion_head.ply
	./$(BUILD)/hausdorff data/wuson_obj.ply data/wuson_stl.ply

test: test-release test-asan

test-release:
	@scripts/deps.sh build extras test python
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release $(CMAKE_ARGS)
	cmake --build $(BUILD) -j$(JOBS)
	cd $(BUILD) && ctest --output-on-failure -j$(JOBS)

test-asan:
	@scripts/deps.sh build extras test
	cmake -S . -B $(ASAN_BUILD) -DCMAKE_BUILD_TYPE=Debug -DHD_SANITIZE=ON -DHD_ASAN_BUILD=ON $(CMAKE_ARGS)
	cmake --build $(ASAN_BUILD) -j$(JOBS)
	cd $(ASAN_BUILD) && ASAN_OPTIONS=detect_leaks=1 ctest --output-on-failure -j$(JOBS) -LE slow

install: all
	cmake --install $(BUILD) $(if $(PREFIX),--prefix $(PREFIX))

# The Python module alone, into $(BUILD)/python (docs/python.md); `make`
# builds it too whenever numpy, setuptools and Python.h are present.
python:
	@scripts/deps.sh build extras python
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release $(CMAKE_ARGS)
	cmake --build $(BUILD) -j$(JOBS) --target hausdorff_python

clean:
	rm -rf $(BUILD) $(ASAN_BUILD)
