/// dragon.h: the six dragon parts of the kiosk and their shared look.
///
/// Every part is built in its own rest space facing +X, +Y up, seen from
/// the side (the sketch view looks along -Z). One palette for all parts so
/// that a dragon assembled from them is of a piece: green scales darkening
/// towards the back, a cream belly with transverse plates, dark red-brown
/// wing membranes, ivory horns and claws, amber dorsal spikes.
#ifndef SP_DRAGON_H
#define SP_DRAGON_H

#include "gen_mesh.h"
#include "gen_rig.h"
#include "sp/result.h"

/// Palette (sRGB).
extern const sp_gen_rgb sp_dragon_back, sp_dragon_flank, sp_dragon_belly, sp_dragon_membrane, sp_dragon_membrane_vein,
    sp_dragon_horn, sp_dragon_horn_tip, sp_dragon_spike, sp_dragon_spike_tip, sp_dragon_eye, sp_dragon_pupil, sp_dragon_mouth,
    sp_dragon_tooth;

/// Scaly skin at section angle a (0 on top, pi underneath) and rest point p:
/// back-to-flank gradient, a belly of `belly` width (0: none, 1: the lower
/// third), belly plates every `plate` units along the tube (u scaled by
/// `plates` plates), and a fine speckle of scales.
sp_gen_rgb sp_dragon_scales(double u, double a, sp_vec3 p, double belly, double plates);

/// The placement parameters every part's root has: tx, ty and the
/// in-plane rotation rz (within +-1 rad, group pose) and a uniform scale s
/// (0.5..2, group shape); translations within the sketch view (saved with
/// root_reach_view).
void sp_dragon_root_params(sp_gen_rig* g, int root);

/// A position for `sp_part`, rounded to 0.1 mm so that the file's text is short and stable.
sp_vec3 sp_dragon_part_position(sp_vec3 v);
/// `sp_part` of a part that attaches to a torso socket (owns nothing).
sp_part sp_dragon_attach_part(const char* category, const char* socket, const char* joint, sp_vec3 position);

/// A row of dorsal spikes along a path between arc lengths s0 and s1,
/// standing on the tube's top (profile `up` at each spike's u) and skinned
/// by the chain; heights follow a bump between h0 and h_max.
typedef struct sp_dragon_spikes_desc {
    const sp_gen_path* path;
    const sp_gen_chain* chain;
    sp_gen_profile_fn profile;
    void* user;
    double s0, s1, path_s0, path_s1; ///< spike range; the tube's own arc-length range (for u)
    int count;
    double height, width; ///< largest spike
    double lean;          ///< backwards lean, radians (spikes point against +T)
    sp_vec3 side;         ///< the tube's side reference (zero: +Z), for its "up"
    double falloff;       ///< 0: heights rise and fall along the row; 1: shrink to nothing at s1
} sp_dragon_spikes_desc;
void sp_dragon_spikes(sp_gen_mesh* m, const sp_dragon_spikes_desc* d);

/// Part builders: each writes `path` (.glb).
sp_result sp_dragon_torso(const char* path, sp_error* err);
sp_result sp_dragon_tail(const char* path, sp_error* err);
sp_result sp_dragon_head(const char* path, sp_error* err);
sp_result sp_dragon_wings(const char* path, sp_error* err);
sp_result sp_dragon_front_legs(const char* path, sp_error* err);
sp_result sp_dragon_hind_legs(const char* path, sp_error* err);

#endif
