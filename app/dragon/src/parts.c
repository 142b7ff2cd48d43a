// parts.c: parts as stored (templates: the rig, its sketch view on the
// canvas, its sp_part hints, its clip, its prepared solver), cached by name,
// and the database behind them (polled for changes, reopened when replaced).
#include <fcntl.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "dragon_internal.h"
#include "sp/synth.h"

void dragon_tpl_release(tpl* t)
{
    if (!t || --t->refs > 0) return;
    dragon_tpl_release(t->line);
    dragon_tpl_release(t->limb);
    sp_solver_destroy(t->solver);
    free(t->active);
    free(t->twins);
    sp_solver_destroy(t->pinned);
    free(t->pinned_active);
    sp_rig_eval_destroy(t->ev);
    free(t->sockets);
    free(t->clip0);
    free(t->scratch_p);
    free(t->tr);
    free(t->sc);
    free(t->rot);
    sp_character_free(&t->ch);
    free(t);
}

// A point given in model space at the rest pose, as an offset in `joint`'s frame.
static sp_vec3 to_joint_local(tpl* t, int joint, sp_vec3 model)
{
    const sp_mat4* G = &sp_rig_eval_world(t->ev)[joint];
    sp_mat4 inv;
    if (!sp_mat4_inverse(G, &inv)) return (sp_vec3){0, 0, 0};
    return sp_mat4_point(&inv, model);
}

// Reads the sockets / attach hints of the part's sp_part extras (DESIGN.md;
// every key optional). t->ev must hold the rest pose.
static void read_part_extras(tpl* t)
{
    const sp_rig* rig = &t->ch.rig;
    t->attach_joint = 0;
    for (int j = 0; j < rig->joint_count; ++j)
        if (rig->joints[j].parent < 0) {
            t->attach_joint = j;
            break;
        }
    t->attach_local = (sp_vec3){0, 0, 0};
    t->is_torso = !strcmp(t->category, "torso");
    if (!t->ch.has_part) return;
    const sp_part* part = &t->ch.part;
    dragon_copy_name(t->family, sizeof t->family, part->family);
    if (part->socket_count > 0) t->sockets = calloc((size_t)part->socket_count, sizeof(dsocket));
    for (int i = 0; t->sockets && i < part->socket_count; ++i) {
        const sp_part_socket* s = &part->sockets[i];
        dsocket* d = &t->sockets[t->socket_count];
        d->joint = s->joint[0] ? sp_rig_find_joint(rig, s->joint) : t->attach_joint;
        if (d->joint < 0) continue; // a socket on a joint the part does not have: ignore it
        dragon_copy_name(d->name, sizeof d->name, s->name);
        d->local = s->has_position ? to_joint_local(t, d->joint, s->position) : (sp_vec3){0, 0, 0};
        size_t len = 0;
        for (int k = 0; k < s->accept_count; ++k) {
            if (len == 0) d->accepts[len++] = ',';
            if (len + strlen(s->accepts[k]) + 2 < sizeof d->accepts)
                len += (size_t)snprintf(d->accepts + len, sizeof d->accepts - len, "%s,", s->accepts[k]);
        }
        if (len == 1) d->accepts[0] = 0;
        ++t->socket_count;
    }
    if (t->socket_count > 0) t->is_torso = true;
    if (part->has_attach) {
        const sp_part_attach* at = &part->attach;
        int j = at->joint[0] ? sp_rig_find_joint(rig, at->joint) : -1;
        if (j >= 0) t->attach_joint = j;
        if (at->has_position) t->attach_local = to_joint_local(t, t->attach_joint, at->position);
        if (at->socket[0]) dragon_copy_name(t->prefer, sizeof t->prefer, at->socket);
    }
}

static sp_result tpl_load(sp_db* db, const tpl* line_of, int limb_leaf, const char* name, int canvas_w, int canvas_h,
                          const sp_solve_desc* solve, tpl** out, sp_error* err);

