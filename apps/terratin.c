#include <stdio.h>
int main(void) { puts("terratin: being built"); return 1; }
