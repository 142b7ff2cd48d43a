// session.c: kiosk sessions as JSON (cJSON to read, plain stdio to write:
// a 2,000-stroke soak session is ~100k events, one line each; written whole).
#include "sp/kiosk_session.h"
#include "sp/sketch_io.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cjson/cJSON.h>

#include "sp/kiosk_ui.h"

sp_result sp_kiosk_session_append(sp_kiosk_session* s, const sp_kiosk_event* ev)
{
    if (s->count >= SP_KIOSK_SESSION_MAX_EVENTS) return SP_ERR_INVALID;
    if (s->count == s->cap) {
        int cap = s->cap ? 2 * s->cap : 256;
        if (cap > SP_KIOSK_SESSION_MAX_EVENTS) cap = SP_KIOSK_SESSION_MAX_EVENTS;
        sp_kiosk_event* e = realloc(s->events, sizeof *e * (size_t)cap);
        if (!e) return SP_ERR_NO_MEMORY;
        s->events = e, s->cap = cap;
    }
    s->events[s->count++] = *ev;
    return SP_OK;
}

void sp_kiosk_session_free(sp_kiosk_session* s)
{
    if (!s) return;
    free(s->events);
    free(s->marks);
    memset(s, 0, sizeof *s);
}

static bool num(const cJSON* o, const char* key, double* v)
{
    const cJSON* n = cJSON_GetObjectItemCaseSensitive(o, key);
    if (!cJSON_IsNumber(n) || !isfinite(n->valuedouble)) return false;
    *v = n->valuedouble;
    return true;
}

static sp_result add(sp_kiosk_session* s, const sp_kiosk_event* ev, const char* name, int i, sp_error* err)
{
    sp_result r = sp_kiosk_session_append(s, ev);
    if (r == SP_ERR_NO_MEMORY) return sp_fail(err, r, "%s: out of memory at events[%d]", name, i);
    if (r != SP_OK) return sp_fail(err, r, "%s: events[%d]: more than %d events", name, i, SP_KIOSK_SESSION_MAX_EVENTS);
    return SP_OK;
}