// Pairs the two legs' joints from the leaves up to the joint they share
// (for dragon_limb_follow): t->twins, t->twin_count (none when out of memory).
static void limb_pairs(tpl* t, int near, int far)
{
    const sp_rig* rig = &t->ch.rig;
    int J = rig->joint_count;
    int* up = malloc(sizeof(int) * (size_t)(2 * J + 2));
    if (!up) return;
    int *a = up, *b = up + J + 1; // each leaf up to the root
    int na = 0, nb = 0;
    for (int j = near; j >= 0 && na < J; j = rig->joints[j].parent)
        a[na++] = j;
    for (int j = far; j >= 0 && nb < J; j = rig->joints[j].parent)
        b[nb++] = j;
    while (na > 0 && nb > 0 && a[na - 1] == b[nb - 1]) // what the two share stays
        --na, --nb;
    int n = na < nb ? na : nb;
    if (n > 0 && (t->twins = malloc(sizeof *t->twins * (size_t)n))) {
        for (int i = 0; i < n; ++i)
            t->twins[i][0] = a[i], t->twins[i][1] = b[i];
        t->twin_count = n;
    }
    free(up);
}

// The direction, as seen (radians), of joint j's bone: towards joint `to`,
// or with to < 0 (a leaf) along the joint's own axis (x, or y where x is
// seen end-on), at the last evaluation of t->ev.
static double seen_angle(const tpl* t, int j, int to)
{
    const sp_mat4* w = sp_rig_eval_world(t->ev);
    sp_vec3 o = sp_mat4_point(&t->base.view, sp_mat4_translation(&w[j])), e;
    if (to >= 0) {
        e = sp_mat4_point(&t->base.view, sp_mat4_translation(&w[to]));
    } else {
        sp_vec3 x = sp_mat4_point(&t->base.view, sp_mat4_point(&w[j], (sp_vec3){1, 0, 0}));
        sp_vec3 y = sp_mat4_point(&t->base.view, sp_mat4_point(&w[j], (sp_vec3){0, 1, 0}));
        e = hypot(x.x - o.x, x.y - o.y) >= 0.3 * hypot(y.x - o.x, y.y - o.y) ? x : y;
    }
    return atan2(e.y - o.y, e.x - o.x);
}

// How fast parameter k turns joint j's bone as seen (radians per unit), at p.
static double seen_rate(const tpl* t, double* p, int k, int j, int to)
{
    const double h = 1e-3;
    sp_rig_eval_update(t->ev, p, false);
    double a0 = seen_angle(t, j, to);
    double keep = p[k];
    p[k] += h;
    sp_rig_eval_update(t->ev, p, false);
    p[k] = keep;
    return remainder(seen_angle(t, j, to) - a0, 2 * M_PI) / h;
}

void dragon_limb_follow(const tpl* limb, double* p)
{
    const sp_rig* rig = &limb->ch.rig;
    // From the hips down: each joint of the other leg turns so that its bone
    // points as the drawn leg's does (a leaf: turns as much as the drawn
    // leaf does), and takes its scales.
    for (int i = limb->twin_count - 1; i >= 0; --i) {
        int a = limb->twins[i][0], b = limb->twins[i][1];
        int a_to = i > 0 ? limb->twins[i - 1][0] : -1, b_to = i > 0 ? limb->twins[i - 1][1] : -1;
        for (int m = 0; m < rig->param_count; ++m) {
            if (rig->params[m].joint != b) continue;
            int k = -1;
            for (int q = 0; q < rig->param_count && k < 0; ++q)
                if (rig->params[q].joint == a && rig->params[q].channel == rig->params[m].channel) k = q;
            if (k < 0) continue;
            double v = p[k];
            if (sp_channel_is_rotation(rig->params[m].channel)) {
                double rf = seen_rate(limb, p, m, b, b_to);
                if (fabs(rf) < 0.1) continue; // a turn this joint cannot show
                if (i > 0) {
                    sp_rig_eval_update(limb->ev, p, false);
                    v = p[m] + remainder(seen_angle(limb, a, a_to) - seen_angle(limb, b, b_to), 2 * M_PI) / rf;
                } else {
                    double d[2] = {rig->params[k].def, p[k]};
                    v = rig->params[m].def + seen_rate(limb, p, k, a, a_to) * (d[1] - d[0]) / rf;
                }
            } else if (!sp_channel_is_scale(rig->params[m].channel)) {
                continue; // the other leg keeps its own offsets
            }
            p[m] = fmin(fmax(v, rig->params[m].min), rig->params[m].max);
        }
    }
}

