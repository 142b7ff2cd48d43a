// mini_gltf.h: a tiny hand-made skinned glTF (two joints, a quad, embedded
// base64 buffer) with knobs that break it in specific ways, for the loader
// tests, the CLI tests' fixture and the fuzz seed corpus. Header-only so that
// test_gltf.c and the corpus generator share it.
#ifndef SP_MINI_GLTF_H
#define SP_MINI_GLTF_H

#include <math.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct mini_desc {
    int pos_count;     ///< POSITION accessor count (0: 4); larger reads past the buffer view
    int pos_accessor;  ///< POSITION accessor index (0: 0); e.g. 42 is out of range
    bool nan_position; ///< vertex 2 gets x = NaN
    bool zero_weights; ///< vertex 3 has all weights 0
    int bad_joint;     ///< JOINTS_0 value of vertex 0 (0: 0); 5 is past the skin's 2 joints
    bool empty_skin;   ///< "joints": []
    bool cycle;        ///< tip lists root as its child
    const char* uri;   ///< buffer uri instead of the data: URI (e.g. "missing.bin")
    bool armature;     ///< a non-joint "Armature" node above the root joint
    bool extras;       ///< sp_dofs, an "outline" curve, sp_part and a camera
    bool bad_dofs;     ///< sp_dofs with min > max
    const char* dofs;  ///< the root's sp_dofs list (JSON) instead, e.g. bounds past reason
    float w1;          ///< weight of vertex 1 (0: 1); e.g. 0.5 needs renormalising
    bool strip;        ///< TRIANGLE_STRIP instead of indexed TRIANGLES
    bool byte_joints;  ///< JOINTS_0 as UNSIGNED_BYTE (in a separate view)
    const char* part;  ///< with extras: the scene's sp_part JSON (NULL: a tail attached by the short form)
    const float* ibm1; ///< 16 floats, column-major: the tip's inverse bind matrix (NULL: translate by -1 in y)
    const float* ibm0; ///< the root's likewise (NULL: identity)
    const char* camera; ///< the camera's JSON object instead (NULL: a perspective one)
} mini_desc;

static void mini_base64(const unsigned char* d, size_t n, char* out)
{
    static const char* t = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    size_t o = 0;
    for (size_t i = 0; i < n; i += 3) {
        uint32_t v = (uint32_t)d[i] << 16 | (i + 1 < n ? (uint32_t)d[i + 1] << 8 : 0) | (i + 2 < n ? d[i + 2] : 0);
        out[o++] = t[v >> 18 & 63];
        out[o++] = t[v >> 12 & 63];
        out[o++] = i + 1 < n ? t[v >> 6 & 63] : '=';
        out[o++] = i + 2 < n ? t[v & 63] : '=';
    }
    out[o] = 0;
}