static sp_result parse_event(const cJSON* e, int i, const char* name, double* last_t, sp_kiosk_session* s, sp_error* err)
{
    if (!cJSON_IsObject(e)) return sp_fail(err, SP_ERR_PARSE, "%s: events[%d] is not an object", name, i);
    double t;
    if (!num(e, "t", &t) || t < 0)
        return sp_fail(err, SP_ERR_INVALID, "%s: events[%d]: \"t\" must be a number >= 0 (ms)", name, i);
    if (t > SP_KIOSK_SESSION_MAX_MS)
        return sp_fail(err, SP_ERR_INVALID, "%s: events[%d]: t = %g is past %.0f ms (1 hour), the longest session", name, i, t,
                       SP_KIOSK_SESSION_MAX_MS);
    if (t < *last_t)
        return sp_fail(err, SP_ERR_INVALID, "%s: events[%d]: t = %g goes back in time (previous %g)", name, i, t, *last_t);
    *last_t = t;
    const cJSON* ty = cJSON_GetObjectItemCaseSensitive(e, "type");
    const char* tname = cJSON_IsString(ty) ? ty->valuestring : NULL;
    if (!tname) return sp_fail(err, SP_ERR_INVALID, "%s: events[%d]: \"type\" is missing", name, i);
    if (strcmp(tname, "stroke") == 0) {
        const cJSON* pts = cJSON_GetObjectItemCaseSensitive(e, "points");
        int n = cJSON_IsArray(pts) ? cJSON_GetArraySize(pts) : 0;
        if (n < 1) return sp_fail(err, SP_ERR_INVALID, "%s: events[%d]: a stroke needs \"points\": [[x, y], ...]", name, i);
        double dt = 8;
        if (cJSON_GetObjectItemCaseSensitive(e, "dt") && (!num(e, "dt", &dt) || dt < 0 || dt > 60000))
            return sp_fail(err, SP_ERR_INVALID, "%s: events[%d]: \"dt\" must be a number of ms in [0, 60000]", name, i);
        int k = 0;
        const cJSON* p;
        cJSON_ArrayForEach(p, pts)
        {
            const cJSON* x = cJSON_GetArrayItem(p, 0);
            const cJSON* y = cJSON_GetArrayItem(p, 1);
            if (!cJSON_IsArray(p) || !cJSON_IsNumber(x) || !cJSON_IsNumber(y) || !isfinite(x->valuedouble) ||
                !isfinite(y->valuedouble))
                return sp_fail(err, SP_ERR_INVALID, "%s: events[%d]: points[%d] is not [x, y] with finite numbers", name, i, k);
            sp_kiosk_event ev = {k == 0 ? SP_KEV_DOWN : SP_KEV_MOVE, t + dt * k, (float)x->valuedouble, (float)y->valuedouble, 0};
            sp_result r = add(s, &ev, name, i, err);
            if (r != SP_OK) return r;
            if (k == n - 1) {
                ev.type = SP_KEV_UP;
                if ((r = add(s, &ev, name, i, err)) != SP_OK) return r;
            }
            ++k;
        }
        *last_t = t + dt * (n - 1);
        if (*last_t > SP_KIOSK_SESSION_MAX_MS)
            return sp_fail(err, SP_ERR_INVALID,
                           "%s: events[%d]: the stroke ends at %g ms, past %.0f ms (1 hour), the longest session", name, i,
                           *last_t, SP_KIOSK_SESSION_MAX_MS);
        return SP_OK;
    }
    if (strcmp(tname, "mark") == 0) {
        const cJSON* nm = cJSON_GetObjectItemCaseSensitive(e, "name");
        const char* v = cJSON_IsString(nm) ? nm->valuestring : "";
        size_t n = strlen(v);
        bool ok = n >= 1 && n <= 32;
        for (size_t k = 0; ok && k < n; ++k)
            ok = (v[k] >= 'a' && v[k] <= 'z') || (v[k] >= 'A' && v[k] <= 'Z') || (v[k] >= '0' && v[k] <= '9') || v[k] == '_' ||
                 v[k] == '-';
        if (!ok) return sp_fail(err, SP_ERR_INVALID, "%s: events[%d]: a mark needs \"name\": 1-32 of A-Z a-z 0-9 _ -", name, i);
        if (s->mark_count >= 1000) return sp_fail(err, SP_ERR_INVALID, "%s: events[%d]: more than 1000 marks", name, i);
        sp_kiosk_mark* m = realloc(s->marks, sizeof *m * (size_t)(s->mark_count + 1));
        if (!m) return sp_fail(err, SP_ERR_NO_MEMORY, "%s: out of memory at events[%d]", name, i);
        s->marks = m;
        m[s->mark_count].t_ms = t;
        memcpy(m[s->mark_count].name, v, n + 1);
        ++s->mark_count;
        return SP_OK;
    }
    sp_kiosk_event ev = {sp_kiosk_event_parse(tname), t, 0, 0, 0};
    switch (ev.type) {
    case SP_KEV_DOWN:
    case SP_KEV_MOVE:
    case SP_KEV_UP: {
        double x, y, b = 0;
        if (!num(e, "x", &x) || !num(e, "y", &y))
            return sp_fail(err, SP_ERR_INVALID, "%s: events[%d]: \"%s\" needs finite \"x\" and \"y\"", name, i, tname);
        if (cJSON_GetObjectItemCaseSensitive(e, "button") && (!num(e, "button", &b) || b < 0 || b > 15 || b != floor(b)))
            return sp_fail(err, SP_ERR_INVALID, "%s: events[%d]: \"button\" must be an integer in [0, 15]", name, i);
        ev.x = (float)x, ev.y = (float)y, ev.button = (int)b;
        break;
    }
    case SP_KEV_PRESS: {
        const cJSON* tg = cJSON_GetObjectItemCaseSensitive(e, "target");
        sp_kiosk_target k = cJSON_IsString(tg) ? sp_kiosk_target_parse(tg->valuestring) : SP_KT_NONE;
        if (k == SP_KT_NONE)
            return sp_fail(err, SP_ERR_INVALID,
                           "%s: events[%d]: \"press\" needs \"target\": one of undo, redraw, start_over, play, turn, save, "
                           "label, guess1, guess2, guess3, more, part1..part12",
                           name, i);
        ev.button = k;
        break;
    }
    case SP_KEV_CANCEL:
    case SP_KEV_FRAME:
        break;
    default:
        return sp_fail(err, SP_ERR_INVALID,
                       "%s: events[%d]: unknown type \"%.40s\" (down, move, up, cancel, press, stroke, mark, frame)", name, i,
                       tname);
    }
    return add(s, &ev, name, i, err);
}

