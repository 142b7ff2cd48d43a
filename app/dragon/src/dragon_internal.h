// dragon_internal.h: what the pipeline's files share (see sp/dragon.h for the
// world, placement, attachment and animation conventions):
//   parts.c    parts as stored (templates: loading, sp_part hints, the
//              cache) and the database (polling, reopening, preloading);
//   stroke.c   the stroke path: cleaning, classifying and deciding, fitting,
//              the parts list (add, redraw, refit, undo, clear);
//   layout.c   where a part goes: its view on the canvas, its placement in
//              the world, attachment to a body;
//   reach.c    a part drawn near a body fitted again to reach it;
//   detail.c   details kept as ink bound to their part's mesh;
//   animate.c  the clips as offsets, posing the dragon at a time;
//   report.c   the report JSON;  export.c  the glTF export;
//   dragon.c   create, destroy and the small accessors.
#ifndef SP_DRAGON_INTERNAL_H
#define SP_DRAGON_INTERNAL_H

#include <math.h>
#include <stdio.h>
#include <sys/types.h>

#include "sp/dragon.h"

static inline void dragon_copy_name(char* dst, size_t cap, const char* src)
{
    snprintf(dst, cap, "%s", src ? src : "");
}

// The point of the segment ab nearest p.
static inline sp_vec2 dragon_segment_nearest(sp_vec2 p, sp_vec2 a, sp_vec2 b)
{
    sp_vec2 ab = sp_v2_sub(b, a);
    double l2 = sp_v2_dot(ab, ab);
    double s = l2 > 0 ? fmin(1, fmax(0, sp_v2_dot(sp_v2_sub(p, a), ab) / l2)) : 0;
    return sp_v2_add(a, sp_v2_scale(ab, s));
}

// ---- parts as stored (templates), parts.c ------------------------------------------

typedef struct dsocket {
    char name[SP_NAME_MAX];
    int joint;
    sp_vec3 local;     // in the joint's frame at the rest pose
    char accepts[256]; // ",head,neck," or empty: anything
} dsocket;

typedef struct tpl {
    int refs; // the cache and every placed part hold one
    char name[SP_NAME_MAX], category[SP_NAME_MAX], sha256[65];
    sp_character ch;
    int abstraction;
    sp_camera base;           // the part's sketch view on the dragon canvas, orthographic
    sp_vec3 centre0;          // the rest pose's centre, model space (placed at world depth 0)
    bool lengthwise;          // from its attachment end it reaches sideways on the canvas (a head, a tail)
    int outward;              // and which way: +1 right, -1 left, as modelled
    sp_vec2 rest_lo, rest_hi; // the rest abstraction's bounding box in `base`, pixels
    double own_mirror_gap;    // the rest abstraction's dragon_mirror_gap (a front view of a person: near 0)
    bool own_polygonal;       // the rest abstraction has a polygon's or a star's symmetry (dragon_turns_onto_itself)
    bool is_torso;
    int socket_count;
    dsocket* sockets;
    int attach_joint;
    sp_vec3 attach_local;
    char prefer[SP_NAME_MAX]; // preferred socket name
    char family[SP_NAME_MAX]; // sp_part.family: told apart from its kin by where it is drawn on a body
    const sp_animation* clip;
    double clip_start, clip_len; // seconds
    double* clip0;               // the rest parameters: the clip's offsets are keyed relative to them
    double* scratch_p;           // param_count
    sp_vec3 *tr, *sc;            // joint_count scratch for sampling the clip
    sp_quat* rot;
    sp_solver* solver;
    sp_camera solver_cam; // the solver reads the camera through this pointer at every solve
    sp_rig_eval* ev;
    // The same part fitted with its `line` abstraction (sp_rig_add_line: a
    // tail, a pair of legs) and, for a pair of legs, its `limb` (one leg:
    // sp_rig_add_limb), for strokes drawn as one open line; NULL for other
    // parts and for the line templates themselves.
    struct tpl *line, *limb;
    bool* active; // the line template's solver moves these (param_count; NULL: all)
    // The limb template's two legs, joint by joint from the leaves up to the
    // joint they share (not included): the drawn leg's joint, then the
    // other's (twin_count pairs; 0 for other templates; limb_pairs, parts.c).
    int twin_count;
    int (*twins)[2];
    // The same fit with the attachment end held in place (reach.c; made on
    // first use): every parameter of `active` but the root's translation.
    sp_solver* pinned;
    bool* pinned_active;
} tpl;

