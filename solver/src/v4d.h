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
// c[0..3] = the four columns of a column-major 4 x 4 (sp_mat4's m).
#define SP_V4D_LOAD_COLS(c, m) (SP_V4D_LOAD((c)[0], (m)), SP_V4D_LOAD((c)[1], (m) + 4), SP_V4D_LOAD((c)[2], (m) + 8), SP_V4D_LOAD((c)[3], (m) + 12))
// v = M (x, 1) for a column-major 4 x 4 m and a point x[0..2]: its columns
// times x's entries, all rows at once, the same sums in the same order as
// sp_mat4_point's rows (lane 3 is M's bottom row against (x, 1)).
#define SP_V4D_MAT4_POINT(v, m, x)                                   \
    do {                                                             \
        sp_v4d c_[4];                                                \
        SP_V4D_LOAD_COLS(c_, m);                                     \
        (v) = c_[0] * (x)[0] + c_[1] * (x)[1] + c_[2] * (x)[2] + c_[3]; \
    } while (0)

#endif
