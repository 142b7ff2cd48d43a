/// sp/curve.h: 2D polylines, arc-length resampling, correspondences, and
/// assigning strokes to abstraction curves.
///
/// How to use: resample a stroke and an abstraction curve to the same count
/// m, then pair their samples with one of the paper's two procedures
/// (Method, "Correspondences"):
///
///     sp_vec2 y[64], z[64];
///     int match[64];
///     sp_curve_resample(stroke.points, stroke.count, false, 64, y);
///     sp_curve_resample(curve_pts, curve_n, false, 64, z);
///     sp_ordered_info info;
///     sp_corr_ordered(y, z, 64, false, match, &info);  // y[i] <-> z[match[i]]
///
/// or `sp_corr_closest` (closest points both ways, my + mz pairs). With
/// several strokes and several curves, `sp_assign_strokes` decides which
/// stroke goes with which curve (optimal assignment, Kuhn-Munkres), so the
/// drawing order and direction of the strokes do not matter.
///
/// Units: pixels (origin top-left, y down); costs are squared pixels.
/// Callers own every buffer; sizes are given on each function. Inputs must
/// be finite: functions check and return SP_ERR_INVALID on NaN/Inf, never
/// propagate it. Everything is deterministic: the same input gives the same
/// bits, and exact ties go to the lowest index.
#ifndef SP_CURVE_H
#define SP_CURVE_H

#include <stdbool.h>

#include "sp/math.h"
#include "sp/result.h"
#include "sp/rig.h"
#include "sp/sketch.h"