/// Drops one reference (the last frees it). NULL is fine.
void dragon_tpl_release(tpl* t);
/// A pair of legs fitted with the limb template (p: its fit): the leg not
/// drawn takes the drawn leg's pose as seen, bone by bone, within its own
/// bounds. parts.c.
void dragon_limb_follow(const tpl* limb, double* p);
/// How far a stroke is from being its own mirror image about the upright
/// line through its centroid, over its RMS radius (0: symmetric; 1 when it
/// cannot be measured). stroke.c.
double dragon_mirror_gap(const sp_vec2* pts, int n);
/// Whether a stroke has the symmetry of a regular polygon or a star. stroke.c.
bool dragon_turns_onto_itself(const sp_vec2* pts, int n);
/// The loaded templates of `category` (loaded and cached on first use), at most cap.
int dragon_category_templates(sp_dragon* d, const char* category, tpl** out, int cap, sp_error* err);
/// The first of them (what every part of a category shares: a body or not,
/// its family), or NULL when the category has no part that loads.
tpl* dragon_category_first(sp_dragon* d, const char* category);
/// Releases every cached template.
void dragon_cache_clear(sp_dragon* d);
/// The file's device and inode (a database replaced on disk is a new inode); false when it does not exist.
// Takes the newest model of d->db (d->desc.no_model: none); keeps the one
// loaded when it cannot be read or is that model already (same_file: d->db
// is the file it was read from; else another file, a replaced one).
void dragon_reload_model(sp_dragon* d, bool same_file);
// model_load.c: the background read of a model (desc.background_model).
typedef struct dragon_loader dragon_loader;
// Starts reading the newest model of d->db_path on a thread (one at a
// time: false only when no thread could be started).
bool dragon_model_load_start(sp_dragon* d);
// Takes the model read, when the read has ended (wait: waits for it);
// true when the pipeline's model changed.
bool dragon_model_load_take(sp_dragon* d, bool wait);
// At a poll: reads again a model whose background read failed for a reason
// that may pass, once its time has come.
void dragon_model_retry(sp_dragon* d);
// The device and inode of the file at path now (false: none there).
bool dragon_file_id(const char* path, dev_t* dev, ino_t* ino);
// d->dev, d->ino: the file its handle opened, as partdb noted it before the open.
void dragon_db_file_id(sp_dragon* d);

// ---- the dragon --------------------------------------------------------------------

enum { CARRIER_MAX = 12 }; // a surface point's joints: 3 corners x 4 weights

