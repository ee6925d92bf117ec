/* test_optimum.c -- the optimisers against the true optimum, found by
 * enumerating every triangulation of small point sets (seeded; the seed is
 * printed, TT_SEED=<n> replays a run):
 *  - point sets of 5 to 10 points: the corners of a box (co-circular) and
 *    random inner points, some rounds with three inner points on one row
 *    (collinear), four on a rectangle (co-circular), or points on the
 *    box's sides (collinear with its corners). Every triangulation is
 *    reached by a walk of the flip graph (connected for a planar point
 *    set) from the Delaunay one;
 *  - edge insertion (edge_insert.c) reaches the least largest angle over all
 *    of them, from the Delaunay triangulation and from a random one;
 *  - Delaunay's flips, from a random triangulation, reach the largest
 *    smallest angle;
 *  - for every other criterion, local swap, look-ahead and annealing
 *    (anneal.c) from a random triangulation never end worse than it: the
 *    additive criteria by their total (each triangulation's relative
 *    quality summed from exact swap values along the walk), the max-type
 *    ones by their true global value (largest angle; sorted angle vector;
 *    sorted vector of the angles between normals); how often each reaches
 *    the optimum is printed;
 *  - on 40-120 points (beyond enumeration): edge insertion ends at or
 *    below local swap's largest angle, reports it as the optimum, never
 *    makes the sorted vector of largest angles worse (also when every
 *    other insertion is refused); annealing is reproducible word for word,
 *    the same with an undo log of 8 records (snapshots and replays), and
 *    takes refusals of its accept callback;
 *  - the polygon DP (polygon_dp.c) reaches the optimum of random convex
 *    polygons of 4 to 9 vertices under seven decomposable measures, against
 *    a recursive enumeration of every triangulation. */
#include "criteria/criterion.h"
#include "criteria/geometry.h"
#include "mesh/mesh.h"
#include "optimize/anneal.h"
#include "optimize/edge_insert.h"
#include "optimize/optimize.h"
#include "optimize/polygon_dp.h"
#include "optimize/swap.h"
#include "terratin/terratin.h"
#include "tt_test.h"

#include <stdbool.h>
#include <time.h>

static tt_context *ctx;

#define MAXP 10
#define MAXT (2 * MAXP)
#define TOL 1e-9

static void check_valid(const tt__mesh *m, const char *what)
{
  char why[256];
  if (!tt__mesh_validate(m, why, sizeof why))
    TT_FAIL_("%s: invalid mesh: %s", what, why);
}

/* --- point sets and their Delaunay triangulation ------------------------ */

static tt_grid *bumpy(size_t nx, size_t ny, uint64_t seed)
{
  tt_grid *g = NULL;
  if (tt_grid_create(ctx, nx, ny, &g) != TT_OK)
    return NULL;
  float *z = tt_grid_heights(g);
  uint64_t rng = seed;
  for (size_t r = 0; r < ny; r++)
    for (size_t c = 0; c < nx; c++)
      z[r * nx + c] = (float)(6 * sin(0.5 * (double)c) * cos(0.4 * (double)r) +
                              4 * tt_test_uniform(&rng));
  return g;
}

/* Inserts (c, r), inside or on the mesh, with Delaunay's repair. */
static bool insert(tt__mesh *m, const tt_grid *g, int32_t c, int32_t r)
{
  const float *z = tt_grid_heights_const(g);
  int32_t v = tt__mesh_add_vertex(m, c, r, z[(size_t)r * tt_grid_width(g) + c]);
  tt__crit_env env = {m, g, NULL};
  tt__edge_stack stack = {NULL, 0, 0};
  bool ok = false;
  for (size_t t = 0; t < m->nslots && !ok; t++) {
    if (!tt__mesh_live(m, (int32_t)t))
      continue;
    int32_t on = -1;
    bool out = false;
    for (int k = 0; k < 3; k++) {
      int o = tt__mesh_orient(m, m->hv[3 * t + k],
                              m->hv[3 * t + (k + 1) % 3], v);
      out |= o < 0;
      if (o == 0)
        on = (int32_t)(3 * t) + k;
    }
    if (out)
      continue;
    int32_t opp[4];
    int n = on < 0 ? 3 : 4;
    if (on < 0 ? !tt__mesh_split_triangle(m, (int32_t)t, v, opp)
               : !tt__mesh_split_edge(m, on, v, opp))
      break;
    ok = tt__swap_repair(m, &tt__criterion_delaunay, &env, opp, n, &stack) >=
         0;
  }
  tt__edge_stack_free(&stack);
  tt__mesh_clear_touched(m);
  return ok;
}

typedef struct pset {
  int n;                 /* points besides the box corners */
  int32_t c[MAXP], r[MAXP];
  int32_t box[4];
  const char *kind;
} pset;

static bool taken(const pset *p, int32_t c, int32_t r)
{
  if ((c == p->box[0] || c == p->box[2]) && (r == p->box[1] || r == p->box[3]))
    return true;
  for (int i = 0; i < p->n; i++)
    if (p->c[i] == c && p->r[i] == r)
      return true;
  return false;
}

static void add(pset *p, int32_t c, int32_t r)
{
  if (p->n < MAXP - 4 && !taken(p, c, r)) {
    p->c[p->n] = c;
    p->r[p->n] = r;
    p->n++;
  }
}

