# terratin -- quick start:  make demo   |   make check
#
# Both targets install the Debian packages the build needs when they are
# missing (apt-get, as root or through sudo), configure with CMake and build.
# `make check` then runs the whole suite through ctest twice: an optimised
# build with -Werror, and a build under AddressSanitizer + UBSan.

BUILD      ?= build
BUILD_SAN  ?= build-asan
JOBS       ?= $(shell nproc 2>/dev/null || echo 2)
DEB_PKGS   := cmake make gcc g++ pkg-config libgdal-dev libproj-dev gdal-bin libxml2-dev \
              python3 python3-cffi python3-dev zip libsqlite3-dev libnetcdf-dev \
              python3-matplotlib \
              libxml2-utils
DEMO_IN    ?= testdata/jacksboro_fault_dem.tif
DEMO_OUT   ?= demo-out/jacksboro_tin.gpkg

.PHONY: all deps build build-san demo check test test-san bench clean study

all: build

deps:
	@missing=""; for p in $(DEB_PKGS); do \
	  dpkg-query -W -f='$${Status}' $$p 2>/dev/null | grep -q "install ok installed" || missing="$$missing $$p"; \
	done; \
	if [ -n "$$missing" ]; then \
	  echo "terratin: installing Debian packages:$$missing"; \
	  if [ "$$(id -u)" = 0 ]; then SUDO=""; else SUDO="sudo"; fi; \
	  $$SUDO apt-get update -qq && \
	  DEBIAN_FRONTEND=noninteractive $$SUDO apt-get install -y -qq --no-install-recommends $$missing; \
	fi

$(BUILD)/CMakeCache.txt: | deps
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release

$(BUILD_SAN)/CMakeCache.txt: | deps
	cmake -S . -B $(BUILD_SAN) -DCMAKE_BUILD_TYPE=Debug -DTT_SANITIZE=address,undefined

build: deps $(BUILD)/CMakeCache.txt
	cmake --build $(BUILD) -j $(JOBS)

build-san: deps $(BUILD_SAN)/CMakeCache.txt
	cmake --build $(BUILD_SAN) -j $(JOBS)

demo: build
	@mkdir -p $(dir $(DEMO_OUT))
	$(BUILD)/terratin simplify -overwrite -max_error 20 $(DEMO_IN) $(DEMO_OUT)
	@echo "demo: wrote $(DEMO_OUT) (layers triangles, vertices, run_parameters); open it in QGIS or run: ogrinfo -so $(DEMO_OUT) triangles"

test: build
	cd $(BUILD) && ctest --output-on-failure -j $(JOBS)

test-san: build-san
	cd $(BUILD_SAN) && ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
	  ctest --output-on-failure -j $(JOBS)

check: test test-san

bench: build
	bench/run.sh

# The 2004 study reproduced into docs/study/ (tools/study.sh; 5.5 to 7
# minutes measured on 2 cores shared with other work): needs Crater Lake
# in ../shared/testdata (or CRATER=PATH).
study: build
	tools/study.sh $(BUILD)/terratin

clean:
	rm -rf $(BUILD) $(BUILD_SAN) demo-out