typedef struct part {
    sp_dragon_part pub;
    tpl* t;
    double* p_fit;
    sp_vec2* stroke;
    int stroke_n;
    double stroke_box[4]; // x0 y0 x1 y1, canvas pixels
    sp_mat4 world_fit;    // model -> world at the fit, after attachment
    // Attachment (layout.c), when pub.attached_to >= 0: the anchor is a
    // point of the body's surface, barycentric in one of its triangles; the
    // body's joints that skin it (the carrier) carry the part.
    uint64_t layout_key; // the bodies it was laid out against (0: not yet)
    sp_dragon_note note; // why it is free although drawn at a body
    uint32_t tri[3];
    double bary[3];
    sp_vec3 anchor0;      // the anchor at the body's fit, world
    sp_mat4 carrier0_inv; // inverse of the carrier's blended skin matrix at the body's fit, world
    int carrier_n;
    int carrier_joint[CARRIER_MAX];
    double carrier_w[CARRIER_MAX]; // sum 1
    // Bodies: vertices at the fit, world and canvas (for attaching; NULL until needed).
    double* body_xyz;
    sp_vec2* body_px;
    double* body_tri_box;     // per triangle its canvas box: lo.x, lo.y, hi.x, hi.y
    sp_vec2 body_lo, body_hi; // canvas box of its vertices
    bool body_has_surface;
    // Its outline at the fit on the canvas, when its abstraction is one
    // closed curve (NULL otherwise): what a drawing of it shows, without the
    // spikes and crests its mesh carries.
    sp_vec2* body_ring;
    int body_ring_n;
    double body_ring_size; // its box's diagonal
    // Its fit before a part drawn later changed it (a body that decided it
    // again or turned it, a body, head or tail that made legs the other
    // legs or turned legs or wings: stroke.c, parts_meet_body,
    // parts_by_place), and that part's id: Undo of that part, or a Redraw
    // or chip that replaces it, gives the fit back.
    struct part* before;
    uint64_t before_by;
    bool chosen; // its category was the caller's (a chip's), not the classifier's
    int carried; // a body: the parts hung on it before the last part came (sp_dragon_add_points)
    // Posed at the last pose_at.
    double *p_t, *xyz, *outline;
    sp_mat4 world_t;
    sp_rig_eval* ev;
} part;

// A detail (detail.c): a stroke kept as ink on a part, each point bound to
// one of the part's triangles by barycentric coordinates, or, off the mesh
// (a flourish's), carried in the air by the part's skin where the stroke
// leaves it.
typedef struct detail {
    uint64_t id, host; // its own id and its part's
    const tpl* t;      // the part's template and facing when bound: shown only while the part has them
    bool mirrored;
    int n;
    uint32_t* tri; // n by 3 (one block with the arrays below)
    // n by 3: barycentric, or for a point in the air its position in the
    // rig's rest space (what its joints' blended skin matrix poses).
    double* bary;
    double* flip;         // n: +1 or -1, the triangle's winding towards the side drawn on; 0: in the air
    uint32_t* joint;      // n by 4: a point in the air's joints and their weights (0 for none)
    double* weight;
    double *xyz, *normal; // posed at the last pose_at, n by 3
    sp_vec2* drawn;       // n: where each point was drawn on the canvas
    sp_mat4 fit0;         // the part's world_fit when drawn (a part laid out again since moves its ink with it)
    bool shown;           // posed and its part as bound
    // The same ink bound to another fit of its part (before the part was
    // decided again or turned; dragon_details_follow), newest first.
    struct detail* alt;
} detail;

struct sp_dragon {
    sp_dragon_desc desc;
    sp_db* db;
    bool own_db;
    char db_path[1024], assets_dir[1024];
    dev_t dev;
    ino_t ino;
    uint64_t gen;
    uint64_t reloads; // sp_dragon_reload_count
    sp_clf* clf;
    int64_t model_id;   // the row clf was read from (0: none)
    char model_sha[65]; // its SHA-256 ("" when not known)
    dragon_loader* loader; // a model being read in the background (NULL: none)
    double model_retry_at; // sp_now_ms when a background read that failed is tried again (0: none)
    tpl** cache;
    int cache_n;
    int preload_next; // sp_dragon_preload_step's cursor over the database's parts
    // Parts that did not load since the last change of the database, and why:
    // not parsed again by every stroke that needs their category, and a
    // stroke they leave without a part can say why (sp_dragon_part_error).
    struct dragon_failed* failed;
    int failed_n;
    char part_error[512]; // why a part the last stroke needed did not load; "" when none
    char model_error[512]; // why there is no model (sp_dragon_model_error); "" when there is one or none was asked for
    part** parts;
    int part_n, part_cap;
    uint64_t next_id;
    detail** details; // SP_DRAGON_MAX_DETAILS slots, allocated with the first
    int detail_n;
    sp_camera world;
    double area[4]; // where strokes may lie (sp_dragon_set_stroke_area); x1 <= x0: the canvas
    double period;
    bool posed;
    // The time of the last sp_dragon_pose_at (0 before one): the dragon as
    // the visitor sees it while drawing, which a detail is bound to.
    double shown_t;
    // Fault injection for tests (NULL in use): called on every fit's
    // parameters before they are checked, e.g. to put a NaN there.
    void (*fit_hook)(double* p, int n);
};