// Gives t (an outline template) its line templates, for strokes drawn as one
// open line: the `line` through its chain (a tail, a pair of legs) and, for
// a pair of legs, the `limb` of the leg nearer the camera (the leg a child
// draws as one straight line). A part whose lines cannot be made is still
// fitted with its outline.
static void load_lines(sp_db* db, tpl* t, const char* name, int canvas_w, int canvas_h, const sp_solve_desc* solve)
{
    const sp_rig* rig = &t->ch.rig;
    int* order = malloc(sizeof(int) * ((size_t)rig->joint_count + 1));
    int n = order ? sp_rig_line_joints(rig, order, rig->joint_count) : 0;
    sp_error lerr = {0};
    if (n > 0) tpl_load(db, t, -1, name, canvas_w, canvas_h, solve, &t->line, &lerr);
    if (t->line && rig->joints[order[n - 1]].parent >= 0) { // two leaves (one chain ends at the root)
        const sp_mat4* world = sp_rig_eval_world(t->ev);
        double z0 = sp_mat4_point(&t->base.view, sp_mat4_translation(&world[order[0]])).z,
               z1 = sp_mat4_point(&t->base.view, sp_mat4_translation(&world[order[n - 1]])).z;
        int near = z0 >= z1 ? order[0] : order[n - 1];
        tpl_load(db, t, near, name, canvas_w, canvas_h, solve, &t->limb, &lerr);
        if (t->limb) limb_pairs(t->limb, near, near == order[0] ? order[n - 1] : order[0]);
    }
    free(order);
    // Which way the part reaches is the part's, whichever curve is fitted.
    tpl* lines[2] = {t->line, t->limb};
    for (int k = 0; k < 2; ++k)
        if (lines[k]) lines[k]->lengthwise = t->lengthwise, lines[k]->outward = t->outward;
}