static void make_set(uint64_t *rng, int round, int32_t w, int32_t h, pset *p)
{
  memset(p, 0, sizeof *p);
  p->box[2] = w - 1;
  p->box[3] = h - 1;
  int want = 1 + (int)(tt_test_rand(rng) % 6); /* 5..10 points */
  switch (round % 4) {
  case 1: { /* three inner points on one row */
    int32_t r = 1 + (int32_t)(tt_test_rand(rng) % (uint64_t)(h - 2));
    for (int k = 0; k < 3; k++)
      add(p, 1 + (int32_t)(tt_test_rand(rng) % (uint64_t)(w - 2)), r);
    p->kind = "collinear";
    break;
  }
  case 2: { /* the corners of an inner rectangle: co-circular */
    int32_t c0 = 1 + (int32_t)(tt_test_rand(rng) % (uint64_t)(w / 2 - 1));
    int32_t r0 = 1 + (int32_t)(tt_test_rand(rng) % (uint64_t)(h / 2 - 1));
    int32_t c1 = c0 + 1 + (int32_t)(tt_test_rand(rng) % (uint64_t)(w / 2 - 1));
    int32_t r1 = r0 + 1 + (int32_t)(tt_test_rand(rng) % (uint64_t)(h / 2 - 1));
    add(p, c0, r0);
    add(p, c1, r0);
    add(p, c1, r1);
    add(p, c0, r1);
    p->kind = "co-circular";
    break;
  }
  case 3: /* on the box's sides */
    add(p, 1 + (int32_t)(tt_test_rand(rng) % (uint64_t)(w - 2)), 0);
    add(p, w - 1, 1 + (int32_t)(tt_test_rand(rng) % (uint64_t)(h - 2)));
    p->kind = "on the outline";
    break;
  default:
    p->kind = "random";
    break;
  }
  while (p->n < want)
    add(p, 1 + (int32_t)(tt_test_rand(rng) % (uint64_t)(w - 2)),
        1 + (int32_t)(tt_test_rand(rng) % (uint64_t)(h - 2)));
}

static bool build(tt__mesh *m, const tt_grid *g, const pset *p)
{
  double fr[4];
  tt_grid_get_ground_frame(g, fr);
  tt__metric metric;
  tt__metric_from_frame(fr, &metric);
  tt__mesh_init(m, &metric);
  const float *z = tt_grid_heights_const(g);
  size_t nx = tt_grid_width(g);
  const int32_t *b = p->box;
  int32_t cc[4][2] = {{b[0], b[1]}, {b[2], b[1]}, {b[2], b[3]}, {b[0], b[3]}};
  for (int k = 0; k < 4; k++)
    tt__mesh_add_vertex(m, cc[k][0], cc[k][1],
                        z[(size_t)cc[k][1] * nx + (size_t)cc[k][0]]);
  if (tt__mesh_orient(m, 0, 1, 2) > 0) {
    tt__mesh_add_triangle(m, 0, 1, 2);
    tt__mesh_add_triangle(m, 0, 2, 3);
  } else {
    tt__mesh_add_triangle(m, 0, 2, 1);
    tt__mesh_add_triangle(m, 0, 3, 2);
  }
  bool ok = tt__mesh_link_all(m);
  tt__mesh_clear_touched(m);
  for (int i = 0; i < p->n && ok; i++)
    ok = insert(m, g, p->c[i], p->r[i]);
  return ok;
}

/* --- every triangulation ------------------------------------------------- */

typedef struct key {
  uint8_t t[MAXT][3];
  int n;
} key;

static int cmp3(const void *x, const void *y) { return memcmp(x, y, 3); }

static void key_of(const tt__mesh *m, key *k)
{
  memset(k, 0, sizeof *k);
  for (size_t t = 0; t < m->nslots; t++) {
    if (!tt__mesh_live(m, (int32_t)t))
      continue;
    uint8_t v[3] = {(uint8_t)m->hv[3 * t], (uint8_t)m->hv[3 * t + 1],
                    (uint8_t)m->hv[3 * t + 2]};
    for (int i = 0; i < 2; i++)
      for (int j = 0; j < 2 - i; j++)
        if (v[j] > v[j + 1]) {
          uint8_t s = v[j];
          v[j] = v[j + 1];
          v[j + 1] = s;
        }
    memcpy(k->t[k->n++], v, 3);
  }
  qsort(k->t, (size_t)k->n, 3, cmp3);
}

/* A mesh with the vertices of src and the triangles of k. */
static void mesh_of(const tt__mesh *src, const key *k, tt__mesh *m)
{
  tt__mesh_init(m, &src->metric);
  for (size_t v = 0; v < src->nv; v++)
    tt__mesh_add_vertex(m, src->v[v].c, src->v[v].r, src->v[v].z);
  for (int i = 0; i < k->n; i++) {
    int32_t a = k->t[i][0], b = k->t[i][1], c = k->t[i][2];
    if (tt__mesh_orient(m, a, b, c) > 0)
      tt__mesh_add_triangle(m, a, b, c);
    else
      tt__mesh_add_triangle(m, a, c, b);
  }
  tt__mesh_link_all(m);
  tt__mesh_clear_touched(m);
}

typedef struct graph {
  key *k;
  int32_t *parent;       /* the node it was reached from (-1: the start) */
  int32_t (*flip)[2];    /* the vertex pair flipped there */
  size_t n, cap;
  int32_t *hash;
  size_t hcap;
} graph;

