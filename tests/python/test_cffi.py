"""Drives the engine from Python through cffi in API mode, as the README
shows: compiles a module against the static library, makes a grid, refines
it, and checks the result. Skips (exit 77) when cffi or a C compiler for
Python extensions is missing."""
import os
import sys
import tempfile

try:
    import cffi
except ImportError:
    print("SKIP: python3-cffi is not installed")
    sys.exit(77)

src = os.environ["TT_SOURCE_DIR"]
lib = os.environ["TT_CORE_LIB"]

ffi = cffi.FFI()
ffi.cdef("""
typedef struct tt_context tt_context;
typedef struct tt_grid tt_grid;
typedef struct tt_tin tt_tin;
typedef int... tt_status;
typedef int... tt_criterion;
typedef struct { double max_error; size_t max_points; size_t max_triangles;
                 double percent; int threads; ...; } tt_refine_options;
typedef struct { size_t samples; size_t covered; double max_error;
                 double rmse; double mean_abs; ...; } tt_error_stats;
typedef struct { size_t vertices; size_t triangles; tt_error_stats errors;
                 ...; } tt_tin_summary;
tt_context *tt_context_create(void);
void tt_context_destroy(tt_context *);
const char *tt_context_errmsg(const tt_context *);
tt_status tt_grid_create_from_floats(tt_context *, size_t, size_t,
                                     const float *, tt_grid **);
void tt_grid_destroy(tt_grid *);
void tt_refine_options_init(tt_refine_options *);
tt_status tt_refine_run(tt_context *, const tt_grid *,
                        const tt_refine_options *, tt_tin **);
void tt_tin_get_summary(const tt_tin *, tt_tin_summary *);
size_t tt_tin_vertex_count(const tt_tin *);
void tt_tin_destroy(tt_tin *);
""")
ffi.set_source("_terratin_test", '#include "terratin/terratin.h"',
               include_dirs=[os.path.join(src, "include")],
               extra_objects=[lib], libraries=["m", "pthread"])
tmp = tempfile.mkdtemp()
try:
    ffi.compile(tmpdir=tmp, verbose=False)
except Exception as exc:  # no compiler or no Python headers
    print("SKIP: cannot build a cffi module: %s" % exc)
    sys.exit(77)
sys.path.insert(0, tmp)
from _terratin_test import ffi as F, lib as L  # noqa: E402
import math  # noqa: E402

nx, ny = 60, 45
z = F.new("float[]", [10 * math.sin(0.2 * c) * math.cos(0.15 * r)
                      for r in range(ny) for c in range(nx)])
ctx = L.tt_context_create()
grid = F.new("tt_grid **")
tin = F.new("tt_tin **")
opt = F.new("tt_refine_options *")
L.tt_refine_options_init(opt)
opt.max_error = 0.25
failures = 0
if L.tt_grid_create_from_floats(ctx, nx, ny, z, grid) != 0 or \
        L.tt_refine_run(ctx, grid[0], opt, tin) != 0:
    print("FAIL:", F.string(L.tt_context_errmsg(ctx)).decode())
    sys.exit(1)
s = F.new("tt_tin_summary *")
L.tt_tin_get_summary(tin[0], s)
checks = [
    ("vertices match the count", s.vertices == L.tt_tin_vertex_count(tin[0])),
    ("bound honoured", s.errors.max_error <= 0.25),
    ("every sample measured", s.errors.samples == nx * ny),
    ("refined beyond the corners", s.vertices > 4),
]
for name, ok in checks:
    if not ok:
        print("FAIL:", name)
        failures += 1
print("%d vertices, %d triangles, max error %.4f" %
      (s.vertices, s.triangles, s.errors.max_error))
L.tt_tin_destroy(tin[0])
L.tt_grid_destroy(grid[0])
L.tt_context_destroy(ctx)
print("%d passed, %d failed" % (len(checks) - failures, failures))
sys.exit(1 if failures else 0)
