/// stroke_pieces.h: a line drawn in pieces, found and joined for redraw
/// posing (solve_cmd.c). People lift the pen mid-line: a limb drawn in two
/// strokes, end to end, is one curve's line, but the solver gives a curve
/// one stroke, so a piece was left unused and the limb fitted short.
///
///     int next[n]; bool flip[n];
///     int joins = sp_pieces_find(sk, keep, surplus, -1, next, flip);
///     sp_sketch lines; int line_of[n];
///     if (joins > 0 && sp_pieces_join(sk, next, flip, &lines, line_of)) ... sp_sketch_free(&lines);
#ifndef SP_STROKE_PIECES_H
#define SP_STROKE_PIECES_H

#include <stdbool.h>

#include "sp/sketch.h"

/// Up to `most` joins of strokes keep[i] whose ends meet, one going on
/// where the other stops in the same direction (a gap of at most 4% of the
/// drawing's size, at least 3 px, or the second put down back over the
/// first; a turn of at most 40 degrees), closest first, the candidate of
/// rank `skip` left out (-1: none; at or past the last: no joins): next[i]
/// is the stroke drawn after i on its line (-1: none), flip[i] whether i
/// runs reversed on it. Returns the number of joins (0 for more than 64
/// strokes: hatching, not pieces).
int sp_pieces_find(const sp_sketch* sk, const bool* keep, int most, int skip, int* next, bool* flip);

/// The sketch of lines: each line's strokes one after another (times
/// dropped; a piece put down back over the last without the points behind
/// where the line got to), the others as they are, in the order of their first strokes;
/// line_of[i] the line of stroke i. False when out of memory.
bool sp_pieces_join(const sp_sketch* sk, const int* next, const bool* flip, sp_sketch* lines, int* line_of);

#endif
