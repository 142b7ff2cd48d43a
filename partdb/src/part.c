// part.c: the one reader and writer of `sp_part` (sp/part.h).
#include <cjson/cJSON.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gltf_internal.h"

void sp_part_free(sp_part* part)
{
    if (!part) return;
    for (int i = 0; i < part->socket_count; ++i) {
        free(part->sockets[i].accepts);
        free(part->sockets[i].extra);
    }
    free(part->sockets);
    free(part->attach.extra);
    free(part->extra);
    memset(part, 0, sizeof *part);
}

// ---- reading ----------------------------------------------------------------

static bool take_name(const cJSON* v, char out[SP_NAME_MAX])
{
    if (!cJSON_IsString(v) || !v->valuestring) return false;
    size_t n = strlen(v->valuestring);
    if (n == 0 || n >= SP_NAME_MAX) return false;
    memcpy(out, v->valuestring, n + 1);
    return true;
}

static bool take_vec3(const cJSON* v, sp_vec3* out)
{
    if (!cJSON_IsArray(v) || cJSON_GetArraySize(v) != 3) return false;
    double a[3];
    for (int i = 0; i < 3; ++i) {
        const cJSON* e = cJSON_GetArrayItem(v, i);
        if (!cJSON_IsNumber(e) || !isfinite(e->valuedouble)) return false;
        a[i] = e->valuedouble;
    }
    *out = sp_v3(a[0], a[1], a[2]);
    return true;
}

static bool is_known(const char* key, const char* const* known)
{
    for (; *known; ++known)
        if (!strcmp(key, *known)) return true;
    return false;
}

// The members of obj not in `known` (NULL-terminated) as a compact JSON
// object into *extra; NULL when there are none. False: out of memory.
static bool keep_extra(const cJSON* obj, const char* const* known, char** extra)
{
    *extra = NULL;
    cJSON* rest = NULL;
    const cJSON* it;
    cJSON_ArrayForEach(it, obj)
    {
        if (is_known(it->string, known)) continue;
        if (!rest && !(rest = cJSON_CreateObject())) return false;
        cJSON* copy = cJSON_Duplicate(it, true);
        if (!copy || !cJSON_AddItemToObject(rest, it->string, copy)) {
            cJSON_Delete(copy);
            cJSON_Delete(rest);
            return false;
        }
    }
    if (!rest) return true;
    *extra = cJSON_PrintUnformatted(rest);
    cJSON_Delete(rest);
    return *extra != NULL;
}

// An optional name member: absent leaves out[] empty; false: present and not a name.
static bool opt_name(const cJSON* obj, const char* key, char out[SP_NAME_MAX])
{
    const cJSON* v = cJSON_GetObjectItemCaseSensitive(obj, key);
    return !v || take_name(v, out);
}

static sp_result opt_position(const cJSON* obj, bool* has, sp_vec3* p, const char* what, const char* where, sp_error* err)
{
    const cJSON* v = cJSON_GetObjectItemCaseSensitive(obj, "position");
    *has = v != NULL;
    if (v && !take_vec3(v, p))
        return sp_fail(err, SP_ERR_INVALID, "%s: sp_part: %s.position must be 3 finite numbers", what, where);
    return SP_OK;
}

static sp_result bad_name(const char* what, const char* where, sp_error* err)
{
    return sp_fail(err, SP_ERR_INVALID, "%s: sp_part: %s must be a name of 1 to %d characters", what, where, SP_NAME_MAX - 1);
}