static uint64_t key_hash(const key *k)
{
  uint64_t h = 1469598103934665603ull;
  const uint8_t *b = (const uint8_t *)k->t;
  for (size_t i = 0; i < sizeof k->t; i++)
    h = (h ^ b[i]) * 1099511628211ull;
  return h;
}

static int32_t find_key(const graph *G, const key *k)
{
  for (size_t s = key_hash(k) & (G->hcap - 1); G->hash[s] >= 0;
       s = (s + 1) & (G->hcap - 1))
    if (memcmp(&G->k[G->hash[s]], k, sizeof *k) == 0)
      return G->hash[s];
  return -1;
}

static void graph_add(graph *G, const key *k, int32_t parent, int32_t a,
                      int32_t b)
{
  if (G->n == G->cap)
    return; /* cannot happen at these sizes: checked by the caller */
  size_t s = key_hash(k) & (G->hcap - 1);
  while (G->hash[s] >= 0)
    s = (s + 1) & (G->hcap - 1);
  G->hash[s] = (int32_t)G->n;
  G->k[G->n] = *k;
  G->parent[G->n] = parent;
  G->flip[G->n][0] = a;
  G->flip[G->n][1] = b;
  G->n++;
}

static void enumerate(const tt__mesh *start, graph *G)
{
  G->cap = 1 << 16;
  G->hcap = 1 << 18;
  G->k = malloc(G->cap * sizeof *G->k);
  G->parent = malloc(G->cap * sizeof *G->parent);
  G->flip = malloc(G->cap * sizeof *G->flip);
  G->hash = malloc(G->hcap * sizeof *G->hash);
  for (size_t i = 0; i < G->hcap; i++)
    G->hash[i] = -1;
  G->n = 0;
  key k;
  key_of(start, &k);
  graph_add(G, &k, -1, -1, -1);
  for (size_t i = 0; i < G->n; i++) {
    tt__mesh m;
    mesh_of(start, &G->k[i], &m);
    for (size_t e = 0; e < 3 * m.nslots; e++) {
      if (m.twin[e] < (int32_t)e || !tt__mesh_flippable(&m, (int32_t)e))
        continue;
      int32_t a = m.hv[e], b = m.hv[tt__next((int32_t)e)];
      tt__mesh_flip_undo u;
      tt__mesh_flip_undoable(&m, (int32_t)e, &u);
      key_of(&m, &k);
      tt__mesh_flip_revert(&m, &u);
      if (find_key(G, &k) < 0)
        graph_add(G, &k, (int32_t)i, a, b);
    }
    tt__mesh_free(&m);
  }
  CHECK(G->n < G->cap);
}

static void graph_free(graph *G)
{
  free(G->k);
  free(G->parent);
  free(G->flip);
  free(G->hash);
}

/* Each node's quality relative to the start, from the swap values along
 * the walk (exact differences for the additive criteria). */
static double *relative(const tt__mesh *start, const graph *G,
                        const tt__criterion_vt *crit, const tt_grid *g)
{
  double *q = malloc(G->n * sizeof *q);
  q[0] = 0.0;
  for (size_t i = 1; i < G->n; i++) {
    tt__mesh m;
    mesh_of(start, &G->k[G->parent[i]], &m);
    tt__crit_env env = {&m, g, NULL};
    int32_t e = tt__mesh_find_edge(&m, G->flip[i][0], G->flip[i][1]);
    q[i] = q[G->parent[i]] + crit->swap_value(&env, e);
    tt__mesh_free(&m);
  }
  return q;
}

/* --- global values of the max-type criteria ------------------------------ */

static int cmp_desc(const void *x, const void *y)
{
  double a = *(const double *)x, b = *(const double *)y;
  return a < b ? 1 : a > b ? -1 : 0;
}

/* Every triangle angle (which 0) or every angle between the normals of
 * two triangles (which 1), sorted in decreasing order; returns the count. */
static int vector_of(const tt__mesh *m, const tt_grid *g, int which,
                     double *out)
{
  double fr[4];
  tt_grid_get_ground_frame(g, fr);
  int n = 0;
  for (size_t t = 0; t < m->nslots; t++) {
    if (!tt__mesh_live(m, (int32_t)t))
      continue;
    int32_t v[3] = {m->hv[3 * t], m->hv[3 * t + 1], m->hv[3 * t + 2]};
    if (which == 0) {
      for (int k = 0; k < 3; k++)
        out[n++] = tt__gangle2(tt__geo_vec(fr, m, v[k], v[(k + 1) % 3]),
                               tt__geo_vec(fr, m, v[k], v[(k + 2) % 3]));
      continue;
    }
    tt__gvec nt = tt__gcross(tt__geo_vec(fr, m, v[0], v[1]),
                             tt__geo_vec(fr, m, v[0], v[2]));
    for (int k = 0; k < 3; k++) {
      int32_t h = 3 * (int32_t)t + k, o = m->twin[h];
      if (o < h)
        continue;
      int32_t u = o / 3;
      int32_t w[3] = {m->hv[3 * u], m->hv[3 * u + 1], m->hv[3 * u + 2]};
      tt__gvec nu = tt__gcross(tt__geo_vec(fr, m, w[0], w[1]),
                               tt__geo_vec(fr, m, w[0], w[2]));
      out[n++] = tt__gangle(nt, nu);
    }
  }
  qsort(out, (size_t)n, sizeof *out, cmp_desc);
  return n;
}

