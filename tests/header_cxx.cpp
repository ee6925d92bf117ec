// The public header compiles alone in C++ (and links).
#include "terratin/terratin.h"
#include <cstring>
int main() { return std::strcmp(tt_version(), TT_VERSION_STRING) != 0; }
