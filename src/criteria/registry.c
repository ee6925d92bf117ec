/*
 * registry.c -- the table of criteria: id <-> name <-> vtable. Adding a
 * criterion means one file in src/criteria/ and one row here.
 */
#include "criterion.h"

#include <string.h>

static const tt__criterion_vt *const table[] = {
    &tt__criterion_delaunay,
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
      if (strcmp(table[i]->name, name) == 0) {
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