static double max_angle(const tt__mesh *m, const tt_grid *g)
{
  double *v = malloc((3 * m->nslots + 1) * sizeof *v);
  double x = vector_of(m, g, 0, v) ? v[0] : 0.0;
  free(v);
  return x;
}

static double min_angle(const tt__mesh *m, const tt_grid *g)
{
  double *v = malloc((3 * m->nslots + 1) * sizeof *v);
  int n = vector_of(m, g, 0, v);
  double x = n ? v[n - 1] : 0.0;
  free(v);
  return x;
}

/* < 0: x better (lexicographically smaller), > 0: worse, 0: equal within
 * TOL entry by entry. */
static int lex_cmp(const double *x, const double *y, int n)
{
  for (int i = 0; i < n; i++)
    if (fabs(x[i] - y[i]) > TOL)
      return x[i] < y[i] ? -1 : 1;
  return 0;
}

/* --- one point set ------------------------------------------------------- */

enum { RUN_LOCAL, RUN_LOOKAHEAD, RUN_ANNEAL, NRUN };
static const char *const run_names[NRUN] = {"local", "lookahead", "anneal"};

#define NCRIT 16
static long reached[NCRIT][NRUN], tried[NCRIT];
static long ei_cases, ei_ok, dl_cases, dl_ok;

static void run_optimiser(tt__mesh *m, const tt__criterion_vt *crit,
                          const tt_grid *g, int run, uint64_t seed)
{
  tt__crit_env env = {m, g, NULL};
  if (run == RUN_ANNEAL) {
    tt_anneal_options ao;
    memset(&ao, 0, sizeof ao);
    ao.seed = seed;
    tt__anneal_stats st;
    CHECK(tt__anneal_run(m, crit, &env, &ao, NULL, NULL, &st));
    if (crit->id != TT_CRITERION_MINMAX_ANGLE &&
        crit->id != TT_CRITERION_MINMAX_ANGLE_LEX &&
        crit->id != TT_CRITERION_ABN)
      CHECK(st.gain >= 0); /* additive: the sum is the quality */
  } else {
    tt__opt_params p = {crit, &env, run == RUN_LOOKAHEAD, NULL, NULL};
    tt__opt_stats st;
    CHECK(tt__optimize_run(m, &p, NULL, 0, &st));
  }
  check_valid(m, run_names[run]);
}

static void check_set(const tt_grid *g, const pset *p, uint64_t seed,
                      int round, uint64_t *rng)
{
  tt__mesh del;
  CHECK(build(&del, g, p));
  check_valid(&del, "Delaunay start");
  graph G;
  enumerate(&del, &G);
  /* the optima of the 2-D criteria */
  double best_max = INFINITY, best_min = -INFINITY;
  for (size_t i = 0; i < G.n; i++) {
    tt__mesh m;
    mesh_of(&del, &G.k[i], &m);
    best_max = fmin(best_max, max_angle(&m, g));
    best_min = fmax(best_min, min_angle(&m, g));
    tt__mesh_free(&m);
  }
  size_t si = (size_t)(tt_test_rand(rng) % G.n);
  tt__mesh tmp;

  /* edge insertion, from Delaunay and from the random start */
  for (int from = 0; from < 2; from++) {
    mesh_of(&del, &G.k[from ? si : 0], &tmp);
    tt__crit_env env = {&tmp, g, NULL};
    tt__edge_insert_stats es;
    CHECK(tt__edge_insert_run(&tmp, &env, NULL, NULL, &es));
    check_valid(&tmp, "edge insertion");
    double got = max_angle(&tmp, g);
    ei_cases++;
    ei_ok += fabs(got - best_max) <= TOL;
    if (!(fabs(got - best_max) <= TOL))
      TT_FAIL_("seed %" PRIu64 " round %d (%s, %d points, %zu "
               "triangulations): edge insertion from %s ends at largest "
               "angle %.12g, the optimum is %.12g", seed, round, p->kind,
               p->n + 4, G.n, from ? "a random start" : "Delaunay", got,
               best_max);
    CHECK_DBL_NEAR(es.end_max, got, TOL);
    tt__mesh_free(&tmp);
  }

  /* Delaunay's flips from the random start */
  mesh_of(&del, &G.k[si], &tmp);
  run_optimiser(&tmp, &tt__criterion_delaunay, g, RUN_LOCAL, seed);
  double dmin = min_angle(&tmp, g);
  if (!(fabs(dmin - best_min) <= TOL))
    TT_FAIL_("seed %" PRIu64 " round %d (%s): Delaunay's flips end at "
             "smallest angle %.12g, the optimum is %.12g", seed, round,
             p->kind, dmin, best_min);
  tt__mesh_free(&tmp);
  dl_cases++;
  dl_ok += fabs(dmin - best_min) <= TOL;

  /* every other criterion, from the random start */
  for (int id = 0; id < NCRIT; id++) {
    const tt__criterion_vt *crit = tt__criterion_get((tt_criterion)id);
    if (!crit || crit->id == TT_CRITERION_DELAUNAY)
      continue;
    int which = crit->id == TT_CRITERION_MINMAX_ANGLE ||
                        crit->id == TT_CRITERION_MINMAX_ANGLE_LEX
                    ? 0
                : crit->id == TT_CRITERION_ABN ? 1 : -1;
    bool only_first = crit->id == TT_CRITERION_MINMAX_ANGLE;
    double *q = which < 0 ? relative(&del, &G, crit, g) : NULL;
    /* the optimum and the start's value */
    double best_q = -INFINITY;
    double bestv[3 * MAXT], startv[3 * MAXT], v[3 * MAXT];
    int nv = 0;
    for (size_t i = 0; i < G.n; i++) {
      if (q) {
        best_q = fmax(best_q, q[i]);
        continue;
      }
      tt__mesh m;
      mesh_of(&del, &G.k[i], &m);
      nv = vector_of(&m, g, which, v);
      if (i == si)
        memcpy(startv, v, sizeof v);
      if (i == 0 || lex_cmp(v, bestv, only_first ? 1 : nv) < 0)
        memcpy(bestv, v, sizeof v);
      tt__mesh_free(&m);
    }
    tried[id]++;
    for (int run = 0; run < NRUN; run++) {
      mesh_of(&del, &G.k[si], &tmp);
      run_optimiser(&tmp, crit, g, run, seed + (uint64_t)round);
      bool worse, best;
      if (q) {
        key k;
        key_of(&tmp, &k);
        int32_t j = find_key(&G, &k);
        CHECK(j >= 0);
        double qj = j >= 0 ? q[j] : -INFINITY;
        double tol = TOL * (1 + fabs(best_q));
        worse = qj < q[si] - tol;
        best = qj >= best_q - tol;
      } else {
        vector_of(&tmp, g, which, v);
        int n = only_first ? 1 : nv;
        worse = lex_cmp(v, startv, n) > 0;
        best = lex_cmp(v, bestv, n) <= 0;
      }
      if (worse)
        TT_FAIL_("seed %" PRIu64 " round %d (%s, %d points): %s under %s "
                 "ends worse than it started", seed, round, p->kind,
                 p->n + 4, run_names[run], crit->name);
      reached[id][run] += best;
      tt__mesh_free(&tmp);
    }
    free(q);
  }
  graph_free(&G);
  tt__mesh_free(&del);
}