/// Frees a placed part and its reference to its template. NULL is fine.
void dragon_part_free(part* p);

// ---- layout.c ----------------------------------------------------------------------

/// The part's sketch view zoomed and panned so its rest abstraction covers the stroke's box [lo, hi].
sp_camera dragon_zoomed_view(const tpl* t, sp_vec2 lo, sp_vec2 hi);
/// The view turned to face the other way: what projected to u' = x now projects to 2u - x.
sp_camera dragon_mirrored_view(const sp_camera* view, double u);
/// Part model space -> world, making the part's view and the world camera agree.
sp_mat4 dragon_placement_of(const sp_dragon* d, const tpl* t, const sp_camera* view);
/// Skin matrices (skin) of n joints blended by their weights w, then world's.
sp_mat4 dragon_blended_skin(const int* joints, const double* w, int n, const sp_mat4* skin, const sp_mat4* world);
/// The distance from canvas point p to the nearest of n points px (a
/// projected mesh's vertices), or `limit` when none is nearer.
double dragon_vertex_nearest(const sp_vec2* px, int n, sp_vec2 p, double limit);
/// Part p's carrier in the world: its joints' skin matrices (skin, the body's
/// evaluation) blended by its weights, then the body's model -> world.
sp_mat4 dragon_carrier_matrix(const part* p, const sp_mat4* skin, const sp_mat4* body_world);
/// Which way template t should face for a stroke in the box [lo, hi]: +1 as
/// modelled, -1 mirrored (drawn on the other side of the nearest body than
/// its socket, or its own reach, puts a part of its kind); 0: no hint (no
/// body, or drawn over its middle). *out_of_end: the stroke comes out of
/// that body's end, where the body's socket for its kind is: its box
/// overlaps the body's on the canvas and reaches past that end.
int dragon_facing_hint(sp_dragon* d, const tpl* t, sp_vec2 lo, sp_vec2 hi, bool* out_of_end);
/// Whether a stroke (box [lo, hi]) of template t's kind comes out of the
/// end of the nearest body where that body's socket for its kind is (a
/// head's or a tail's) while no part of its kind hangs on that body: the
/// dragon's missing head drawn there is its head, never a flourish of the
/// part it touches.
bool dragon_claims_socket(sp_dragon* d, const tpl* t, sp_vec2 lo, sp_vec2 hi);
/// Which way a part that does not reach sideways (legs, wings) should face
/// for a stroke in the box [lo, hi]: the way the dragon it is drawn at faces
/// (the nearest body whose box is within the snap distance of the stroke's,
/// its facing told by the heads and tails attached at its ends: +1 as
/// modelled, -1 mirrored); 0 when no body or nothing tells.
int dragon_facing_at(sp_dragon* d, sp_vec2 lo, sp_vec2 hi);
/// The category that attached part i takes from where it was drawn, when it
/// has a family (sp_part.family): the family's member whose socket on the
/// body lies nearest the part's anchor along the body (the family's sockets
/// centred on the body's middle), the dragon's facing
/// read from the sideways parts (heads, tails) on that body. False (out
/// untouched) for a free part, a body with fewer than two of the family's
/// sockets, or a facing the body's parts do not tell or disagree on.
bool dragon_family_member(sp_dragon* d, int i, char out[SP_NAME_MAX]);
/// Whether a stroke with box [lo, hi] is drawn on a body: its box overlaps
/// a body's on the canvas and is clearly smaller than it. Such a
/// stroke is a part of that dragon, never a second body (docs/DESIGN.md,
/// "Which strokes join a dragon"). Part `skip` (the one a Redraw
/// replaces, or -1) does not count.
bool dragon_drawn_on_body(sp_dragon* d, sp_vec2 lo, sp_vec2 hi, int skip);
/// The same test against part k only (false when k is not a body).
bool dragon_on_body(sp_dragon* d, sp_vec2 lo, sp_vec2 hi, int k);
/// Where part i's stroke comes nearest a body it is drawn on or near
/// (dragon_on_body; only body `only` when it is not -1), within the snap
/// distance: that body's surface point in *target, and the body's index.
/// Of the stroke's points about that near (a stroke that overlaps the body
/// has many), the one nearest the fitted attachment end a2. -1: none.
int dragon_reach_target(sp_dragon* d, int i, int only, sp_vec2 a2, sp_vec2* target);
/// What becomes of a detail's points off its part's mesh: left out (a
/// detail drawn on the part), carried in the air together from the mesh's
/// point nearest their middle (a flourish: it keeps its shape), or each from
/// the mesh vertex nearest it (an edge: it follows the body's bends).
typedef enum detail_air { DETAIL_AIR_NONE, DETAIL_AIR_TOGETHER, DETAIL_AIR_EACH } detail_air;
/// Where a stroke lies on the part it is a detail of: the part, its mesh at
/// its fit as shown (world and canvas, vertex_count each, malloc'd), how
/// near that mesh a point counts as on it (pixels), and what becomes of
/// the points off it.
typedef struct detail_hit {
    int part;
    double* xyz;
    sp_vec2* px;
    double near;
    detail_air air;
} detail_hit;
/// The part that a stroke (pts: n canvas points, box [lo, hi]) is a detail
/// of, or -1: the part drawn last whose projected mesh at its fit (as
/// shown, after attachment) holds nearly all the stroke's points and whose
/// box's diagonal is over eight times the stroke's (an eye on a head, spots on a
/// body: docs/DESIGN.md, "Details are not parts"). Part `skip` (the one a
/// Redraw replaces, or -1) does not count. hit (may be NULL) receives the
/// mesh it was found on, for dragon_detail_keep; free it with dragon_detail_hit_free.
int dragon_detail_of(sp_dragon* d, const sp_vec2* pts, int n, sp_vec2 lo, sp_vec2 hi, int skip, detail_hit* hit);
/// The part that a speck is drawn on, or -1: a stroke too small to become a
/// part (its box's diagonal under SP_DRAGON_PART_MIN of the canvas's) with
/// half its points on a part's mesh, as dragon_detail_of measures (a spot
/// at a thin tail's edge), its points off the mesh carried together in the
/// air, as a flourish's. hit as for dragon_detail_of.
int dragon_speck_of(sp_dragon* d, const sp_vec2* pts, int n, sp_vec2 lo, sp_vec2 hi, int skip, detail_hit* hit);
/// A stroke lying on a part as a detail does, at any size up to the
/// part's, and not a loop (sp_stroke_is_loop): colouring in (DETAIL_ON of
/// its points on the part; `recognised`, a stroke the classifier took for a
/// part: within the part's mesh, not only near it). Returns the part's
/// index or -1.
int dragon_colouring_of(sp_dragon* d, const sp_vec2* pts, int n, sp_vec2 lo, sp_vec2 hi, int skip, bool recognised,
                        detail_hit* hit);
