// report.c: the whole dragon's solve report (DESIGN.md, "dragon --report").
#include <cjson/cJSON.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "dragon_internal.h"
#include "report.h"

struct cJSON* sp_dragon_report_json(const sp_dragon* d)
{
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
            // One stroke per part, in order: the part's stroke is stroke i of the file.
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
        if (p->pub.attached_to >= 0) {
            cJSON_AddNumberToObject(pj, "attached_to", p->pub.attached_to);
            cJSON_AddStringToObject(pj, "socket", p->pub.socket);
        } else {
            cJSON_AddNullToObject(pj, "attached_to");
            cJSON_AddNullToObject(pj, "socket");
        }
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
    return o;
}
