// face.h: the `face` asset, a procedurally generated head whose rig is not
// linear blend skinning: blendshapes, procedural eyelids and eyeballs, bend
// and twist deformers and a squash-and-stretch, evaluated by one function.
// It is the solver's example black-box plugin (docs/blackbox.md): the solver
// sees only sp_blackbox_rig and poses it through finite differences.
//
// Files: face_build.c generates everything from constants (deterministic,
// no input), face_eval.c evaluates the rig and exports the plugin entry.
// World units: the head is about 2 units tall, y up, the face looks along +z;
// `_l` is the character's left (+x).
#ifndef SP_FACE_H
#define SP_FACE_H

#include <stdint.h>

#include "sp/blackbox.h"

// The parameters, in order (face_build.c has their bounds and meaning).
enum {
    F_JAW_OPEN,
    F_JAW_SIDE,
    F_SMILE_L,
    F_SMILE_R,
    F_FROWN_L,
    F_FROWN_R,
    F_STRETCH_L,
    F_STRETCH_R,
    F_PUCKER,
    F_UPPER_LIP_RAISE,
    F_LOWER_LIP_DEPRESS,
    F_MOUTH_SHIFT,
    F_CHIN_RAISE,
    F_PUFF_L,
    F_PUFF_R,
    F_CHEEK_RAISE_L,
    F_CHEEK_RAISE_R,
    F_SNEER_L,
    F_SNEER_R,
    F_BROW_RAISE_L,
    F_BROW_RAISE_R,
    F_BROW_INNER_L,
    F_BROW_INNER_R,
    F_FURROW_L,
    F_FURROW_R,
    F_LID_CLOSE_L,
    F_LID_CLOSE_R,
    F_LID_LOWER_L,
    F_LID_LOWER_R,
    F_LOOK_H,
    F_LOOK_V,
    F_MOUTH_TWIST,
    F_NOSE_BEND_SIDE,
    F_NOSE_BEND_UP,
    F_HEAD_TWIST,
    F_HEAD_NOD,
    F_HEAD_TILT,
    F_FACE_SQUASH,
    F_HEAD_WIDTH,
    F_JAW_WIDTH,
    F_NOSE_SIZE,
    F_EYE_SIZE,
    F_MOUTH_WIDTH,
    F_BROW_HEIGHT,
    F_PARAMS,
    F_BLENDSHAPES = F_LID_CLOSE_L, // parameters 0 .. F_BLENDSHAPES-1 except the jaw's two are blendshape weights
};

// Rotation-type deformers weight each point by a level 0..F_LEVELS (weight
// level / F_LEVELS): an evaluation builds one transform per level used, not
// per point. 1/64 steps of a 0.3 rad twist are 0.005 rad, far below what
// shows.
enum { F_LEVELS = 64 };

// The lid grids: LID_ACROSS columns at angles beta_j across the eye, LID_ROWS
// rows at fractions f_r from the edge (0) to the far end (1).
enum { FACE_LID_ACROSS = 17, FACE_LID_ROWS = 5 };

typedef enum face_kind { FK_SKIN, FK_EYEBALL, FK_LID_UPPER, FK_LID_LOWER } face_kind;

// One vertex as the builder sees it: where it is and how much each
// deformer moves it. compile_plan turns these into the evaluator's lists.
typedef struct face_point {
    double rest[3];
    float w_eye;         // eye_size: scaling about the eye's centre
    float w_mouth;       // mouth_width: x scaling
    float w_low;         // jaw_width: x scaling of the lower face
    float w_brow;        // brow_height: y translation
    float w_nose;        // nose_size: scaling about the nose root
    int32_t delta_first; // blendshape deltas of this point
    uint8_t delta_count;
    uint8_t kind;                               // face_kind
    uint8_t side;                               // 0: left (+x), 1: right; for eyes, lids and side fields
    uint8_t lv_neck, lv_jaw, lv_mouth, lv_nose; // rotation levels (the neck's also weighs head_width and the squash)
    uint8_t col, row;                           // lids and lips: column and row of their grid
    int8_t lip;                                 // +1 upper lip, -1 lower lip, 0 elsewhere
} face_point;