static sp_result read_socket(const cJSON* s, int i, const char* what, sp_part_socket* out, sp_error* err)
{
    static const char* const known[] = {"name", "joint", "position", "accepts", NULL};
    char where[32];
    snprintf(where, sizeof where, "sockets[%d]", i);
    if (!cJSON_IsObject(s)) return sp_fail(err, SP_ERR_INVALID, "%s: sp_part: %s must be an object", what, where);
    const cJSON* name = cJSON_GetObjectItemCaseSensitive(s, "name");
    if (!name) return sp_fail(err, SP_ERR_INVALID, "%s: sp_part: %s has no name", what, where);
    char field[48];
    snprintf(field, sizeof field, "%s.name", where);
    if (!take_name(name, out->name)) return bad_name(what, field, err);
    snprintf(field, sizeof field, "%s.joint", where);
    if (!opt_name(s, "joint", out->joint)) return bad_name(what, field, err);
    sp_result r = opt_position(s, &out->has_position, &out->position, what, where, err);
    if (r != SP_OK) return r;
    const cJSON* acc = cJSON_GetObjectItemCaseSensitive(s, "accepts");
    int n = !acc ? 0 : cJSON_IsArray(acc) ? cJSON_GetArraySize(acc) : 1;
    if (n > 0 && !(out->accepts = calloc((size_t)n, sizeof *out->accepts)))
        return sp_fail(err, SP_ERR_NO_MEMORY, "%s: out of memory", what);
    bool ok = true;
    if (cJSON_IsArray(acc)) {
        const cJSON* c;
        cJSON_ArrayForEach(c, acc) ok = ok && take_name(c, out->accepts[out->accept_count++]);
    } else if (acc) {
        ok = take_name(acc, out->accepts[0]);
        out->accept_count = 1;
    }
    if (!ok)
        return sp_fail(err, SP_ERR_INVALID, "%s: sp_part: %s.accepts must be a name or a list of names of 1 to %d characters",
                       what, where, SP_NAME_MAX - 1);
    if (!keep_extra(s, known, &out->extra)) return sp_fail(err, SP_ERR_NO_MEMORY, "%s: out of memory", what);
    return SP_OK;
}

static sp_result read_attach(const cJSON* at, const char* what, sp_part_attach* out, sp_error* err)
{
    static const char* const known[] = {"socket", "joint", "position", NULL};
    if (cJSON_IsString(at)) // the short form: the attachment joint's name
        return take_name(at, out->joint) ? SP_OK : bad_name(what, "attach", err);
    if (!cJSON_IsObject(at)) return sp_fail(err, SP_ERR_INVALID, "%s: sp_part: attach must be an object or a joint name", what);
    if (!opt_name(at, "socket", out->socket)) return bad_name(what, "attach.socket", err);
    if (!opt_name(at, "joint", out->joint)) return bad_name(what, "attach.joint", err);
    sp_result r = opt_position(at, &out->has_position, &out->position, what, "attach", err);
    if (r != SP_OK) return r;
    if (!keep_extra(at, known, &out->extra)) return sp_fail(err, SP_ERR_NO_MEMORY, "%s: out of memory", what);
    return SP_OK;
}

static sp_result read_part(const cJSON* j, const char* what, sp_part* out, sp_error* err)
{
    static const char* const known[] = {"category", "abstraction", "family", "sockets", "attach", NULL};
    if (!cJSON_IsObject(j)) return sp_fail(err, SP_ERR_INVALID, "%s: sp_part must be a JSON object", what);
    if (!opt_name(j, "category", out->category)) return bad_name(what, "category", err);
    if (!opt_name(j, "abstraction", out->abstraction)) return bad_name(what, "abstraction", err);
    if (!opt_name(j, "family", out->family)) return bad_name(what, "family", err);
    const cJSON* sockets = cJSON_GetObjectItemCaseSensitive(j, "sockets");
    if (sockets && !cJSON_IsArray(sockets)) return sp_fail(err, SP_ERR_INVALID, "%s: sp_part: sockets must be a list", what);
    int n = cJSON_GetArraySize(sockets);
    if (n > 0 && !(out->sockets = calloc((size_t)n, sizeof *out->sockets)))
        return sp_fail(err, SP_ERR_NO_MEMORY, "%s: out of memory", what);
    const cJSON* s;
    cJSON_ArrayForEach(s, sockets)
    {
        sp_result r = read_socket(s, out->socket_count, what, &out->sockets[out->socket_count], err);
        ++out->socket_count; // counted also when it fails, so that sp_part_free frees it
        if (r != SP_OK) return r;
    }
    const cJSON* at = cJSON_GetObjectItemCaseSensitive(j, "attach");
    out->has_attach = at != NULL;
    if (at) {
        sp_result r = read_attach(at, what, &out->attach, err);
        if (r != SP_OK) return r;
    }
    if (!keep_extra(j, known, &out->extra)) return sp_fail(err, SP_ERR_NO_MEMORY, "%s: out of memory", what);
    return SP_OK;
}

