# terratin -- quick start:  make demo   |   make check
#
# Both targets install the Debian packages the build needs when they are
# missing (apt-get, as root or through sudo), configure with CMake and build.
# `make check` then runs the suite through ctest twice, all but the `long`
# label: an optimised build with -Werror, and a build under AddressSanitizer
# + UBSan; it ends with the tests each build skipped and why
# (tests/skipped.py). `make check-long` runs the `long` label (full-size
# scenarios, README "Tests"); `cd build && ctest -L unit` is the inner loop.

BUILD      ?= build
BUILD_SAN  ?= build-asan
JOBS       ?= $(shell nproc 2>/dev/null || echo 2)
DEB_PKGS   := cmake make gcc g++ pkg-config libgdal-dev libproj-dev gdal-bin libxml2-dev \
              python3 python3-cffi python3-dev zip libsqlite3-dev libnetcdf-dev \
              python3-matplotlib libpq-dev \
              libxml2-utils
DEMO_IN    ?= testdata/jacksboro_fault_dem.tif
DEMO_OUT   ?= demo-out/jacksboro_tin.gpkg

.PHONY: all deps build build-san demo check check-long test test-san ctest ctest-san bench clean study doc-tables

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

# ctest's results also go to BUILD/Testing/ctest-junit.xml, where
# tests/skipped.py finds the skipped tests and the reasons they printed.
CTEST       = ctest --output-on-failure -j $(JOBS) --output-junit Testing/ctest-junit.xml
SAN_ENV     = ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1

ctest: build
	cd $(BUILD) && $(CTEST) -LE long

ctest-san: build-san
	cd $(BUILD_SAN) && $(SAN_ENV) $(CTEST) -LE long

test: ctest
	@python3 tests/skipped.py $(BUILD)

test-san: ctest-san
	@python3 tests/skipped.py $(BUILD_SAN)

check: ctest ctest-san
	@python3 tests/skipped.py $(BUILD) $(BUILD_SAN)

# The long tier (ctest label `long`, tests/long/): full-size runs, in the
# optimised build only, one at a time; README "Tests" says how long.
check-long: build
	cd $(BUILD) && ctest --output-on-failure -L long --output-junit Testing/ctest-long-junit.xml

bench: build
	bench/run.sh

# The 2004 study reproduced into docs/study/ (tools/study.sh; 5.5 to 7
# minutes measured on 2 cores shared with other work): needs Crater Lake
# in ../shared/testdata (or CRATER=PATH).
study: build
	tools/study.sh $(BUILD)/terratin

# The tables of docs/ that scripts print, rerun in place (README "Tests").
doc-tables: build
	bench/doc_tables.py --update --tier long $(BUILD)/terratin

# The QGIS plugin (qgis/terratin/, docs/qgis.md) as the zip QGIS's
# "Install from ZIP" takes.
.PHONY: qgis-plugin
qgis-plugin:
	python3 tools/qgis_plugin_zip.py $(BUILD)/terratin-qgis.zip

clean:
	rm -rf $(BUILD) $(BUILD_SAN) demo-out
