/*
 * registry.c -- the table of criteria: id <-> name <-> vtable. Adding a
 * criterion means one file in src/criteria/ and one row here.
 */
#include "criteria/geometry.h"

#include <string.h>

static const tt__criterion_vt *const table[] = {
    &tt__criterion_delaunay,        &tt__criterion_minmax_angle,
    &tt__criterion_minmax_angle_lex, &tt__criterion_min_area,
    &tt__criterion_mean_curvature,  &tt__criterion_gaussian,
    &tt__criterion_abn,             &tt__criterion_abn_sum,
    &tt__criterion_abn_sumsq,       &tt__criterion_l2,
};

#define NCRIT (sizeof table / sizeof table[0])

const tt__criterion_vt *tt__criterion_get(tt_criterion id)
{
  for (size_t i = 0; i < NCRIT; i++)
    if (table[i]->id == id)
      return table[i];
  return NULL;
}

const char *tt_criterion_name(tt_criterion criterion)
{
  const tt__criterion_vt *vt = tt__criterion_get(criterion);
  return vt ? vt->name : NULL;
}

tt_status tt_criterion_parse(tt_context *ctx, const char *name,
                             tt_criterion *out_criterion)
{
  if (name && out_criterion)
    for (size_t i = 0; i < NCRIT; i++)
      if (tt__name_equal(table[i]->name, name)) {
        *out_criterion = table[i]->id;
        return TT_OK;
      }
  char known[256] = "";
  for (size_t i = 0; i < NCRIT; i++) {
    if (i)
      strncat(known, ", ", sizeof known - strlen(known) - 1);
    strncat(known, table[i]->name, sizeof known - strlen(known) - 1);
  }
  return tt__error(ctx, TT_ERR_ARG, "unknown criterion '%s' (known: %s)",
                   name ? name : "(null)", known);
}