sp_result sp_part_from_cjson(const cJSON* j, const char* what, sp_part* out, sp_error* err)
{
    memset(out, 0, sizeof *out);
    sp_result r = read_part(j, what, out, err);
    if (r != SP_OK) sp_part_free(out);
    return r;
}

sp_result sp_part_parse_json(const char* json, const char* what, sp_part* out, sp_error* err)
{
    memset(out, 0, sizeof *out);
    cJSON* j = json ? cJSON_Parse(json) : NULL;
    if (!j) return sp_fail(err, SP_ERR_PARSE, "%s: sp_part is not valid JSON", what);
    sp_result r = sp_part_from_cjson(j, what, out, err);
    cJSON_Delete(j);
    return r;
}

// ---- writing ----------------------------------------------------------------

static int cmp_member(const void* a, const void* b)
{
    return strcmp((*(cJSON* const*)a)->string, (*(cJSON* const*)b)->string);
}

// Reorders obj's members by key, as tinygltf writes a glTF file's objects
// (std::map), so that the text equals the file's.
static bool sort_members(cJSON* obj)
{
    int n = cJSON_GetArraySize(obj);
    if (n < 2) return true;
    cJSON** v = malloc(sizeof *v * (size_t)n);
    if (!v) return false;
    for (int i = 0; i < n; ++i)
        v[i] = cJSON_DetachItemViaPointer(obj, obj->child);
    qsort(v, (size_t)n, sizeof *v, cmp_member);
    for (int i = 0; i < n; ++i)
        cJSON_AddItemToArray(obj, v[i]); // keeps the member's key
    free(v);
    return true;
}

// Known members, then the extra ones whose keys are not taken, then sorted.
// False: out of memory.
static bool finish_object(cJSON* obj, const char* extra)
{
    if (extra) {
        cJSON* rest = cJSON_Parse(extra);
        if (!rest) return false;
        while (rest->child) {
            cJSON* it = cJSON_DetachItemViaPointer(rest, rest->child);
            if (cJSON_GetObjectItemCaseSensitive(obj, it->string))
                cJSON_Delete(it); // a known key wins
            else
                cJSON_AddItemToArray(obj, it);
        }
        cJSON_Delete(rest);
    }
    return sort_members(obj);
}

static bool add_name(cJSON* obj, const char* key, const char* name)
{
    return !name[0] || cJSON_AddStringToObject(obj, key, name) != NULL;
}

static bool add_position(cJSON* obj, bool has, sp_vec3 p)
{
    double a[3] = {p.x, p.y, p.z};
    return !has || cJSON_AddItemToObject(obj, "position", cJSON_CreateDoubleArray(a, 3));
}

static bool finite3(sp_vec3 p)
{
    return isfinite(p.x) && isfinite(p.y) && isfinite(p.z);
}

static cJSON* socket_cjson(const sp_part_socket* s)
{
    cJSON* o = cJSON_CreateObject();
    bool ok =
        o && add_name(o, "name", s->name) && add_name(o, "joint", s->joint) && add_position(o, s->has_position, s->position);
    if (ok && s->accept_count > 0) {
        cJSON* acc = cJSON_AddArrayToObject(o, "accepts");
        for (int i = 0; ok && i < s->accept_count; ++i)
            ok = acc && cJSON_AddItemToArray(acc, cJSON_CreateString(s->accepts[i]));
    }
    if (ok && finish_object(o, s->extra)) return o;
    cJSON_Delete(o);
    return NULL;
}