// Loads part `name` from the database as a template fitted with its
// abstraction (`outline`); or, with line_of, makes line_of's part fitted
// with a `line` added to it (with limb_leaf >= 0: a `limb` from that leaf),
// from a copy of its character (SP_OK, *out NULL and nothing in err when
// its skeleton has no such curve).
static sp_result tpl_load(sp_db* db, const tpl* line_of, int limb_leaf, const char* name, int canvas_w, int canvas_h,
                          const sp_solve_desc* solve, tpl** out, sp_error* err)
{
    *out = NULL;
    tpl* t = calloc(1, sizeof *t);
    if (!t) return sp_fail(err, SP_ERR_NO_MEMORY, "out of memory");
    t->refs = 1;
    sp_db_part_info info;
    sp_result r = line_of ? sp_character_clone(&line_of->ch, &t->ch, err) : sp_db_part(db, name, &info, err);
    if (r == SP_OK && !line_of) r = sp_db_load_part(db, name, &t->ch, err);
    if (r != SP_OK) {
        free(t);
        return r;
    }
    dragon_copy_name(t->name, sizeof t->name, name);
    dragon_copy_name(t->category, sizeof t->category, line_of ? line_of->category : info.category);
    dragon_copy_name(t->sha256, sizeof t->sha256, line_of ? line_of->sha256 : info.sha256);
    const sp_rig* rig = &t->ch.rig;
    if (line_of) {
        bool added = false;
        r = limb_leaf >= 0 ? sp_rig_add_limb(&t->ch.rig, limb_leaf, &added, err) : sp_rig_add_line(&t->ch.rig, &added, err);
        if (r != SP_OK || !added) {
            dragon_tpl_release(t);
            return r;
        }
        t->abstraction = sp_rig_find_abstraction(rig, limb_leaf >= 0 ? "limb" : "line");
    } else {
        t->abstraction = info.abstraction[0] ? sp_rig_find_abstraction(rig, info.abstraction) : -1;
        if (t->abstraction < 0) t->abstraction = rig->abstraction_count > 0 ? 0 : -1;
    }
    size_t P = (size_t)rig->param_count + 1, J = (size_t)rig->joint_count + 1;
    sp_rig_eval_create(rig, &t->ev, NULL);
    t->scratch_p = malloc(sizeof(double) * P);
    t->tr = malloc(sizeof(sp_vec3) * J);
    t->sc = malloc(sizeof(sp_vec3) * J);
    t->rot = malloc(sizeof(sp_quat) * J);
    double* xyz = malloc(sizeof(double) * 3 * ((size_t)rig->vertex_count + 1));
    double* xy =
        t->abstraction >= 0 ? malloc(sizeof(double) * 2 * ((size_t)rig->abstractions[t->abstraction].point_count + 1)) : NULL;
    if (!t->ev || !t->scratch_p || !t->tr || !t->sc || !t->rot || !xyz || (t->abstraction >= 0 && !xy)) {
        r = sp_fail(err, SP_ERR_NO_MEMORY, "part %s: out of memory", name);
        goto fail;
    }
    if (t->abstraction < 0 || rig->abstractions[t->abstraction].point_count < 2) {
        r = sp_fail(err, SP_ERR_INVALID, "part %s: no sketch abstraction to fit", name);
        goto fail;
    }
    // The rest pose: where sockets and attach points are given, and the depth reference.
    sp_rig_defaults(rig, t->scratch_p);
    sp_rig_eval_update(t->ev, t->scratch_p, false);
    read_part_extras(t);
    sp_rig_eval_update(t->ev, t->ch.pose, false);
    sp_rig_eval_points(t->ev, sp_rig_mesh_points(rig), xyz);
    sp_vec3 lo, hi;
    sp_bounds(xyz, rig->vertex_count, &lo, &hi);
    sp_vec3 centre = sp_v3_scale(sp_v3_add(lo, hi), 0.5);
    t->base = sp_camera_resize(&t->ch.camera, canvas_w, canvas_h);
    sp_vec3 c = sp_mat4_point(&t->base.view, centre);
    if (t->base.kind == SP_CAMERA_PERSPECTIVE) {
        // Weak perspective at the part's centre: the world is orthographic (dragon.h).
        double d = -c.z > 1e-9 ? -c.z : 1.0;
        t->base.kind = SP_CAMERA_ORTHOGRAPHIC;
        t->base.scale /= d;
    }
    t->centre0 = centre;
    sp_abstraction_project(rig, t->abstraction, &t->base, t->ch.pose, xy);
    int n = rig->abstractions[t->abstraction].point_count;
    t->rest_lo = t->rest_hi = (sp_vec2){xy[0], xy[1]};
    for (int i = 1; i < n; ++i) {
        t->rest_lo.x = fmin(t->rest_lo.x, xy[2 * i]), t->rest_lo.y = fmin(t->rest_lo.y, xy[2 * i + 1]);
        t->rest_hi.x = fmax(t->rest_hi.x, xy[2 * i]), t->rest_hi.y = fmax(t->rest_hi.y, xy[2 * i + 1]);
    }
    // Its own symmetry: the refusal's symmetry rules are for what no
    // dragon part is, and a curator's part may be (a star, a person from the front).
    t->own_mirror_gap = dragon_mirror_gap((const sp_vec2*)xy, n);
    t->own_polygonal = dragon_turns_onto_itself((const sp_vec2*)xy, n);
    double diag = sp_v2_len(sp_v2_sub(t->rest_hi, t->rest_lo));
    if (!(diag > 1e-6) || !isfinite(diag)) {
        r = sp_fail(err, SP_ERR_INVALID, "part %s: its abstraction is invisible in its sketch view", name);
        goto fail;
    }
    // Which way it reaches from its attachment end, as modelled: sideways
    // (a head, a tail) parts may be fitted facing the other way (stroke.c).
    sp_vec2 at = sp_camera_project(&t->base, sp_mat4_point(&sp_rig_eval_world(t->ev)[t->attach_joint], t->attach_local));
    sp_vec2 reach = sp_v2_sub(sp_v2_scale(sp_v2_add(t->rest_lo, t->rest_hi), 0.5), at);
    t->lengthwise = !t->is_torso && fabs(reach.x) > fabs(reach.y);
    t->outward = reach.x >= 0 ? 1 : -1;
    double start = 0, end = 0; // the clip: the rig's first animation that moves
    t->clip = sp_rig_first_clip(rig, &start, &end);
    t->clip_start = start, t->clip_len = end - start;
    if (t->clip) {
        t->clip0 = malloc(sizeof(double) * P);
        if (!t->clip0) {
            r = sp_fail(err, SP_ERR_NO_MEMORY, "part %s: out of memory", name);
            goto fail;
        }
        // Offsets relative to rest (docs/DESIGN.md, "Animation clips as
        // offsets"), not to the clip's first frame: the clips have phase lags
        // along their chains, and subtracting a first frame would make a flap
        // or a sway lopsided about the drawn pose.
        sp_rig_defaults(rig, t->clip0);
    }
    t->solver_cam = t->base;
    sp_solve_desc sd = *solve;
    if (line_of) {
        // A line says nothing of a part's thickness: its proportions stay
        // as modelled (the bone scales held at rest) and only the pose and
        // the root's size move, so a tail drawn as a line is not fattened.
        t->active = malloc(sizeof(bool) * P);
        if (!t->active) {
            r = sp_fail(err, SP_ERR_NO_MEMORY, "part %s: out of memory", name);
            goto fail;
        }
        for (int k = 0; k < rig->param_count; ++k)
            t->active[k] = rig->params[k].group == SP_GROUP_POSE ||
                           (rig->joints[rig->params[k].joint].parent < 0 && rig->params[k].channel == SP_CH_S);
        sd.active = t->active;
    }
    sp_error serr = {0};
    if ((r = sp_solver_create(rig, t->abstraction, &t->solver_cam, &sd, &t->solver, &serr)) != SP_OK) {
        sp_fail(err, r, "part %s: cannot prepare the solver: %s", name, serr.text);
        goto fail;
    }
    free(xyz);
    free(xy);
    if (!line_of && !t->is_torso) load_lines(db, t, name, canvas_w, canvas_h, solve);
    *out = t;
    return SP_OK;
fail:
    free(xyz);
    free(xy);
    dragon_tpl_release(t);
    return r;
}

