// report.c: the whole dragon's solve report (DESIGN.md, "dragon --report").
#include <cjson/cJSON.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "dragon_internal.h"
#include "report.h"

static cJSON* box_json(const double b[4])
{
    return cJSON_CreateDoubleArray(b, 4);
}

// Part i's abstraction at the last pose, on the canvas: its box (x0 y0 x1 y1).
static void outline_box(const sp_dragon* d, const part* p, double b[4])
{
    int n = p->t->ch.rig.abstractions[p->t->abstraction].point_count;
    b[0] = b[1] = INFINITY, b[2] = b[3] = -INFINITY;
    for (int k = 0; k < n; ++k) {
        sp_vec2 u = sp_camera_project(&d->world, (sp_vec3){p->outline[3 * k], p->outline[3 * k + 1], p->outline[3 * k + 2]});
        b[0] = fmin(b[0], u.x), b[1] = fmin(b[1], u.y), b[2] = fmax(b[2], u.x), b[3] = fmax(b[3], u.y);
    }
}

static cJSON* report_tree(sp_dragon* d)
{
    dragon_pose(d, 0);
    cJSON* o = cJSON_CreateObject();
    double ms = 0, eb = 0, ea = 0, mean = 0, mx = 0;
    int it = 0, rounds = 0, unused = 0;
    const char* stopped = "converged";
    sp_vec2 lo = {0, 0}, hi = {0, 0};
    char note[1024] = "";
    cJSON* curves = cJSON_CreateArray();
    cJSON* params = cJSON_CreateObject();
    cJSON* parts = cJSON_CreateArray();
    for (int i = 0; i < d->part_n; ++i) {
        const part* p = d->parts[i];
        const sp_solve_report* r = &p->pub.report;
        const sp_rig* rig = &p->t->ch.rig;
        const sp_abstraction* ab = &rig->abstractions[p->t->abstraction];
        ms += r->ms, it += r->iterations, rounds += r->icp_rounds, eb += r->before.total, ea += r->after.total;
        mean += r->mean_error_px / d->part_n, mx = fmax(mx, r->max_error_px), unused += r->unused_strokes;
        if (r->stopped != SP_STOP_CONVERGED && !strcmp(stopped, "converged")) stopped = sp_stop_reason_name(r->stopped);
        if (r->note[0]) {
            size_t l = strlen(note);
            snprintf(note + l, sizeof note - l, "%spart %d (%s): %s", l ? "; " : "", i, p->pub.category, r->note);
        }
        for (int k = 0; k < p->stroke_n; ++k) {
            sp_vec2 s = p->stroke[k];
            if (i == 0 && k == 0) lo = hi = s;
            lo.x = fmin(lo.x, s.x), lo.y = fmin(lo.y, s.y), hi.x = fmax(hi.x, s.x), hi.y = fmax(hi.y, s.y);
        }
        for (int c = 0; c < r->curve_count; ++c) {
            cJSON* cv = cJSON_CreateObject();
            cJSON_AddNumberToObject(cv, "part", i);
            cJSON_AddStringToObject(cv, "curve", c < ab->curve_count ? ab->curves[c].name : "");
            // One stroke per part, in order (demo's strokes file); `dragon`
            // renumbers it by its input's strokes, refused ones included.
            if (r->curves[c].stroke >= 0)
                cJSON_AddNumberToObject(cv, "stroke", i);
            else
                cJSON_AddNullToObject(cv, "stroke");
            cJSON_AddBoolToObject(cv, "reversed", r->curves[c].reversed);
            cJSON_AddNumberToObject(cv, "mean_error_px", r->curves[c].mean_px);
            cJSON_AddNumberToObject(cv, "max_error_px", r->curves[c].max_px);
            cJSON_AddItemToArray(curves, cv);
        }
        for (int k = 0; k < rig->param_count; ++k) {
            char key[3 * SP_NAME_MAX];
            snprintf(key, sizeof key, "%d/%s", i, rig->params[k].name);
            cJSON_AddNumberToObject(params, key, p->p_fit[k]);
        }
        cJSON* pj = cJSON_CreateObject();
        cJSON_AddStringToObject(pj, "category", p->pub.category);
        cJSON_AddNumberToObject(pj, "confidence", p->pub.confidence);
        cJSON_AddStringToObject(pj, "name", p->pub.name);
        cJSON_AddNumberToObject(pj, "attached_to", p->pub.attached_to);
        if (p->pub.socket[0])
            cJSON_AddStringToObject(pj, "socket", p->pub.socket);
        else
            cJSON_AddNullToObject(pj, "socket");
        if (p->pub.attached_to >= 0) {
            double a[2] = {p->pub.anchor.x, p->pub.anchor.y};
            cJSON_AddItemToObject(pj, "anchor_px", cJSON_CreateDoubleArray(a, 2));
        } else {
            cJSON_AddNullToObject(pj, "anchor_px");
        }
        cJSON_AddBoolToObject(pj, "far_side", p->pub.far_side);
        cJSON_AddBoolToObject(pj, "mirrored", p->pub.mirrored);
        double box[4];
        outline_box(d, p, box);
        cJSON_AddItemToObject(pj, "outline_bbox_px", box_json(box));
        cJSON_AddItemToObject(pj, "stroke_bbox_px", box_json(p->stroke_box));
        cJSON_AddStringToObject(pj, "note", p->note ? sp_dragon_note_name(p->note) : "");
        cJSON_AddItemToObject(pj, "report", sp_report_to_json(r, rig, ab, p->p_fit));
        cJSON_AddItemToArray(parts, pj);
    }
    cJSON_AddNumberToObject(o, "ms", ms);
    cJSON_AddNumberToObject(o, "iterations", it);
    cJSON_AddNumberToObject(o, "icp_rounds", rounds);
    cJSON_AddStringToObject(o, "stopped", stopped);
    cJSON_AddNumberToObject(o, "energy_before", eb);
    cJSON_AddNumberToObject(o, "energy_after", ea);
    cJSON_AddNumberToObject(o, "mean_error_px", mean);
    cJSON_AddNumberToObject(o, "max_error_px", mx);
    cJSON_AddNumberToObject(o, "bbox_diagonal_px", sp_v2_len(sp_v2_sub(hi, lo)));
    cJSON_AddItemToObject(o, "curves", curves);
    cJSON_AddNumberToObject(o, "unused_strokes", unused);
    cJSON_AddStringToObject(o, "note", note);
    cJSON_AddItemToObject(o, "parameters", params);
    cJSON_AddNumberToObject(o, "period_s", d->period);
    cJSON_AddItemToObject(o, "parts", parts);
    cJSON* details = cJSON_AddArrayToObject(o, "details");
    for (int i = 0; i < d->detail_n; ++i) {
        sp_dragon_detail e;
        sp_dragon_detail_get(d, i, &e);
        cJSON* dj = cJSON_CreateObject();
        cJSON_AddNumberToObject(dj, "part", e.part);
        cJSON_AddNumberToObject(dj, "points", e.point_count);
        cJSON_AddItemToArray(details, dj);
    }
    d->posed = false;
    return o;
}

sp_result sp_dragon_report_json(sp_dragon* d, char** json, sp_error* err)
{
    // The outlines' boxes at t = 0 are read from a pose, which reuses the
    // parts' evaluation buffers (sp/dragon.h says a report ends the last pose).
    cJSON* o = report_tree(d);
    // cJSON allocates with malloc (the project sets no hooks): free() frees it.
    *json = o ? cJSON_PrintUnformatted(o) : NULL;
    cJSON_Delete(o);
    return *json ? SP_OK : sp_fail(err, SP_ERR_NO_MEMORY, "dragon report: out of memory");
}