static void test_point_sets(uint64_t seed)
{
  tt_grid *g = bumpy(13, 11, seed);
  uint64_t rng = seed;
  long sets = 0;
  for (int round = 0; round < 48; round++) {
    pset p;
    make_set(&rng, round, 13, 11, &p);
    check_set(g, &p, seed, round, &rng);
    sets++;
  }
  printf("%ld point sets of 5-10 points: edge insertion reached the "
         "Min-Max angle optimum in %ld of %ld runs, Delaunay's flips the "
         "Max-Min angle optimum in %ld of %ld\n",
         sets, ei_ok, ei_cases, dl_ok, dl_cases);
  printf("optimum reached from a random triangulation (of %ld sets):\n",
         sets);
  printf("  %-20s %9s %9s %9s\n", "criterion", "local", "lookahead",
         "anneal");
  for (int id = 0; id < NCRIT; id++)
    if (tried[id])
      printf("  %-20s %9ld %9ld %9ld\n",
             tt__criterion_get((tt_criterion)id)->name, reached[id][0],
             reached[id][1], reached[id][2]);
  tt_grid_destroy(g);
}

/* --- beyond enumeration: 40 to 120 points --------------------------------- */

/* The Delaunay triangulation of the grid's corners and n random inner
 * points. */
static bool build_random(tt__mesh *m, const tt_grid *g, uint64_t *rng, int n)
{
  pset p;
  memset(&p, 0, sizeof p);
  p.box[2] = (int32_t)tt_grid_width(g) - 1;
  p.box[3] = (int32_t)tt_grid_height(g) - 1;
  if (!build(m, g, &p))
    return false;
  bool ok = true;
  /* points along the sides every 5 pixels, so that the largest angle is
   * not forced by a long side and a point near it */
  for (int32_t c = 5; c < p.box[2] && ok; c += 5)
    ok = insert(m, g, c, 0) && insert(m, g, c, p.box[3]);
  for (int32_t r = 5; r < p.box[3] && ok; r += 5)
    ok = insert(m, g, 0, r) && insert(m, g, p.box[2], r);
  for (int i = 0; i < n && ok; i++) {
    int32_t c = 1 + (int32_t)(tt_test_rand(rng) % (uint64_t)(p.box[2] - 1));
    int32_t r = 1 + (int32_t)(tt_test_rand(rng) % (uint64_t)(p.box[3] - 1));
    bool dup = false;
    for (size_t v = 0; v < m->nv; v++)
      dup |= m->v[v].c == c && m->v[v].r == r;
    if (!dup)
      ok = insert(m, g, c, r);
  }
  return ok;
}

/* The largest angle of every triangle, sorted in decreasing order, into
 * *out (malloc'd); the count. */
static int largest_angles(const tt__mesh *m, const tt_grid *g, double **out)
{
  tt__crit_env env = {m, g, NULL};
  double *v = malloc((m->nslots + 1) * sizeof *v);
  int n = 0;
  for (size_t t = 0; t < m->nslots; t++)
    if (tt__mesh_live(m, (int32_t)t))
      v[n++] = tt__edge_insert_tri_angle(m, &env, (int32_t)t);
  qsort(v, (size_t)n, sizeof *v, cmp_desc);
  *out = v;
  return n;
}