/// The part that a stroke is drawn out of, away from the dragon's bodies,
/// or -1 (fire from a mouth, a spade at a tail's tip, a crown on a head:
/// docs/DESIGN.md, "Flourishes ride their part"): a part attached to a
/// body, that the stroke comes near (its mesh or the ink drawn out of it),
/// at least two thirds of the stroke's size, with every point of the
/// stroke nearer it than any body and a share of them off its mesh. Part
/// `skip` (or -1) does not count. hit as for dragon_detail_of, with air set.
int dragon_flourish_of(sp_dragon* d, const sp_vec2* pts, int n, sp_vec2 lo, sp_vec2 hi, int skip, detail_hit* hit);
/// The body that a stroke (an open line, not a loop) is drawn along the
/// back of, or -1 (spikes, a mane: docs/DESIGN.md, "Spikes along the
/// back"): every point of the stroke on the body's projected mesh at its
/// fit or, beside its upper half, within 6% of the body's size of it, 30%
/// of them off it, the stroke 0.25 to 0.75 of the body's size. Part `skip`
/// (or -1) does not count. hit as for dragon_detail_of, its points off the
/// mesh each carried from the vertex nearest it.
int dragon_edge_of(sp_dragon* d, const sp_vec2* pts, int n, sp_vec2 lo, sp_vec2 hi, int skip, detail_hit* hit);
void dragon_detail_hit_free(detail_hit* hit);
/// Recomputes every attachment and the loop period (after any change of the parts).
void dragon_relayout(sp_dragon* d);