void dragon_part_free(part* p)
{
    if (!p) return;
    dragon_part_free(p->before);
    dragon_tpl_release(p->t);
    free(p->p_fit);
    free(p->stroke);
    free(p->p_t);
    free(p->xyz);
    free(p->outline);
    free(p->body_xyz);
    free(p->body_px);
    free(p->body_tri_box);
    free(p->body_ring);
    sp_rig_eval_destroy(p->ev);
    free(p);
}

struct dragon_failed {
    char name[SP_NAME_MAX];
    sp_result code;
    char why[512];
};

void dragon_cache_clear(sp_dragon* d)
{
    for (int i = 0; i < d->cache_n; ++i)
        dragon_tpl_release(d->cache[i]);
    free(d->cache);
    d->cache = NULL;
    d->cache_n = 0;
    free(d->failed);
    d->failed = NULL;
    d->failed_n = 0;
}

// After a change of the database: keeps the loaded parts whose stored bytes
// are unchanged (same name, category and SHA-256), so a curator's edit does
// not make every next stroke pay for loading and preparing its part again.
static void cache_prune(sp_dragon* d)
{
    d->preload_next = 0; // the database changed: what is left to load is counted again
    d->failed_n = 0;     // and a part that did not load may load now
    int kept = 0;
    for (int i = 0; i < d->cache_n; ++i) {
        tpl* t = d->cache[i];
        sp_db_part_info info;
        sp_error e = {0};
        bool same = d->db && sp_db_part(d->db, t->name, &info, &e) == SP_OK && !strcmp(info.sha256, t->sha256) &&
                    !strcmp(info.category, t->category);
        if (same)
            d->cache[kept++] = t;
        else
            dragon_tpl_release(t);
    }
    d->cache_n = kept;
}

void dragon_db_file_id(sp_dragon* d)
{
    uint64_t dev = 0, ino = 0;
    sp_db_file_id(d->db, &dev, &ino);
    d->dev = (dev_t)dev, d->ino = (ino_t)ino;
}

bool dragon_file_id(const char* path, dev_t* dev, ino_t* ino)
{
    struct stat st;
    if (stat(path, &st) != 0) return false;
    *dev = st.st_dev, *ino = st.st_ino;
    return true;
}

// Opens our own connection, read-only: the kiosk never writes.
static sp_result open_own(sp_dragon* d, sp_error* err)
{
    sp_db* db = NULL;
    sp_result r = sp_db_open(d->db_path, SP_DB_READONLY, &db, err);
    if (r != SP_OK) return r;
    d->db = db;
    dragon_db_file_id(d);
    return SP_OK;
}