static bool same_mesh(const tt__mesh *a, const tt__mesh *b)
{
  return a->nslots == b->nslots &&
         memcmp(a->hv, b->hv, 3 * a->nslots * sizeof *a->hv) == 0 &&
         memcmp(a->twin, b->twin, 3 * a->nslots * sizeof *a->twin) == 0;
}

typedef struct cap_arg {
  const tt_grid *g;
  double cap;     /* no triangle may get a largest angle above this */
  long calls;
} cap_arg;

/* A stand-in for the -max_error guard: refuses any move that makes a
 * triangle with a largest angle above cap (so refusals really happen). */
static bool cap_accept(void *arg, const tt__mesh *m, const int32_t *slots,
                       int ns)
{
  cap_arg *c = arg;
  c->calls++;
  tt__crit_env env = {m, c->g, NULL};
  for (int i = 0; i < ns; i++)
    if (tt__edge_insert_tri_angle(m, &env, slots[i]) > c->cap)
      return false;
  return true;
}

typedef struct alt_arg {
  long calls;
} alt_arg;

/* Refuses every other move. */
static bool alt_accept(void *arg, const tt__mesh *m, const int32_t *slots,
                       int ns)
{
  (void)m;
  (void)slots;
  (void)ns;
  alt_arg *a = arg;
  return a->calls++ % 2 == 0;
}

static void test_medium(uint64_t seed)
{
  tt_grid *g = bumpy(60, 45, seed);
  uint64_t rng = seed * 31 + 7;
  int better = 0, rounds = 12, anneal_better = 0;
  const tt__criterion_vt *mm = tt__criterion_get(TT_CRITERION_MINMAX_ANGLE);
  const tt__criterion_vt *l2 = tt__criterion_get(TT_CRITERION_L2);
  for (int round = 0; round < rounds; round++) {
    int n = 40 + (int)(tt_test_rand(&rng) % 81);
    tt__mesh a, b;
    uint64_t r0 = rng;
    CHECK(build_random(&a, g, &rng, n));
    rng = r0;
    CHECK(build_random(&b, g, &rng, n));
    double del = max_angle(&a, g);
    tt__crit_env ea = {&a, g, NULL}, eb = {&b, g, NULL};
    tt__opt_params pl = {mm, &ea, false, NULL, NULL};
    tt__opt_stats sl;
    CHECK(tt__optimize_run(&a, &pl, NULL, 0, &sl));
    tt__edge_insert_stats es;
    CHECK(tt__edge_insert_run(&b, &eb, NULL, NULL, &es));
    check_valid(&b, "edge insertion, medium");
    double loc = max_angle(&a, g), ins = max_angle(&b, g);
    CHECK_DBL_LE(ins, loc + TOL);
    CHECK_DBL_LE(ins, del + TOL);
    CHECK_DBL_NEAR(es.end_max, ins, TOL);
    better += ins < loc - TOL;
    if (getenv("TT_VERBOSE"))
      printf("%d points: largest angle Delaunay %.6f, local %.6f (%ld "
             "swaps), edge insertion %.6f (%ld insertions, %ld edges "
             "tried)\n", n + 4, del, loc, sl.swaps, ins, es.insertions,
             es.candidates);
    CHECK(es.optimum_reached);
    CHECK_DBL_NEAR(es.optimum_max, ins, TOL);
    /* again from its own result (triangles set aside may have become
     * improvable): the largest angle stays, the sorted vector of the
     * triangles' largest angles never gets worse */
    double *v1 = NULL, *v2 = NULL;
    int n1 = largest_angles(&b, g, &v1);
    tt__edge_insert_stats es2;
    CHECK(tt__edge_insert_run(&b, &eb, NULL, NULL, &es2));
    int n2 = largest_angles(&b, g, &v2);
    CHECK_INT_EQ(n1, n2);
    CHECK(lex_cmp(v2, v1, n1) <= 0);
    CHECK_DBL_NEAR(es2.end_max, ins, TOL);
    free(v1);
    free(v2);
    tt__mesh_free(&a);
    tt__mesh_free(&b);

    /* annealing: the same seed gives the same mesh word for word, and
     * under L2 it never ends above its start */
    tt__mesh c, d;
    rng = r0;
    CHECK(build_random(&c, g, &rng, n));
    rng = r0;
    CHECK(build_random(&d, g, &rng, n));
    tt__crit_env ec = {&c, g, NULL}, ed = {&d, g, NULL};
    tt_anneal_options ao;
    memset(&ao, 0, sizeof ao);
    ao.seed = seed + (uint64_t)round;
    ao.stages = 40;
    tt__anneal_stats s1, s2;
    CHECK(tt__anneal_run(&c, l2, &ec, &ao, NULL, NULL, &s1));
    CHECK(tt__anneal_run(&d, l2, &ed, &ao, NULL, NULL, &s2));
    check_valid(&c, "anneal, medium");
    CHECK(same_mesh(&c, &d));
    CHECK_INT_EQ(s1.swaps, s2.swaps);
    /* a log of 8 records: the best is saved whole again and again and the
     * log replayed; the same mesh word for word */
    tt__mesh f;
    rng = r0;
    CHECK(build_random(&f, g, &rng, n));
    tt__crit_env ef = {&f, g, NULL};
    tt__anneal_stats s4;
    CHECK(tt__anneal_run_log(&f, l2, &ef, &ao, NULL, NULL, 8, &s4));
    check_valid(&f, "anneal, a log of 8");
    CHECK(s4.saves > 0 && s1.saves == 0);
    CHECK(same_mesh(&c, &f));
    CHECK_INT_EQ(s4.swaps, s1.swaps);
    tt__mesh_free(&f);
    CHECK(s1.gain >= 0);
    CHECK(s1.worse > 0); /* it did wander uphill */
    tt__mesh_free(&d);
    anneal_better += s1.gain > 0;

    /* a refusing accept callback: no triangle of the result above the cap
     * unless it was there at the start */
    tt__mesh e;
    rng = r0;
    CHECK(build_random(&e, g, &rng, n));
    tt__crit_env ee = {&e, g, NULL};
    cap_arg ca = {g, max_angle(&e, g) * 0.999, 0};
    tt__anneal_stats s3;
    CHECK(tt__anneal_run(&e, mm, &ee, &ao, cap_accept, &ca, &s3));
    check_valid(&e, "anneal with refusals");
    CHECK(s3.refused > 0);
    tt__edge_insert_stats es3;
    cap_arg cb = {g, INFINITY, 0};
    CHECK(tt__edge_insert_run(&e, &ee, cap_accept, &cb, &es3));
    CHECK(cb.calls == es3.insertions);
    /* every other insertion refused: the old triangles go back, the
     * triangle is set aside, the mesh stays valid and no worse */
    double *w1 = NULL, *w2 = NULL;
    alt_arg aa = {0};
    tt__edge_insert_stats es4;
    tt__mesh h;
    rng = r0;
    CHECK(build_random(&h, g, &rng, n));
    tt__crit_env eh = {&h, g, NULL};
    int m1 = largest_angles(&h, g, &w1);
    CHECK(tt__edge_insert_run(&h, &eh, alt_accept, &aa, &es4));
    check_valid(&h, "edge insertion with refusals");
    int m2 = largest_angles(&h, g, &w2);
    CHECK_INT_EQ(m1, m2);
    CHECK(lex_cmp(w2, w1, m1) <= 0);
    CHECK(es4.refused > 0 || aa.calls < 2);
    CHECK_INT_EQ(es4.refused + es4.insertions, aa.calls);
    free(w1);
    free(w2);
    tt__mesh_free(&h);
    tt__mesh_free(&c);
    tt__mesh_free(&e);
  }
  printf("40-120 points: edge insertion below local swap's largest angle in "
         "%d of %d sets; annealing under L2 gained in %d of %d\n", better,
         rounds, anneal_better, rounds);
  tt_grid_destroy(g);
}

