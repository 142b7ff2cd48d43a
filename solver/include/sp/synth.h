/// sp/synth.h: synthetic targets for tests, benchmarks and training data.
///
///     sp_synth_params(&rig, seed, 0.785, p);            // a random pose within bounds
///     sp_synth_sketch(&rig, abstraction, &cam, p, &sk);  // its abstraction, one stroke per curve
///
/// Amplitude A (DESIGN.md, `synth --amplitude`): every rotation parameter
/// moves at most A radians from its default (clamped to its bounds), every
/// shape parameter is uniform within its bounds, and pose-group translations
/// and scales move at most A/pi of their half range. Deterministic for a
/// seed (splitmix64), on every machine.
#ifndef SP_SYNTH_H
#define SP_SYNTH_H

#include <stdint.h>

#include "sp/rig.h"
#include "sp/sketch.h"

#ifdef __cplusplus
extern "C" {
#endif

/// Deterministic generator (splitmix64).
typedef struct sp_rng {
    uint64_t state;
} sp_rng;
/// Uniform in [0, 1).
double sp_rng_uniform(sp_rng* r);
/// Uniform in [lo, hi).
double sp_rng_range(sp_rng* r, double lo, double hi);
/// Standard normal (Box-Muller).
double sp_rng_normal(sp_rng* r);

/// A random parameter vector within bounds (see the amplitude rule above).
void sp_synth_params(const sp_rig* rig, uint64_t seed, double amplitude, double* p);

/// Adds Gaussian noise (standard deviation noise_px, per coordinate) to every
/// point of sk, from its own seeded stream (`synth --noise`).
void sp_synth_jitter(sp_sketch* sk, double noise_px, uint64_t seed);

/// The abstraction's curves at p, projected by cam, as strokes (one per
/// curve, in curve order, closed curves repeat their first point at the end)
/// on the camera's canvas. mesh_xyz scratch is allocated internally.
sp_result sp_synth_sketch(const sp_rig* rig, int abstraction, const sp_camera* cam, const double* p, sp_sketch* out);

/// Projects the abstraction's points at p: xy is point_count by 2, pixels.
sp_result sp_abstraction_project(const sp_rig* rig, int abstraction, const sp_camera* cam, const double* p, double* xy);

#ifdef __cplusplus
}
#endif
#endif