// Takes the newest model of the (re)opened database; keeps the old one when
// it cannot be read, and when it is the one already loaded: a curator's
// sketch or review bumps the generation too, and parsing a 30 MB model
// again held the kiosk's frames (BENCHMARKS.md, "A new model while the
// kiosk runs"). Within one file model ids only grow (db train removes old
// models, never the newest), so the newest row's id tells; another file may
// have a model of the same id, so there its checksum tells (read past the
// model's bytes: too slow for every poll).
void dragon_reload_model(sp_dragon* d, bool same_file)
{
    if (d->desc.no_model) return;
    int64_t head = 0, id = 0;
    char sha[65] = "";
    sp_error merr = {0};
    bool known = sp_db_model_head(d->db, &head, same_file ? NULL : sha, &merr) == SP_OK;
    bool loaded = known && d->clf && head > 0 && head == d->model_id;
    if (loaded && (same_file || (d->model_sha[0] && !strcmp(sha, d->model_sha)))) return;
    // With a model to go on with, a kiosk reads the new one on a thread of
    // its own (model_load.c); with none there is nothing better to show meanwhile.
    if (d->desc.background_model && d->own_db && d->clf && dragon_model_load_start(d)) return;
    if (same_file) known = sp_db_model_head(d->db, &head, sha, &merr) == SP_OK;
    sp_clf* clf = NULL;
    sp_result r = sp_db_load_model(d->db, &clf, &id, &merr);
    if (r == SP_OK || r == SP_ERR_INVALID) {
        // SP_ERR_INVALID: no model stored (strokes then need a forced category).
        sp_clf_destroy(d->clf);
        d->clf = r == SP_OK ? clf : NULL;
        d->model_id = r == SP_OK ? id : 0;
        // The checksum read before the model is its own only when the rows agree.
        snprintf(d->model_sha, sizeof d->model_sha, "%s", r == SP_OK && known && id == head ? sha : "");
        snprintf(d->model_error, sizeof d->model_error, "%s", r == SP_OK ? "" : merr.text);
    } else if (!d->clf)
        snprintf(d->model_error, sizeof d->model_error, "%s", merr.text);
}

uint64_t sp_dragon_reload_count(const sp_dragon* d)
{
    return d->reloads;
}

sp_result sp_dragon_reload_if_changed(sp_dragon* d, bool* reloaded, sp_error* err)
{
    if (reloaded) *reloaded = false;
    sp_dragon_model_update(d);
    if (d->own_db) {
        // A database replaced on disk (a new file renamed over it) is a new
        // inode: the open connection still reads the old one. A deleted file
        // keeps being read through the open connection until a new one appears.
        bool replaced = d->db && sp_db_file_check(d->db) == SP_DB_FILE_REPLACED;
        if (replaced || !d->db) {
            // First: then nothing of ours holds the old file's sidecars (a
            // model being read ends, and what it read is not taken).
            (void)dragon_model_load_take(d, true);
            if (d->db) sp_db_close(d->db);
            if (replaced) sp_db_drop_stale_sidecars(d->db_path);
            d->db = NULL;
            if (open_own(d, err) != SP_OK) return SP_ERR_IO; // parts already loaded and the model stay usable
            dragon_reload_model(d, false);
            d->gen = sp_db_generation(d->db);
            cache_prune(d);
            ++d->reloads;
            if (reloaded) *reloaded = true;
            return SP_OK;
        }
    }
    dragon_model_retry(d); // after a reopen, which reads anew anyway
    uint64_t g = sp_db_generation(d->db);
    if (g == 0) return sp_fail(err, SP_ERR_IO, "%s: the database cannot be read", d->db_path);
    if (g == d->gen) return SP_OK;
    dragon_reload_model(d, true);
    d->gen = g;
    cache_prune(d);
    ++d->reloads;
    if (reloaded) *reloaded = true;
    return SP_OK;
}

static tpl* cached(const sp_dragon* d, const char* name)
{
    for (int k = 0; k < d->cache_n; ++k)
        if (!strcmp(d->cache[k]->name, name)) return d->cache[k];
    return NULL;
}

static const struct dragon_failed* failed_before(const sp_dragon* d, const char* name)
{
    for (int k = 0; k < d->failed_n; ++k)
        if (!strcmp(d->failed[k].name, name)) return &d->failed[k];
    return NULL;
}

// Remembers that part `name` did not load, and why (with no memory to
// remember it, it is simply tried again).
static void fail_part(sp_dragon* d, const char* name, sp_result code, const char* why)
{
    snprintf(d->part_error, sizeof d->part_error, "%s", why);
    struct dragon_failed* f = realloc(d->failed, sizeof *f * (size_t)(d->failed_n + 1));
    if (!f) return;
    d->failed = f;
    f += d->failed_n++;
    snprintf(f->name, sizeof f->name, "%s", name);
    f->code = code;
    snprintf(f->why, sizeof f->why, "%s", why);
}