// ---- reach.c -----------------------------------------------------------------------

/// Fits part p again with its attachment end held at canvas point `target`
/// (a body's surface where the part's stroke comes nearest it): the root's
/// translation set so that the end lies there and held, the rest of the
/// pose fitted to the part's own stroke as before. Keeps the new fit
/// (p->p_fit, p->pub.report) and returns true when the end got there and
/// the fit is not clearly worse than the one it had; else leaves the part
/// as it was.
bool dragon_fit_reaching(sp_dragon* d, part* p, sp_vec2 target);

// ---- detail.c ----------------------------------------------------------------------

/// Keeps the stroke (pts: n canvas points) as a detail of the part and mesh
/// dragon_detail_of found it on: its index, or -1 when the dragon holds
/// SP_DRAGON_MAX_DETAILS, fewer than two points can be bound, or memory runs out.
int dragon_detail_keep(sp_dragon* d, const detail_hit* hit, const sp_vec2* pts, int n);
/// The ink on each part follows it when the part is another fit of its
/// stroke than the ink was bound to (decided again, turned, or given back
/// by an Undo; the same id): a binding to its fit kept from before comes
/// first again, else the ink is bound anew to it where it shows on the fit
/// it replaced (part.before), laid out as it was. After a stroke's
/// changes, when the parts are where they end.
void dragon_details_follow_parts(sp_dragon* d);
/// The distance on the canvas from p to the ink kept on the part with this
/// id, as drawn, moved with the part when it was laid out again since
/// (INFINITY when it has none shown).
double dragon_ink_distance(const sp_dragon* d, uint64_t host, sp_vec2 p);
/// Poses every detail on its part's vertices at the last pose_at (after them).
void dragon_details_pose(sp_dragon* d);
/// Poses the dragon at time t as sp_dragon_pose_at does, without taking t as
/// the time shown (for the export's and report's own poses).
void dragon_pose(sp_dragon* d, double t);
/// Poses only the parts (their p_t, ev, xyz, outline, world_t), not the
/// details, and leaves d->posed as it was.
void dragon_pose_parts(sp_dragon* d, double t);
/// The parts posed as shown (at d->shown_t), for binding details where
/// they were drawn; d->posed stays as it was.
void dragon_pose_shown(sp_dragon* d);
/// Detail i's points in its part's bind space with their skin (for the
/// export; rest: n by 3, joints and weights: n by 4 for the detail's n
/// points): each point's corners and their four influences blended by its
/// barycentric coordinates, the four largest kept. Returns its part's index,
/// -1 when the part does not show it (then nothing is written).
int dragon_detail_skinned(const sp_dragon* d, int i, double* rest, uint16_t* joints, float* weights);
/// Drops the details whose part is gone (replaced by a Redraw or a chip).
void dragon_details_prune(sp_dragon* d);
/// The last detail's id when it is the dragon's last change (its id is above
/// the last part's: the last part always has the largest of the parts'), else 0.
uint64_t dragon_detail_last_change(const sp_dragon* d);
/// Drops the last detail (n > 0), the detail with this id (if any) or every detail.
void dragon_detail_pop(sp_dragon* d);
void dragon_detail_remove(sp_dragon* d, uint64_t id);
void dragon_details_clear(sp_dragon* d);

#endif
