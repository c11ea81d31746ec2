/* Stand-ins for what a generated C file defines for its arm before the runtime's routines
   (never copied): the size of the polynomial steps' arrays and the general method's tables of
   one sample split, so that derive/c/runtime.c and general.c compile on their own (as
   derive/runtime/arm.py lets the Python runtime import). */
#include <math.h>
#include <stddef.h>

#define DK_POLY_MAX 6
#define DK_VALUES_MAX 8
#define DK_SEED_TOL (0.0)
#define DK_REFINE_N 2
#define DK_REFINE_M 2
#define DK_REFINE_ROWS 6
#define DK_REFINE_TASK 0
#define DK_REFINE_AXIS 2
#define DK_REFINE_CONE 2

#define DK_RR_SPLIT_COUNT 1
#define DK_RR_LENGTH (1.0)
static const int DK_RR_REVERSED[DK_RR_SPLIT_COUNT] = {0};
static const double DK_RR_FILL[DK_RR_SPLIT_COUNT][7][4] = {{{0.0}}};
static const double DK_RR_TRUE[DK_RR_SPLIT_COUNT][7][4] = {{{0.0}}};
static const int DK_RR_FLIPS[2] = {0, 1};
#define DK_RR_SPURIOUS_WIDTH 2
static const int DK_RR_PIVOTS[DK_RR_SPLIT_COUNT][DK_RR_SPURIOUS_WIDTH / 2] = {{0}};
static const int DK_RR_SPURIOUS_COUNT[DK_RR_SPLIT_COUNT] = {0};
static const double DK_RR_SPURIOUS[DK_RR_SPLIT_COUNT][12][DK_RR_SPURIOUS_WIDTH] = {{{0.0}}};

static void dk_rr_fill(int k, double l_x, double l_y, double l_z, double p_x, double p_y,
                       double p_z, double out[490])
{
    out[0] = k + l_x + l_y + l_z + p_x + p_y + p_z;
}