/* --- the polygon DP on convex polygons ----------------------------------- */

#define MAXN 9

typedef struct cpoly {
  int n;
  int64_t x[MAXN], y[MAXN];
  double z[MAXN];
} cpoly;

enum { M_MAX_ANGLE, M_MIN_ANGLE, M_MAX_EDGE, M_SUM_PERIMETER, M_AREA3,
       M_MAX_AREA, M_MIN_AREA, NMEASURE };
static const char *const measure_names[NMEASURE] = {
    "largest angle", "smallest angle (max-min)", "longest edge",
    "sum of perimeters", "total 3-D area", "largest area",
    "smallest area (max-min)"};
static const bool measure_sum[NMEASURE] = {false, false, false, true, true,
                                           false, false};

typedef struct marg {
  const cpoly *p;
  int which;
} marg;

static double angle_at(const cpoly *p, int a, int b, int c)
{
  double ux = (double)(p->x[b] - p->x[a]), uy = (double)(p->y[b] - p->y[a]);
  double vx = (double)(p->x[c] - p->x[a]), vy = (double)(p->y[c] - p->y[a]);
  return atan2(fabs(ux * vy - uy * vx), ux * vx + uy * vy);
}

static double len(const cpoly *p, int a, int b)
{
  return hypot((double)(p->x[b] - p->x[a]), (double)(p->y[b] - p->y[a]));
}

static double measure(void *arg, int i, int j, int k)
{
  const marg *m = arg;
  const cpoly *p = m->p;
  double a1 = angle_at(p, i, j, k), a2 = angle_at(p, j, k, i),
         a3 = angle_at(p, k, i, j);
  double e1 = len(p, i, j), e2 = len(p, j, k), e3 = len(p, k, i);
  double ux = (double)(p->x[j] - p->x[i]), uy = (double)(p->y[j] - p->y[i]),
         uz = p->z[j] - p->z[i];
  double vx = (double)(p->x[k] - p->x[i]), vy = (double)(p->y[k] - p->y[i]),
         vz = p->z[k] - p->z[i];
  double cx = uy * vz - uz * vy, cy = uz * vx - ux * vz, cz = ux * vy - uy * vx;
  double area2 = 0.5 * fabs(cz);
  double area3 = 0.5 * sqrt(cx * cx + cy * cy + cz * cz);
  switch (m->which) {
  case M_MAX_ANGLE: return fmax(a1, fmax(a2, a3));
  case M_MIN_ANGLE: return -fmin(a1, fmin(a2, a3));
  case M_MAX_EDGE: return fmax(e1, fmax(e2, e3));
  case M_SUM_PERIMETER: return e1 + e2 + e3;
  case M_AREA3: return area3;
  case M_MAX_AREA: return area2;
  default: return -area2;
  }
}

