/* dim.h - the dimension the library is compiled for and the index conventions of its vectors and
 * tensors (docs/development.md, "Dimensions").
 *
 * DIM is a compile-time constant (MIXSPH_DIM, 2 by default): every loop over components is
 * `for (int d = 0; d < DIM; d++)`, which the compiler unrolls, so the 2D build runs the same
 * arithmetic as a code written for two components (measured: docs/performance.md). Vectors are
 * stored as DIM component arrays (struct-of-arrays, for the vectorised pair loops). The last
 * component is the vertical one, along which gravity acts: (x, z) in 2D, (x, y, z) in 3D.
 *
 * Symmetric tensors (the deviatoric stress) are stored as their independent components in an
 * order whose 2D part is a prefix of the 3D one: xx, xz, zz, yy, then xy, yz. The 2D model is
 * plane strain: its stress keeps the out-of-plane normal component yy (4 in 2D), while xy and yz
 * vanish there (6 in 3D). */
#ifndef MIXSPH_DIM_H
#define MIXSPH_DIM_H
#include <math.h>

#ifndef MIXSPH_DIM
#define MIXSPH_DIM 2
#endif
#if MIXSPH_DIM != 2 && MIXSPH_DIM != 3
#error "MIXSPH_DIM must be 2 or 3"
#endif

#define DIM MIXSPH_DIM
#define DIM_UP (DIM - 1) /* the vertical component (gravity acts along -e_up) */

/* The components of a stored symmetric tensor (see above). */
enum { SYM_XX = 0, SYM_XZ = 1, SYM_ZZ = 2, SYM_YY = 3, SYM_XY = 4, SYM_YZ = 5 };
#define SYM_N (DIM == 2 ? 4 : 6)

/* SYM index of the tensor component (a, b), a, b < 3, in 3D axis numbering x = 0, y = 1, z = 2. */
static inline int sym_index3(int a, int b)
{
    static const int t[3][3] = {{SYM_XX, SYM_XY, SYM_XZ}, {SYM_XY, SYM_YY, SYM_YZ}, {SYM_XZ, SYM_YZ, SYM_ZZ}};
    return t[a][b];
}

/* SYM index of component (a, b) of a DIM-vector basis (in 2D: 0 = x, 1 = z). */
static inline int sym_index(int a, int b)
{
    return DIM == 3 ? sym_index3(a, b) : sym_index3(a == 1 ? 2 : a, b == 1 ? 2 : b);
}

/* Before a loop over components inside a vectorised (omp simd) loop: unroll it completely, so
 * that the vectoriser sees straight-line code (a nested component loop left rolled, such as the
 * triangle of a symmetric tensor, stops the vectorisation: "multiple nested loops"). */
#define DIM_UNROLL _Pragma("GCC unroll 16")

/* The axis letters of component d, for file columns ("x", "z" in 2D; "x", "y", "z" in 3D). */
#if DIM == 2
#define DIM_AXES "xz"
#else
#define DIM_AXES "xyz"
#endif

/* The length of a DIM-vector: hypot in 2D (no overflow, and the rounding the 2D code has always
 * had), the root of the sum of squares in 3D. */
static inline double dim_norm(const double v[DIM])
{
#if DIM == 2
    return hypot(v[0], v[1]);
#else
    return sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
#endif
}

/* The volume of a lattice cell of side dx, dx^DIM (dx dx in 2D: per unit depth) [m^DIM]. */
static inline double dim_cell_volume(double dx)
{
    double v = dx;
    for (int d = 1; d < DIM; d++) v *= dx;
    return v;
}

#endif