sp_result sp_part_to_cjson(const sp_part* p, cJSON** out, sp_error* err)
{
    *out = NULL;
    for (int i = 0; i < p->socket_count; ++i) {
        if (!p->sockets[i].name[0]) return sp_fail(err, SP_ERR_INVALID, "sp_part: sockets[%d] has no name", i);
        if (p->sockets[i].has_position && !finite3(p->sockets[i].position))
            return sp_fail(err, SP_ERR_INVALID, "sp_part: socket '%s': the position is not finite", p->sockets[i].name);
    }
    if (p->has_attach && p->attach.has_position && !finite3(p->attach.position))
        return sp_fail(err, SP_ERR_INVALID, "sp_part: attach: the position is not finite");
    cJSON* o = cJSON_CreateObject();
    bool ok = o && add_name(o, "category", p->category) && add_name(o, "abstraction", p->abstraction) &&
              add_name(o, "family", p->family);
    if (ok && p->socket_count > 0) {
        cJSON* arr = cJSON_AddArrayToObject(o, "sockets");
        for (int i = 0; ok && i < p->socket_count; ++i)
            ok = arr && cJSON_AddItemToArray(arr, socket_cjson(&p->sockets[i]));
    }
    if (ok && p->has_attach) {
        cJSON* at = cJSON_AddObjectToObject(o, "attach");
        ok = at && add_name(at, "socket", p->attach.socket) && add_name(at, "joint", p->attach.joint) &&
             add_position(at, p->attach.has_position, p->attach.position) && finish_object(at, p->attach.extra);
    }
    if (ok && finish_object(o, p->extra)) {
        *out = o;
        return SP_OK;
    }
    cJSON_Delete(o);
    return sp_fail(err, SP_ERR_NO_MEMORY, "sp_part: out of memory");
}

sp_result sp_part_write_json(const sp_part* part, char** json, sp_error* err)
{
    *json = NULL;
    cJSON* o;
    sp_result r = sp_part_to_cjson(part, &o, err);
    if (r != SP_OK) return r;
    *json = cJSON_PrintUnformatted(o);
    cJSON_Delete(o);
    return *json ? SP_OK : sp_fail(err, SP_ERR_NO_MEMORY, "sp_part: out of memory");
}

// ---- copying ----------------------------------------------------------------

static bool dup_text(const char* src, char** dst)
{
    *dst = src ? strdup(src) : NULL;
    return !src || *dst;
}

sp_result sp_part_copy(const sp_part* src, sp_part* dst, sp_error* err)
{
    *dst = *src;
    dst->sockets = NULL;
    dst->socket_count = 0;
    bool ok = dup_text(src->extra, &dst->extra);
    ok = dup_text(src->attach.extra, &dst->attach.extra) && ok; // both set, so that a failure frees what was made
    if (ok && src->socket_count > 0) ok = (dst->sockets = calloc((size_t)src->socket_count, sizeof *dst->sockets)) != NULL;
    for (int i = 0; ok && i < src->socket_count; ++i) {
        const sp_part_socket* s = &src->sockets[i];
        sp_part_socket* d = &dst->sockets[dst->socket_count++];
        *d = *s;
        d->accepts = NULL;
        d->accept_count = 0;
        ok = dup_text(s->extra, &d->extra);
        if (ok && s->accept_count > 0) ok = (d->accepts = malloc(sizeof *d->accepts * (size_t)s->accept_count)) != NULL;
        if (d->accepts) {
            memcpy(d->accepts, s->accepts, sizeof *d->accepts * (size_t)s->accept_count);
            d->accept_count = s->accept_count;
        }
    }
    if (ok) return SP_OK;
    sp_part_free(dst);
    return sp_fail(err, SP_ERR_NO_MEMORY, "sp_part: out of memory");
}

bool sp_part_name_is_plain(const char* s)
{
    size_t n = s ? strlen(s) : 0;
    if (n == 0 || n >= SP_NAME_MAX || s[0] == '.') return false;
    for (size_t i = 0; i < n; ++i) {
        char c = s[i];
        if (!((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '-' || c == '.'))
            return false;
    }
    return true;
}