// Loads part `name` into the cache; NULL when it does not load (err says why).
static tpl* cache_load(sp_dragon* d, const char* name, sp_error* err)
{
    sp_error lerr = {0};
    tpl* t = NULL;
    sp_result r = tpl_load(d->db, NULL, -1, name, d->desc.canvas_w, d->desc.canvas_h, &d->desc.solve, &t, &lerr);
    if (r != SP_OK) {
        fail_part(d, name, r, lerr.text);
        sp_fail(err, r, "%s", lerr.text);
        return NULL;
    }
    tpl** c = realloc(d->cache, sizeof(tpl*) * (size_t)(d->cache_n + 1));
    if (!c) {
        dragon_tpl_release(t);
        sp_fail(err, SP_ERR_NO_MEMORY, "part %s: out of memory", name);
        return NULL;
    }
    d->cache = c;
    d->cache[d->cache_n++] = t;
    return t;
}

// The templates of a category (loaded and cached), up to max_variants.
int dragon_category_templates(sp_dragon* d, const char* category, tpl** out, int cap, sp_error* err)
{
    char** names = NULL;
    int n = 0, got = 0;
    if (!d->db) {
        // The database is gone for now: the parts already loaded still serve.
        for (int k = 0; k < d->cache_n && got < cap; ++k)
            if (!strcmp(d->cache[k]->category, category)) out[got++] = d->cache[k];
        return got;
    }
    if (sp_db_category_parts(d->db, category, &names, &n, err) != SP_OK) {
        // Said with the stroke it leaves out (it blamed the stroke file alone).
        if (err) snprintf(d->part_error, sizeof d->part_error, "%s", err->text);
        return 0;
    }
    for (int i = 0; i < n && got < cap; ++i) {
        tpl* t = cached(d, names[i]);
        const struct dragon_failed* f = t ? NULL : failed_before(d, names[i]);
        if (f) { // skipped, as it was when it failed
            snprintf(d->part_error, sizeof d->part_error, "%s", f->why);
            sp_fail(err, f->code, "%s", f->why);
            continue;
        }
        if (!t && !(t = cache_load(d, names[i], err))) continue; // a part that does not load is skipped; err keeps why
        out[got++] = t;
    }
    sp_db_free_strings(names, n);
    return got;
}

tpl* dragon_category_first(sp_dragon* d, const char* category)
{
    tpl* t[1];
    sp_error lerr = {0};
    return dragon_category_templates(d, category, t, 1, &lerr) == 1 ? t[0] : NULL;
}

bool sp_dragon_has_part(sp_dragon* d, const char* category)
{
    return d && category && dragon_category_first(d, category) != NULL;
}

sp_result sp_dragon_preload_step(sp_dragon* d, bool* done, sp_error* err)
{
    *done = true;
    if (!d->db) return SP_OK;
    char** cats = NULL;
    int n = 0;
    sp_result r = sp_db_categories(d->db, &cats, &n, err);
    if (r != SP_OK) return r;
    // The database's parts in order (each category's first max_variants, as
    // strokes use them); the first not loaded from the cursor on is loaded.
    int cap = d->desc.max_variants < 16 ? d->desc.max_variants : 16, index = 0;
    for (int i = 0; i < n && *done; ++i) {
        char** names = NULL;
        int m = 0;
        sp_error lerr = {0};
        if (sp_db_category_parts(d->db, cats[i], &names, &m, &lerr) != SP_OK) continue;
        for (int k = 0; k < m && k < cap && *done; ++k, ++index)
            if (index >= d->preload_next && !cached(d, names[k]) && !failed_before(d, names[k])) {
                d->preload_next = index + 1; // tried once: a part that does not load is not tried again
                cache_load(d, names[k], err);
                *done = false;
            }
        sp_db_free_strings(names, m);
    }
    sp_db_free_strings(cats, n);
    return SP_OK;
}

int sp_dragon_loaded_parts(const sp_dragon* d)
{
    return d->cache_n;
}

const char* sp_dragon_part_error(const sp_dragon* d)
{
    return d->part_error;
}

sp_result sp_dragon_preload(sp_dragon* d, sp_error* err)
{
    d->preload_next = 0;
    bool done = false;
    sp_result r = SP_OK;
    while (!done && r == SP_OK)
        r = sp_dragon_preload_step(d, &done, err);
    return r;
}
