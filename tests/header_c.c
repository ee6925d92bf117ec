/* The public header compiles alone in C (and links). */
#include "terratin/terratin.h"
#include <string.h>
int main(void) { return strcmp(tt_version(), TT_VERSION_STRING) != 0; }