#ifdef __cplusplus
extern "C" {
#endif

/// A non-owning view of a polyline: `count` points, pixels.
typedef struct sp_polyline {
    const sp_vec2* points; ///< count points, pixels
    int count;             ///< >= 1
    bool closed;           ///< a loop: the segment points[count-1] -> points[0] belongs to it
} sp_polyline;

// ---------------------------------------------------------------------------
// Polylines

/// True when n >= 1 and every coordinate is finite.
bool sp_curve_is_valid(const sp_vec2* pts, int n);

/// Arc length in pixels; includes the closing segment when `closed`.
/// 0 for n <= 1.
double sp_curve_length(const sp_vec2* pts, int n, bool closed);

/// Arc-length resampling to exactly m evenly spaced samples, O(n + m).
///
/// pts: n points (n >= 1), out: m points (m >= 1); out must not overlap pts.
/// - open: sample k sits at arc length k*L/(m-1); out[0] == pts[0] and
///   out[m-1] == pts[n-1] exactly. With m == 1 the single sample is pts[0].
/// - closed: the loop includes the closing segment; sample k sits at arc
///   length k*L/m from pts[0], so out[0] == pts[0] and the spacing across
///   the seam (out[m-1] -> out[0]) is the same as every other.
/// Duplicate points and zero-length segments are skipped; a stroke of zero
/// length (one point, or all points equal) gives m copies of pts[0].
/// Returns SP_ERR_INVALID when n < 1, m < 1, a coordinate is not finite or
/// the length overflows.
sp_result sp_curve_resample(const sp_vec2* pts, int n, bool closed, int m, sp_vec2* out);

/// Cleans a raw touch stroke: drops every point closer than `min_step`
/// pixels to the last kept point (min_step <= 0 drops exact consecutive
/// duplicates only). The first point is always kept; the last input point
/// is always kept too (it replaces the last kept point when that one is too
/// close and is not the first, else it is appended unless equal to the
/// first). out: up to n points; may equal pts (in place). Returns the number of points written (0 when n <= 0).
int sp_curve_clean(const sp_vec2* pts, int n, double min_step, sp_vec2* out);

/// Where a stroke starts going over itself again: the first point of the
/// last stretch (at least `min_share` of its length) that lies, all but a
/// tenth of it, within `tol` pixels of the stroke before that point: a loop
/// gone round twice, a line drawn out and back along itself, following it
/// in order (not shading drawn back and forth, each pass over the last one
/// only, nor a scribble here and there over itself). Returns how many
/// points to keep, the stretch cut off with what leads into it without
/// being gone over (the pen's jump back to the start; pts[0 .. r-1],
/// r >= 2; a loop after the point nearest where it began), or n when
/// the stroke does not go over itself (n < 4, tol <= 0 or a length of 0
/// included). O(64 n + 64^3).
int sp_curve_retrace_start(const sp_vec2* pts, int n, double tol, double min_share);

/// Light Laplacian smoothing: `iterations` passes of (1/4, 1/2, 1/4) over
/// neighbours. Open polylines keep their end points; closed ones wrap.
/// out: n points; may equal pts (in place). n < 3 copies the input.
void sp_curve_smooth(const sp_vec2* pts, int n, bool closed, int iterations, sp_vec2* out);

// ---------------------------------------------------------------------------
// Correspondences (paper, Method: "Correspondences")

/// What the ordered procedure found.
typedef struct sp_ordered_info {
    bool reversed; ///< y was drawn against z's direction
    int shift;     ///< closed curves: y[0] pairs with z[shift]; 0 for open curves
    double cost;   ///< sum over i of |y[i] - z[match[i]]|^2, px^2
} sp_ordered_info;

/// First procedure: in-order correspondences between m stroke samples y and
/// m abstraction samples z (resampled to the same count), O(m) for open
/// curves and O(m^2) for closed ones (every cyclic shift in both directions
/// is tried by brute force: 2*m*m distance evaluations, ~2e6 for m = 1000).
///
/// Candidates, the one of lowest cost wins:
/// - open:   forward match[i] = i; reversed match[i] = m-1-i.
/// - closed: forward match[i] = (i + s) mod m; reversed match[i] = (s - i) mod m,
///           for every shift s in [0, m).
/// Exact ties go to forward, then the lowest shift. The shift is in whole
/// samples, so on a closed curve the start point is found to within half a
/// sample spacing.
/// match: m entries (may be NULL), a permutation of 0..m-1 indexing z.
/// info: may be NULL. Returns SP_ERR_INVALID for m < 1 or non-finite input.
sp_result sp_corr_ordered(const sp_vec2* y, const sp_vec2* z, int m, bool closed, int* match, sp_ordered_info* info);

/// The pairing of one candidate: match[i] = (shift + i) mod m, or
/// (shift - i) mod m when reversed (what sp_corr_ordered writes for its best).
void sp_corr_ordered_match(const sp_ordered_info* c, int m, int* match);

/// The alternatives sp_corr_ordered chooses from on a closed curve, best
/// first: the local minima of its cost over the cyclic shifts of each
/// direction, at most k, no two of one direction within m / 20 shifts of
/// each other. Returns how many were written to out (0 for m < 3, k < 1,
/// non-finite input or no memory).
int sp_corr_ordered_candidates(const sp_vec2* y, const sp_vec2* z, int m, sp_ordered_info* out, int k);

/// One correspondence: y[y] <-> z[z].
typedef struct sp_corr_pair {
    int y; ///< index into the stroke samples
    int z; ///< index into the abstraction samples
} sp_corr_pair;

/// Second procedure: closest points in both directions, so every stroke
/// sample and every abstraction sample has a partner. pairs: my + mz
/// entries: pairs[i] = {i, closest z to y[i]} for i < my, then
/// pairs[my + j] = {closest y to z[j], j}. A mutually closest pair appears
/// twice (it then weighs double in the energy, as the two directions count
/// separately). cost (may be NULL): the sum of squared distances over all
/// my + mz pairs, px^2.
///
/// Brute force (O(my*mz), exact ties to the lowest index) while
/// my*mz <= SP_CORR_BRUTE_MAX; above it an exact single k-d tree (FLANN) per
/// direction, O((my + mz) log), whose ties between exactly equidistant
/// candidates are broken by the tree (still deterministic, not necessarily
/// the lowest index). Returns SP_ERR_INVALID for my < 1, mz < 1 or
/// non-finite input, SP_ERR_NO_MEMORY / SP_ERR_INTERNAL if the tree fails.
sp_result sp_corr_closest(const sp_vec2* y, int my, const sp_vec2* z, int mz, sp_corr_pair* pairs, double* cost);

/// Above this many distance evaluations sp_corr_closest uses a k-d tree.
enum { SP_CORR_BRUTE_MAX = 1 << 20 };

/// Distance from each query q[i] to a set of polylines through p[0..n): the
/// segments (v, next[v]) for every v with next[v] >= 0 (a closed curve links
/// its last point to its first); a point in no segment counts on its own.
/// Exact, by a sweep over the points sorted by x (a query stops where the x
/// gap exceeds its best distance plus half the longest segment). out: nq
/// distances. Returns SP_ERR_INVALID for n < 1 or a next[] index out of
/// range; falls back to scanning every segment when out of memory.
sp_result sp_polyline_distances(const sp_vec2* p, const int* next, int n, const sp_vec2* q, int nq, double* out);

// ---------------------------------------------------------------------------
// Assignment (drawing-order independence)

/// Optimal assignment (Kuhn-Munkres, O(min^2 * max)) on a rows by cols cost
/// matrix, row-major, finite entries (any sign). Every row is assigned when
/// rows <= cols, every column when rows > cols; the rest get -1.
/// row_to_col: rows entries; col_to_row: cols entries or NULL; total: the
/// summed cost of the assignment or NULL. Deterministic: exact ties resolve
/// the same way for the same matrix (lowest column first in the search).
/// rows == 0 or cols == 0 is valid (everything -1, total 0).
/// Returns SP_ERR_INVALID for negative sizes or non-finite costs,
/// SP_ERR_NO_MEMORY if the O(rows + cols) work space cannot be allocated.
sp_result sp_assign_hungarian(const double* cost, int rows, int cols, int* row_to_col, int* col_to_row, double* total);

/// Options for sp_assign_strokes; zero-initialised means defaults.
typedef struct sp_assign_desc {
    int samples;             ///< samples per stroke and per curve for the cost; 0: 64
    sp_correspondence match; ///< SP_CORR_ORDERED (default): ordered cost, best direction (and
                             ///< cyclic shift); SP_CORR_CLOSEST: closest-point cost both ways
} sp_assign_desc;

/// One stroke's assignment.
typedef struct sp_stroke_match {
    int curve;     ///< assigned curve, or -1 when unassigned (more strokes than curves)
    bool reversed; ///< ordered cost: the stroke runs against the curve (false for closest)
    int shift;     ///< ordered cost on a closed curve: stroke sample 0 pairs with curve sample
                   ///< `shift` of the `samples`-point resampling, else 0
    double cost;   ///< mean squared distance of the pair, px^2 (ordered: over `samples`
                   ///< pairs; closest: over 2*`samples` pairs); 0 when unassigned
} sp_stroke_match;

/// Assigns strokes to abstraction curves (paper: prescribed drawing order;
/// here: free). Every stroke and every curve is resampled to `samples`
/// points (a stroke as closed when compared with a closed curve), the pair
/// cost is the ordered or closest-point mean squared distance, and the
/// assignment minimising the summed cost is taken.
///
/// With more strokes than curves the extra strokes get curve -1; with fewer,
/// some curves get no stroke (curve_to_stroke -1). The result depends only
/// on the strokes' shapes, not on their order or drawing direction: each
/// stroke is put into a canonical direction before resampling (so a reversed
/// stroke gives bit-identical costs) and the cost matrix's rows are sorted
/// by content before the assignment.
///
/// out: stroke_count entries. curve_to_stroke: curve_count entries or NULL.
/// Returns SP_ERR_INVALID (with a message naming the stroke or curve) for an
/// empty stroke or curve, or non-finite coordinates; SP_ERR_NO_MEMORY.
sp_result sp_assign_strokes(const sp_stroke* strokes, int stroke_count, const sp_polyline* curves, int curve_count,
                            const sp_assign_desc* desc, sp_stroke_match* out, int* curve_to_stroke, sp_error* err);

#ifdef __cplusplus
}
#endif
#endif