sp_result sp_kiosk_session_parse(const char* text, size_t len, const char* name, sp_kiosk_session* out, sp_error* err)
{
    memset(out, 0, sizeof *out);
    // As a stroke file (a key given twice replayed nothing; junk values took
    // gigabytes): a session's strokes hold twice a drawing's values.
    sp_result r = sp_json_document_check(text, len, 2 * (size_t)SP_SKETCH_MAX_JSON_VALUES, name, err);
    if (r != SP_OK) return r;
    cJSON* root = cJSON_ParseWithLength(text, len);
    if (!root) return sp_fail(err, SP_ERR_NO_MEMORY, "%s: out of memory", name);
    sp_kiosk_session s = {0};
    const cJSON* fmt = cJSON_GetObjectItemCaseSensitive(root, "format");
    if (!cJSON_IsObject(root) || !cJSON_IsString(fmt) || strcmp(fmt->valuestring, "sketchpose-kiosk-session") != 0) {
        r = sp_fail(err, SP_ERR_PARSE, "%s: not a kiosk session (\"format\": \"sketchpose-kiosk-session\" is missing)", name);
        goto done;
    }
    double v;
    if (!num(root, "version", &v) || v != 1) {
        r = sp_fail(err, SP_ERR_UNSUPPORTED, "%s: unsupported \"version\" (this build reads 1)", name);
        goto done;
    }
    const cJSON* canvas = cJSON_GetObjectItemCaseSensitive(root, "canvas");
    if (canvas) {
        const cJSON* w = cJSON_GetArrayItem(canvas, 0);
        const cJSON* h = cJSON_GetArrayItem(canvas, 1);
        if (!cJSON_IsArray(canvas) || !cJSON_IsNumber(w) || !cJSON_IsNumber(h) ||
            !(w->valuedouble >= 1 && w->valuedouble <= SP_KIOSK_SESSION_MAX_CANVAS) ||
            !(h->valuedouble >= 1 && h->valuedouble <= SP_KIOSK_SESSION_MAX_CANVAS)) {
            r = sp_fail(err, SP_ERR_INVALID, "%s: \"canvas\" must be [width, height] in pixels (1..%d)", name,
                        SP_KIOSK_SESSION_MAX_CANVAS);
            goto done;
        }
        s.canvas_w = (int)w->valuedouble, s.canvas_h = (int)h->valuedouble;
    }
    if (cJSON_GetObjectItemCaseSensitive(root, "px_per_mm") &&
        (!num(root, "px_per_mm", &s.px_per_mm) || s.px_per_mm < 0 || s.px_per_mm > 1000)) {
        r = sp_fail(err, SP_ERR_INVALID, "%s: \"px_per_mm\" must be a number in [0, 1000]", name);
        goto done;
    }
    const cJSON* coords = cJSON_GetObjectItemCaseSensitive(root, "coords");
    if (coords) {
        if (cJSON_IsString(coords) && strcmp(coords->valuestring, "unit") == 0)
            s.unit_coords = true;
        else if (!cJSON_IsString(coords) || strcmp(coords->valuestring, "pixels") != 0) {
            r = sp_fail(err, SP_ERR_INVALID, "%s: \"coords\" must be \"pixels\" or \"unit\"", name);
            goto done;
        }
    }
    const cJSON* events = cJSON_GetObjectItemCaseSensitive(root, "events");
    if (!cJSON_IsArray(events)) {
        r = sp_fail(err, SP_ERR_PARSE, "%s: \"events\" must be an array", name);
        goto done;
    }
    double last_t = 0;
    int i = 0;
    const cJSON* e;
    cJSON_ArrayForEach(e, events)
    {
        if ((r = parse_event(e, i++, name, &last_t, &s, err)) != SP_OK) goto done;
    }
    s.end_ms = last_t;
    if (cJSON_GetObjectItemCaseSensitive(root, "end_ms")) {
        if (!num(root, "end_ms", &v) || v < 0 || v > SP_KIOSK_SESSION_MAX_MS) {
            r = sp_fail(err, SP_ERR_INVALID, "%s: \"end_ms\" must be a number of ms in [0, %.0f] (1 hour)", name,
                        SP_KIOSK_SESSION_MAX_MS);
            goto done;
        }
        if (v > s.end_ms) s.end_ms = v;
    }
done:
    cJSON_Delete(root);
    if (r != SP_OK)
        sp_kiosk_session_free(&s);
    else
        *out = s;
    return r;
}