/// Writes the glTF JSON into a malloc'd string. Buffer layout: positions
/// (48 B) | joints u16 (32 B) | weights f32 (64 B) | indices u16 (12 B) |
/// inverse bind matrices (128 B) | joints u8 (16 B) = 300 bytes.
static char* mini_gltf(const mini_desc* d)
{
    unsigned char buf[300];
    memset(buf, 0, sizeof buf);
    float pos[12] = {-0.5f, 0, 0, 0.5f, 0, 0, 0.5f, 2, 0, -0.5f, 2, 0};
    if (d->nan_position) pos[6] = NAN;
    uint16_t jn[16] = {0};
    jn[0] = (uint16_t)d->bad_joint;
    jn[8] = jn[12] = 1;
    float w[16] = {1, 0, 0, 0, 1, 0, 0, 0, 0.5f, 0.5f, 0, 0, 1, 0, 0, 0};
    jn[9] = 0; // vertex 2 shared between tip (1) and root (0)
    if (d->w1 > 0) w[4] = d->w1;
    if (d->zero_weights) w[12] = 0;
    uint16_t idx[6] = {0, 1, 2, 0, 2, 3};
    float ibm[32] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, -1, 0, 1};
    if (d->ibm0) memcpy(ibm, d->ibm0, sizeof(float) * 16);
    if (d->ibm1) memcpy(ibm + 16, d->ibm1, sizeof(float) * 16);
    uint8_t jb[16];
    for (int i = 0; i < 16; ++i)
        jb[i] = (uint8_t)jn[i];
    memcpy(buf, pos, 48);
    memcpy(buf + 48, jn, 32);
    memcpy(buf + 80, w, 64);
    memcpy(buf + 144, idx, 12);
    memcpy(buf + 156, ibm, 128);
    memcpy(buf + 284, jb, 16);
    char b64[512];
    mini_base64(buf, sizeof buf, b64);
    char uri[700];
    if (d->uri)
        snprintf(uri, sizeof uri, "%s", d->uri);
    else
        snprintf(uri, sizeof uri, "data:application/octet-stream;base64,%s", b64);

    const char* dofs_root =
        d->bad_dofs ? ", \"extras\": {\"sp_dofs\": [{\"channel\": \"rz\", \"min\": 2, \"max\": 1}]}"
                    : ", \"extras\": {\"sp_dofs\": [{\"channel\": \"rz\", \"min\": -1, \"max\": 1, \"group\": \"pose\"},"
                      " {\"channel\": \"s\", \"min\": 0.5, \"max\": 2, \"group\": \"shape\"},"
                      " {\"channel\": \"tx\", \"min\": -0.25, \"max\": 0.25}]}";
    char own_dofs[512];
    if (d->dofs) snprintf(own_dofs, sizeof own_dofs, ", \"extras\": {\"sp_dofs\": %s}", d->dofs), dofs_root = own_dofs;
    const char* dofs_tip = ", \"extras\": {\"sp_dofs\": [{\"channel\": \"rx\", \"min\": -1.5, \"max\": 1.5}, "
                           "{\"channel\": \"rz\", \"min\": -1.5, \"max\": 1.5}]}";
    bool ex = d->extras || d->bad_dofs || d->dofs;
    char scene_extras[2048];
    snprintf(scene_extras, sizeof scene_extras, ", \"extras\": {\"sp_part\": %s}",
             d->part ? d->part : "{\"category\": \"tail\", \"attach\": \"back\"}");
    char* out = malloc(8192);
    snprintf(out, 8192,
             "{\"asset\": {\"version\": \"2.0\", \"generator\": \"sketchpose tests (hand-made)\"},\n"
             " \"scene\": 0,\n"
             " \"scenes\": [{\"nodes\": [%s, 2%s]%s}],\n"
             " \"nodes\": [\n"
             "  {\"name\": \"root\", \"children\": [1]%s},\n"
             "  {\"name\": \"tip\", \"translation\": [0, 1, 0]%s%s},\n"
             "  {\"name\": \"mesh\", \"mesh\": 0, \"skin\": 0},\n"
             "  {\"name\": \"Armature\"%s, \"rotation\": [0, 0, 0.38268343, 0.92387953]},\n"
             "  {\"name\": \"outline\", \"mesh\": 1, \"skin\": 0, \"extras\": {\"sp_abstraction\": \"outline\", \"sp_curve\": "
             "\"body\","
             " \"sp_correspondence\": \"closest\"}},\n"
             "  {\"name\": \"view\", \"camera\": 0, \"translation\": [0, 1, 5]}\n"
             " ],\n"
             " \"cameras\": [%s],\n"
             " \"meshes\": [\n"
             "  {\"primitives\": [{\"attributes\": {\"POSITION\": %d, \"JOINTS_0\": %d, \"WEIGHTS_0\": 2}%s, \"mode\": %d,"
             " \"material\": 0}]},\n"
             "  {\"primitives\": [{\"attributes\": {\"POSITION\": 0, \"JOINTS_0\": 1, \"WEIGHTS_0\": 2}, \"mode\": 2}]}\n"
             " ],\n"
             " \"materials\": [{\"pbrMetallicRoughness\": {\"baseColorFactor\": [0.9, 0.3, 0.1, 1]}}],\n"
             " \"skins\": [{\"joints\": [%s], \"inverseBindMatrices\": 4}],\n"
             " \"accessors\": [\n"
             "  {\"bufferView\": 0, \"componentType\": 5126, \"count\": %d, \"type\": \"VEC3\", \"min\": [-0.5, 0, 0], \"max\": "
             "[0.5, 2, 0]},\n"
             "  {\"bufferView\": 1, \"componentType\": 5123, \"count\": 4, \"type\": \"VEC4\"},\n"
             "  {\"bufferView\": 2, \"componentType\": 5126, \"count\": 4, \"type\": \"VEC4\"},\n"
             "  {\"bufferView\": 3, \"componentType\": 5123, \"count\": 6, \"type\": \"SCALAR\"},\n"
             "  {\"bufferView\": 4, \"componentType\": 5126, \"count\": 2, \"type\": \"MAT4\"},\n"
             "  {\"bufferView\": 5, \"componentType\": 5121, \"count\": 4, \"type\": \"VEC4\"}\n"
             " ],\n"
             " \"bufferViews\": [\n"
             "  {\"buffer\": 0, \"byteOffset\": 0, \"byteLength\": 48},\n"
             "  {\"buffer\": 0, \"byteOffset\": 48, \"byteLength\": 32},\n"
             "  {\"buffer\": 0, \"byteOffset\": 80, \"byteLength\": 64},\n"
             "  {\"buffer\": 0, \"byteOffset\": 144, \"byteLength\": 12},\n"
             "  {\"buffer\": 0, \"byteOffset\": 156, \"byteLength\": 128},\n"
             "  {\"buffer\": 0, \"byteOffset\": 284, \"byteLength\": 16}\n"
             " ],\n"
             " \"buffers\": [{\"byteLength\": 300, \"uri\": \"%s\"}]\n"
             "}\n",
             d->armature ? "3" : "0", ex ? ", 4, 5" : "", ex ? scene_extras : "", ex ? dofs_root : "",
             d->cycle ? ", \"children\": [0]" : "", ex ? dofs_tip : "", d->armature ? ", \"children\": [0]" : "",
             d->camera ? d->camera
                       : "{\"type\": \"perspective\", \"perspective\": {\"yfov\": 0.8, \"znear\": 0.1, \"zfar\": 100}}",
             d->pos_accessor ? d->pos_accessor : 0, d->byte_joints ? 5 : 1, d->strip ? "" : ", \"indices\": 3", d->strip ? 5 : 4,
             d->empty_skin ? "" : "0, 1", d->pos_count ? d->pos_count : 4, uri);
    return out;
}

static inline bool mini_write(const char* path, const char* text, size_t n)
{
    FILE* f = fopen(path, "wb");
    if (!f) return false;
    bool ok = fwrite(text, 1, n, f) == n;
    return fclose(f) == 0 && ok;
}

#endif
