// Placeholder entry point; the command line is being written (see src/app).
#include "scene/cornell.h"
int main() { return 0; }