/* The value of a given triangulation (n - 2 index triples). */
static double value_of(const marg *m, const int32_t *tris, int nt)
{
  double v = measure_sum[m->which] ? 0.0 : -INFINITY;
  for (int t = 0; t < nt; t++) {
    double x = measure((void *)m, tris[3 * t], tris[3 * t + 1],
                       tris[3 * t + 2]);
    v = measure_sum[m->which] ? v + x : fmax(v, x);
  }
  return v;
}

/* Every triangulation of a convex polygon, one by one, each evaluated in
 * full: the sub-polygons still to triangulate are intervals i..j on a
 * stack (each level works on its own copy); the top one with j - i >= 2
 * takes every apex k in turn. Each triangulation is one sequence of apex
 * choices, so it is met exactly once. */
static void enum_all(const marg *m, const int *iv, int niv, int32_t *tris,
                     int nt, double *best, long *count)
{
  while (niv > 0 && iv[2 * niv - 1] - iv[2 * niv - 2] < 2)
    niv--;
  if (niv == 0) {
    (*count)++;
    *best = fmin(*best, value_of(m, tris, nt));
    return;
  }
  int i = iv[2 * niv - 2], j = iv[2 * niv - 1];
  int mine[4 * MAXN];
  memcpy(mine, iv, 2 * (size_t)(niv - 1) * sizeof *mine);
  for (int k = i + 1; k < j; k++) {
    tris[3 * nt] = i;
    tris[3 * nt + 1] = k;
    tris[3 * nt + 2] = j;
    mine[2 * niv - 2] = i;
    mine[2 * niv - 1] = k;
    mine[2 * niv] = k;
    mine[2 * niv + 1] = j;
    enum_all(m, mine, niv + 1, tris, nt + 1, best, count);
  }
}

static bool convex_polygon(uint64_t *rng, int n, cpoly *p)
{
  /* points on a circle of radius 1000, jittered and rounded; kept only
   * when strictly convex */
  double a[MAXN];
  for (int i = 0; i < n; i++)
    a[i] = 2 * TT__PI * tt_test_uniform(rng);
  for (int i = 1; i < n; i++)
    for (int j = i; j > 0 && a[j - 1] > a[j]; j--) {
      double t = a[j];
      a[j] = a[j - 1];
      a[j - 1] = t;
    }
  p->n = n;
  for (int i = 0; i < n; i++) {
    p->x[i] = (int64_t)llround(1000 * cos(a[i]) + 20 * tt_test_uniform(rng));
    p->y[i] = (int64_t)llround(1000 * sin(a[i]) + 20 * tt_test_uniform(rng));
    p->z[i] = 300 * tt_test_uniform(rng);
  }
  for (int i = 0; i < n; i++) {
    int j = (i + 1) % n, k = (i + 2) % n;
    __int128 c = (__int128)(p->x[j] - p->x[i]) * (p->y[k] - p->y[i]) -
                 (__int128)(p->y[j] - p->y[i]) * (p->x[k] - p->x[i]);
    if (c <= 0)
      return false;
  }
  return true;
}

static void test_convex_dp(uint64_t seed)
{
  uint64_t rng = seed ^ 0x5bd1e995u;
  int done = 0;
  for (int round = 0; done < 60 && round < 2000; round++) {
    cpoly p;
    int n = 4 + (int)(tt_test_rand(&rng) % (MAXN - 3));
    if (!convex_polygon(&rng, n, &p))
      continue;
    done++;
    for (int w = 0; w < NMEASURE; w++) {
      marg m = {&p, w};
      long count = 0;
      double best = INFINITY;
      int iv[2] = {0, n - 1};
      int32_t all[3 * MAXN], tris[3 * MAXN];
      enum_all(&m, iv, 1, all, 0, &best, &count);
      static const long catalan[MAXN + 1] = {0, 0, 0, 1, 2, 5, 14, 42, 132,
                                             429};
      CHECK_INT_EQ(count, catalan[n]);
      double val;
      CHECK(tt__polygon_dp(n, p.x, p.y, 1,
                           measure_sum[w] ? TT__DP_SUM : TT__DP_MAX, measure,
                           &m, tris, &val));
      double tol = TOL * (1 + fabs(best));
      if (!(fabs(val - best) <= tol) ||
          !(fabs(value_of(&m, tris, n - 2) - best) <= tol))
        TT_FAIL_("seed %" PRIu64 " round %d: %d-gon, %s: DP %.17g, its "
                 "triangulation %.17g, best of %ld triangulations %.17g",
                 seed, round, n, measure_names[w], val,
                 value_of(&m, tris, n - 2), count, best);
    }
  }
  CHECK(done == 60);
  printf("polygon DP: optimum on %d convex polygons of 4-%d vertices under "
         "%d measures\n", done, MAXN, NMEASURE);
}

int main(void)
{
  uint64_t seed = (uint64_t)time(NULL);
  const char *env = getenv("TT_SEED");
  if (env)
    seed = strtoull(env, NULL, 10);
  printf("seed %" PRIu64 "\n", seed);
  ctx = tt_context_create();
  TT_RUN(test_point_sets(seed));
  TT_RUN(test_medium(seed));
  TT_RUN(test_convex_dp(seed));
  tt_context_destroy(ctx);
  TT_TEST_DONE();
}
