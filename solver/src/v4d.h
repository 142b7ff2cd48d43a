// v4d.h: four doubles in one vector register (the GCC/Clang vector
// extension) for the solver's products with 4 x 4 columns. Lane-wise + and *
// are the same IEEE operations as scalar ones, so with contraction off and no
// fast-math a loop written with them gives the same bits as the scalar loop
// it replaces, in fewer instructions (SSE2 pairs, or one AVX2 register).
// Macros, not functions: a function returning a 32-byte vector has a
// different ABI with and without AVX (GCC's -Wpsabi).
#ifndef SP_V4D_H
#define SP_V4D_H

#include <string.h>

typedef double sp_v4d __attribute__((vector_size(32)));

// v = p[0..3], unaligned (sp_mat4 is only 8-byte aligned).
#define SP_V4D_LOAD(v, p) memcpy(&(v), (p), sizeof(sp_v4d))
#define SP_V4D_SPLAT(x) ((sp_v4d){(x), (x), (x), (x)})

#endif