sp_result sp_kiosk_session_read(const char* path, sp_kiosk_session* out, sp_error* err)
{
    memset(out, 0, sizeof *out);
    void* buf;
    size_t n;
    sp_result r = sp_file_read(path, (size_t)512 << 20, &buf, &n, err);
    if (r == SP_OK) r = sp_kiosk_session_parse(buf, n, path, out, err);
    free(buf);
    return r;
}

sp_result sp_kiosk_session_write(const char* path, const sp_kiosk_session* s, sp_error* err)
{
    // Made in memory and written whole (sp_file_write): a recording cut short
    // by a full disk would not replay, and would have replaced the old one.
    char* text = NULL;
    size_t len = 0;
    FILE* f = open_memstream(&text, &len);
    if (!f) return sp_fail(err, SP_ERR_NO_MEMORY, "%s: out of memory", path);
    double end = s->end_ms;
    fprintf(f,
            "{\"format\": \"sketchpose-kiosk-session\", \"version\": 1, \"canvas\": [%d, %d], \"px_per_mm\": %.6g, \"coords\": "
            "\"%s\",\n",
            s->canvas_w > 0 ? s->canvas_w : 1, s->canvas_h > 0 ? s->canvas_h : 1, s->px_per_mm,
            s->unit_coords ? "unit" : "pixels");
    fprintf(f, " \"events\": [");
    bool first = true;
    for (int i = 0; i < s->count; ++i) {
        const sp_kiosk_event* e = &s->events[i];
        if (e->type == SP_KEV_FRAME || !sp_kiosk_event_name(e->type)) continue;
        if (e->t_ms > end) end = e->t_ms;
        fprintf(f, "%s\n  {\"t\": %.17g, \"type\": \"%s\"", first ? "" : ",", e->t_ms, sp_kiosk_event_name(e->type));
        first = false;
        if (e->type == SP_KEV_PRESS) {
            const char* tn = sp_kiosk_target_name((sp_kiosk_target)e->button);
            fprintf(f, ", \"target\": \"%s\"}", tn ? tn : "undo");
        } else if (e->type == SP_KEV_CANCEL) {
            fprintf(f, "}");
        } else {
            // %.9g round-trips a float exactly: a replay sees the same pixels.
            fprintf(f, ", \"x\": %.9g, \"y\": %.9g", e->x, e->y);
            if (e->button) fprintf(f, ", \"button\": %d", e->button);
            fprintf(f, "}");
        }
    }
    fprintf(f, "\n ],\n \"end_ms\": %.3f}\n", end);
    return sp_file_write_printed(path, f, &text, &len, err);
}

sp_kiosk_event sp_kiosk_session_map(const sp_kiosk_session* s, const sp_kiosk_event* ev, int fb_w, int fb_h)
{
    sp_kiosk_event o = *ev;
    if (o.type != SP_KEV_DOWN && o.type != SP_KEV_MOVE && o.type != SP_KEV_UP) return o;
    if (s->unit_coords) {
        o.x = ev->x * (float)fb_w, o.y = ev->y * (float)fb_h;
    } else if (s->canvas_w > 0 && s->canvas_h > 0 && (s->canvas_w != fb_w || s->canvas_h != fb_h)) {
        // One scale for both axes, the canvas centred: a drawing replayed on a
        // screen of another shape keeps its shape (stretched, a recorded tree
        // became a pair of wings on a portrait screen).
        double k = fmin((double)fb_w / s->canvas_w, (double)fb_h / s->canvas_h);
        o.x = (float)(ev->x * k + 0.5 * (fb_w - s->canvas_w * k));
        o.y = (float)(ev->y * k + 0.5 * (fb_h - s->canvas_h * k));
    }
    return o;
}
