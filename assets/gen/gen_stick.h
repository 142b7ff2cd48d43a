/// gen_stick.h: stick-figure abstractions along a generated skeleton.
///
/// How to use (after the joints exist, before sp_gen_save):
///
///     sp_abstraction stick;
///     sp_gen_stick_begin(&stick);                                   // "stick", ordered
///     int spine[] = {pelvis, spine_1, chest, neck, head};
///     sp_gen_stick_curve(&stick, &g, "spine", spine, 5, head_top, 40);
///     ... one curve per bone chain ...
///     sp_gen_save(&g, &mesh, &(sp_gen_save_desc){.abstractions = &stick, .abstraction_count = 1, ...}, path, &err);
///
/// A curve runs through the rest pivots of its chain's joints and ends at a
/// tip point (a hand's fingertip, the top of the head). Every point is bound
/// rigidly to the joint whose bone it lies on, so the curve is exactly the
/// posed skeleton: it bends at the pivots and stretches with bone scales.
/// Points are spread by arc length, each bone getting a share by its length
/// and its first point on its pivot, so the corners stay sharp.
#ifndef SP_GEN_STICK_H
#define SP_GEN_STICK_H

#include "gen_rig.h"

/// An empty abstraction named "stick" with ordered correspondences.
void sp_gen_stick_begin(sp_abstraction* ab);
/// Appends an open curve `name` through the pivots of chain[0..n) and
/// `tip`, with `points` points (>= n + 1).
void sp_gen_stick_curve(sp_abstraction* ab, const sp_gen_rig* g, const char* name, const int* chain, int n, sp_vec3 tip,
                        int points);

#endif
