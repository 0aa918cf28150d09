/* The one translation unit of the test binary that compiles the implementation. The tests run
   with the library's expensive self-checks on. */
#define SPH_VALIDATE
#define SPH_IMPLEMENTATION
#include "../sph.h"