// A blendshape delta of one point, as the builder computes them.
typedef struct face_delta {
    int32_t shape; // parameter index
    float d[3];
} face_delta;

// The evaluator's plan, compiled from the points by face_build: each pass
// of an evaluation runs over a list of the points it moves instead of
// testing every point for every deformer.
typedef struct face_item {
    int32_t i;                     // point
    uint8_t side, upper, col, row; // eyes and lids
    uint8_t lv;                    // rotation level
    float w, w2;                   // weights (x scaling: mouth and jaw)
} face_item;
typedef struct face_list {
    face_item* items;
    int count;
} face_list;
enum { FL_EYEBALL, FL_LID, FL_EYE_SIZE, FL_NOSE_SIZE, FL_BROW, FL_XSCALE, FL_NOSE_ROT, FL_MOUTH_ROT, FL_JAW_ROT, FL_COUNT };
// A blendshape's delta at one point.
typedef struct face_entry {
    int32_t i;
    float d[3];
} face_entry;
// A run of consecutive points at one neck level (the grid's rows).
typedef struct face_run {
    int32_t first, count;
    uint8_t lv;
} face_run;

typedef struct face_rig {
    sp_blackbox_rig desc;          // first: release() gets the desc's user pointer, which is this struct
    int vertex_count, point_count; // the same: abstraction points are vertices too (the nose's base is not in a triangle)
    face_point* points;
    face_delta* deltas;
    int delta_count;
    double* rest; // vertex_count by 3
    uint32_t* triangles;
    int triangle_count;
    float* colors;
    int32_t* abs_index; // abstraction point -> point index
    int abs_count;
    sp_blackbox_param params[F_PARAMS];
    sp_blackbox_curve curves[8];
    sp_blackbox_abstraction abstraction;
    uint8_t used[4][F_LEVELS + 1];                           // which levels each rotation deformer uses (neck, jaw, mouth, nose)
    double lid_cb[FACE_LID_ACROSS], lid_sb[FACE_LID_ACROSS]; // cos and sin of each lid column's beta
    // The plan (see face_item).
    face_list lists[FL_COUNT];
    face_entry* entries;           // blendshape deltas by shape
    int shape_first[F_PARAMS + 1]; // shape s: entries[shape_first[s] .. shape_first[s+1])
    face_run* neck_runs;           // the neck's pass, level by level (level 0 skipped)
    int neck_run_count;
} face_rig;

// Geometry constants shared by the generator and the evaluator.
#define FACE_EYE_X 0.26
#define FACE_EYE_Y 0.20
#define FACE_EYE_R 0.105
#define FACE_MOUTH_Y (-0.36)
#define FACE_HINGE_Y 0.05
#define FACE_HINGE_Z (-0.05)
#define FACE_NECK_Y (-0.85)
#define FACE_NECK_Z (-0.05)
#define FACE_SQUASH_Y (-0.55)

// Builds the whole rig (NULL when out of memory).
face_rig* face_build(void);
void face_free(face_rig* f);
// Eye centre of side 0 (+x) or 1.
void face_eye_centre(int side, double out[3]);
// Nose root (the pivot of the nose deformers) and mouth centre (the twist's).
void face_nose_root(double out[3]);
void face_mouth_centre(double out[3]);
// The lids' procedural angles: upper edge and lower edge (radians about the
// eye's x axis, 0 straight ahead, positive up) at the given parameters.
double face_upper_edge(double close);
double face_lower_edge(double lower_up);
double face_lid_beta(int j);
double face_lid_fraction(int r);
// A lid's angle about the eye's x axis at row fraction f, given its edge.
double face_lid_psi(int upper, double f, double edge);
// A lid point relative to the eye centre (unit eye size) from cos/sin of
// beta and of psi: the lid is a shell around the eyeball whose edge is a
// circle of latitude about the eye's x axis, so it is an arc from the front.
static inline void face_lid_point(int upper, double cb, double sb, double cpsi, double spsi, double out[3])
{
    double rl = (upper ? 1.12 : 1.09) * FACE_EYE_R;
    out[0] = rl * cb;
    out[1] = rl * sb * spsi;
    out[2] = rl * sb * cpsi;
}

#endif
