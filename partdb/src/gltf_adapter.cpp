// gltf_adapter.cpp: the only file that includes <tiny_gltf.h>. It turns a
// glTF document into the plain C structs of sp/rig.h and sp/gltf.h (and
// back, for export); the sketch-abstraction conventions that need no glTF
// types live in character.c and stickfig.c.
//
// Every exported function is an exception firewall: tinygltf and the STL may
// throw, C callers must not see it. Inside, errors are thrown as `Failure`
// (code + one-line message) and turned into an sp_result at the boundary.
#include <tiny_gltf.h>

#include <cjson/cJSON.h>
#include <sys/stat.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <memory>
#include <new>
#include <set>
#include <sstream>
#include <string>
#include <tuple>
#include <unordered_map>
#include <vector>

// Why the pragma: sp/math.h is C11 and uses compound literals, which C++
// accepts only as a GNU extension (-pedantic warns).
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpedantic"
#include "gltf_internal.h"
#include "sp/sketch_io.h"
#pragma GCC diagnostic pop

namespace
{

struct Failure {
    sp_result code;
    std::string text;
};

[[noreturn]] __attribute__((format(printf, 2, 3))) void fail(sp_result code, const char* fmt, ...)
{
    char buf[512];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(buf, sizeof buf, fmt, ap);
    va_end(ap);
    throw Failure{code, buf};
}

// tinygltf reports several lines; we keep the first meaningful one.
std::string first_line(const std::string& s)
{
    size_t i = 0;
    while (i < s.size()) {
        size_t e = s.find('\n', i);
        if (e == std::string::npos) e = s.size();
        std::string line = s.substr(i, e - i);
        while (!line.empty() && (line.back() == '\r' || line.back() == ' '))
            line.pop_back();
        if (!line.empty()) return line;
        i = e + 1;
    }
    return std::string();
}

// ---- GLB container check ------------------------------------------------

uint32_t le32(const unsigned char* p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

// Why our own check: tinygltf 2.7 trusts some of the GLB header's lengths.
// Returns the number of bytes the container declares.
size_t check_glb(const unsigned char* d, size_t n, const char* what)
{
    if (n < 20) fail(SP_ERR_PARSE, "%s: truncated .glb (%zu bytes, the header alone is 20)", what, n);
    if (le32(d + 4) != 2) fail(SP_ERR_UNSUPPORTED, "%s: .glb version %u (only glTF 2.0 is supported)", what, le32(d + 4));
    size_t total = le32(d + 8);
    if (total > n) fail(SP_ERR_PARSE, "%s: truncated .glb (the header says %zu bytes, the file has %zu)", what, total, n);
    if (total < 20) fail(SP_ERR_PARSE, "%s: corrupt .glb header (total length %zu)", what, total);
    size_t json_len = le32(d + 12);
    if (le32(d + 16) != 0x4E4F534Au) fail(SP_ERR_PARSE, "%s: .glb: the first chunk is not JSON", what);
    if (json_len > total - 20) fail(SP_ERR_PARSE, "%s: truncated .glb (the JSON chunk runs past the end)", what);
    size_t off = 20 + json_len;
    if (off < total) {
        if (total - off < 8) fail(SP_ERR_PARSE, "%s: truncated .glb (incomplete chunk header at byte %zu)", what, off);
        size_t bin_len = le32(d + off);
        if (bin_len > total - off - 8) fail(SP_ERR_PARSE, "%s: truncated .glb (the BIN chunk runs past the end)", what);
    }
    return total;
}

// ---- tinygltf callbacks -------------------------------------------------

// Why: we never need pixels (colours come from baseColorFactor), and
// decoding a JPEG costs time and attack surface.
bool skip_image(tinygltf::Image*, const int, std::string*, std::string*, int, int, const unsigned char*, int, void*)
{
    return true;
}

bool no_file_exists(const std::string&, void*)
{
    return false;
}
std::string no_expand(const std::string& p, void*)
{
    return p;
}
bool no_read(std::vector<unsigned char>*, std::string* err, const std::string& p, void*)
{
    if (err) *err += "external file '" + p + "' cannot be resolved when loading from memory\n";
    return false;
}
bool no_write(std::string*, const std::string&, const std::vector<unsigned char>&, void*)
{
    return false;
}

// What the document's "buffers" say, read with cJSON beside tinygltf: its
// messages name neither the buffer nor the numbers, and the file callback
// must know a buffer's byteLength before it allocates. Also the nodes that
// give both a matrix and a TRS, which tinygltf reads as the matrix alone.
struct BufferDecl {
    bool has_uri = false;
    std::string uri;
    double byte_length = -1; // -1: missing or not a number
};

struct LoadContext {
    const char* what = "";
    std::vector<BufferDecl> buffers;
    std::vector<int> matrix_and_trs; // nodes with both (tinygltf keeps only the matrix)
    std::vector<std::string> required; // extensionsRequired
    bool scanned = false;
    std::string message; // set by read_buffer_file: says better what went wrong
};

void scan_buffers(LoadContext& cx, const unsigned char* json, size_t len)
{
    cx.scanned = true;
    cJSON* root = cJSON_ParseWithLength(reinterpret_cast<const char*>(json), len);
    const cJSON* bufs = cJSON_GetObjectItemCaseSensitive(root, "buffers");
    if (!cJSON_IsArray(bufs)) bufs = nullptr;
    const cJSON* b;
    cJSON_ArrayForEach(b, bufs)
    {
        BufferDecl d;
        const cJSON* uri = cJSON_GetObjectItemCaseSensitive(b, "uri");
        const cJSON* bl = cJSON_GetObjectItemCaseSensitive(b, "byteLength");
        d.has_uri = cJSON_IsString(uri) && uri->valuestring[0];
        if (d.has_uri) d.uri = uri->valuestring;
        if (cJSON_IsNumber(bl)) d.byte_length = bl->valuedouble;
        cx.buffers.push_back(d);
    }
    const cJSON* req = cJSON_GetObjectItemCaseSensitive(root, "extensionsRequired");
    if (!cJSON_IsArray(req)) req = nullptr;
    const cJSON* r;
    cJSON_ArrayForEach(r, req)
    {
        if (cJSON_IsString(r)) cx.required.push_back(r->valuestring);
    }
    const cJSON* nodes = cJSON_GetObjectItemCaseSensitive(root, "nodes");
    if (!cJSON_IsArray(nodes)) nodes = nullptr;
    int i = 0;
    const cJSON* n;
    cJSON_ArrayForEach(n, nodes)
    {
        auto has = [n](const char* key) { return cJSON_GetObjectItemCaseSensitive(n, key) != nullptr; };
        if (has("matrix") && (has("translation") || has("rotation") || has("scale"))) cx.matrix_and_trs.push_back(i);
        ++i;
    }
    cJSON_Delete(root);
}

// The JSON text of a .gltf, or of a .glb's first chunk (check_glb has run).
// tinygltf's JSON parser recurses once a level: a 40 KB file nested 20,000
// deep overflowed the stack (every command, and the kiosk at start). No
// glTF needs more than a few dozen levels; cJSON (scan_buffers) stops at
// the same limit.
enum { JSON_DEPTH_MAX = CJSON_NESTING_LIMIT };

void check_json_depth(const LoadContext& cx, const unsigned char* json, size_t len)
{
    if (sp_json_measure(reinterpret_cast<const char*>(json), len).depth > JSON_DEPTH_MAX)
        fail(SP_ERR_PARSE, "%s: the JSON is nested more than %d levels deep", cx.what, JSON_DEPTH_MAX);
}

void scan_buffers_of(LoadContext& cx, const unsigned char* data, size_t size)
{
    const unsigned char* json = data;
    size_t len = size;
    if (size >= 20 && !memcmp(data, "glTF", 4)) json = data + 20, len = std::min((size_t)le32(data + 12), size - 20);
    check_json_depth(cx, json, len);
    scan_buffers(cx, json, len);
}

bool is_data_uri(const std::string& uri)
{
    return uri.compare(0, 5, "data:") == 0;
}

// As tinygltf decodes a buffer's uri into a file name.
std::string url_decode(const std::string& s)
{
    auto hex = [](char c) {
        return c >= '0' && c <= '9' ? c - '0' : c >= 'a' && c <= 'f' ? c - 'a' + 10 : c >= 'A' && c <= 'F' ? c - 'A' + 10 : 0;
    };
    std::string r;
    for (size_t i = 0; i < s.size(); ++i) {
        if (s[i] == '+')
            r += ' ';
        else if (s[i] == '%' && i + 2 < s.size()) {
            r += (char)(hex(s[i + 1]) << 4 | hex(s[i + 2]));
            i += 2;
        } else
            r += s[i];
    }
    return r;
}

// The external buffer whose uri names the file at `path`, or -1 (an image).
int buffer_of_path(const LoadContext& cx, const std::string& path)
{
    for (size_t i = 0; i < cx.buffers.size(); ++i) {
        const BufferDecl& b = cx.buffers[i];
        if (!b.has_uri || is_data_uri(b.uri)) continue;
        std::string name = url_decode(b.uri);
        if (path == name || (path.size() > name.size() && path.compare(path.size() - name.size(), name.size(), name) == 0 &&
                             path[path.size() - name.size() - 1] == '/'))
            return (int)i;
    }
    return -1;
}

// tinygltf looks for a file next to the glTF, then in the working directory,
// and of a missing one says only "File not found". A buffer's file is said to
// exist beside the glTF, so that read_buffer_file tries exactly that one (a
// relative uri is relative to the glTF, not to where we run) and says which
// buffer is missing. Otherwise stat, not tinygltf::FileExists: that opens
// the file, and opening a FIFO (an image's uri) waits for a writer forever;
// read_buffer_file then refuses what is not a regular file.
bool buffer_file_exists(const std::string& path, void* user)
{
    const LoadContext& cx = *static_cast<const LoadContext*>(user);
    struct stat st;
    return buffer_of_path(cx, path) >= 0 || stat(path.c_str(), &st) == 0;
}

// A uri with a scheme ("http:", "file:") or an absolute path: tinygltf would
// join it to the glTF's folder ("g//dev/zero") and then find nothing there.
bool is_absolute_uri(const std::string& uri)
{
    if (!uri.empty() && uri[0] == '/') return true;
    size_t i = 0;
    while (i < uri.size() && (isalnum((unsigned char)uri[i]) || uri[i] == '+' || uri[i] == '-' || uri[i] == '.'))
        ++i;
    return i > 1 && i < uri.size() && uri[i] == ':' && isalpha((unsigned char)uri[0]);
}

// tinygltf's own reader sizes its vector by seeking to the end, which for a
// directory gives 2^63 - 1 and an attempt to allocate that. Ours reads only a
// regular file, and only as many bytes as the buffer that names it declares.
// An image's file is looked at but never read: skip_image ignores its bytes,
// so reading a texture of many megabytes (or one outside the glTF's folder)
// would only cost time and memory.
bool read_buffer_file(std::vector<unsigned char>* out, std::string* err, const std::string& path, void* user)
{
    LoadContext& cx = *static_cast<LoadContext*>(user);
    int index = buffer_of_path(cx, path);
    char who[64] = "";
    if (index >= 0) snprintf(who, sizeof who, "buffer %d: ", index);
    char msg[1024] = "";
    struct stat st;
    FILE* f = nullptr;
    int stat_errno = stat(path.c_str(), &st) != 0 ? errno : 0;
    if (index >= 0 && is_absolute_uri(url_decode(cx.buffers[(size_t)index].uri)))
        snprintf(msg, sizeof msg,
                 "%s: buffer %d (uri '%s'): not a path relative to the glTF (only those and data: URIs are read)", cx.what, index,
                 cx.buffers[(size_t)index].uri.c_str());
    else if (index >= 0 && (stat_errno == ENOENT || stat_errno == ENOTDIR))
        snprintf(msg, sizeof msg, "%s: buffer %d (uri '%s'): file not found (%s)", cx.what, index,
                 cx.buffers[(size_t)index].uri.c_str(), path.c_str());
    else if (stat_errno)
        snprintf(msg, sizeof msg, "%s: %s%s: %s", cx.what, who, path.c_str(), strerror(stat_errno));
    else if (S_ISDIR(st.st_mode))
        snprintf(msg, sizeof msg, "%s: %s%s is a directory, not a buffer file", cx.what, who, path.c_str());
    else if (!S_ISREG(st.st_mode))
        snprintf(msg, sizeof msg, "%s: %s%s is not a regular file", cx.what, who, path.c_str());
    else if (index >= 0 && (double)st.st_size != cx.buffers[(size_t)index].byte_length)
        snprintf(msg, sizeof msg, "%s: %s%s has %lld bytes, but the buffer's byteLength is %.17g", cx.what, who, path.c_str(),
                 (long long)st.st_size, cx.buffers[(size_t)index].byte_length);
    else if (index < 0) {
        out->assign(st.st_size > 0 ? 1 : 0, 0); // tinygltf warns of an empty file
        return true;
    } else if (st.st_size > 0x7fffffff)
        snprintf(msg, sizeof msg, "%s: %s%s is over 2 GiB (not supported)", cx.what, who, path.c_str());
    else if (!(f = fopen(path.c_str(), "rb")))
        snprintf(msg, sizeof msg, "%s: %s%s: %s", cx.what, who, path.c_str(), strerror(errno));
    if (!f) {
        // Only a buffer's: an image's is a warning, which must not become the
        // reason of a load that fails on something else.
        if (index >= 0 && cx.message.empty()) cx.message = msg;
        if (err) *err += msg;
        return false;
    }
    out->resize((size_t)st.st_size);
    size_t got = out->empty() ? 0 : fread(out->data(), 1, out->size(), f);
    fclose(f);
    if (got != out->size()) {
        snprintf(msg, sizeof msg, "%s: %s%s: read error", cx.what, who, path.c_str());
        if (cx.message.empty()) cx.message = msg;
        if (err) *err += msg;
        return false;
    }
    return true;
}

// Decoded size of a base64 data URI's payload, or -1 when it is not base64.
long long data_uri_bytes(const std::string& uri)
{
    size_t comma = uri.find(',');
    if (comma == std::string::npos || uri.rfind(";base64", comma) == std::string::npos) return -1;
    size_t n = 0, pad = 0;
    for (size_t i = comma + 1; i < uri.size(); ++i) {
        char c = uri[i];
        if (c == '=' && i + 2 >= uri.size())
            ++pad;
        else if (isalnum((unsigned char)c) || c == '+' || c == '/')
            ++n;
        else
            return -1;
    }
    if ((n + pad) % 4) return -1;
    return (long long)((n + pad) / 4 * 3 - pad);
}

// A data URI's payload can be megabytes of base64: a message keeps its
// media type only.
std::string without_data_payloads(std::string line)
{
    for (size_t at = line.find("data:"); at != std::string::npos; at = line.find("data:", at + 5)) {
        size_t comma = line.find(',', at);
        if (comma == std::string::npos) break;
        size_t end = comma + 1;
        while (end < line.size() && line[end] != ' ' && line[end] != '\'' && line[end] != '"')
            ++end;
        if (end - comma > 4) line.replace(comma + 1, end - comma - 1, "...");
    }
    return line;
}

// tinygltf's first error line, said as we say things: which buffer and why.
std::string explain(LoadContext& cx, const unsigned char* data, size_t size, const std::string& line)
{
    char msg[512];
    // nlohmann's own words ("[json.exception.parse_error.101] parse error at
    // line 1, column 92: ...") said as ours: what is wrong, and where.
    const char* json_head = "[json.exception.parse_error.";
    size_t at = line.find("] parse error at ");
    if (line.compare(0, strlen(json_head), json_head) == 0 && at != std::string::npos)
        return "not valid JSON at " + line.substr(at + strlen("] parse error at "));
    if (line.find("'uri' is missing from non binary glTF file buffer") != std::string::npos) {
        if (!cx.scanned) scan_buffers_of(cx, data, size);
        for (size_t i = 0; i < cx.buffers.size(); ++i)
            if (!cx.buffers[i].has_uri) {
                snprintf(msg, sizeof msg, "buffer %zu has no uri (only a .glb's own buffer may leave it out)", i);
                return msg;
            }
    }
    const char* head = "Failed to decode 'uri' : ";
    if (line.compare(0, strlen(head), head) == 0) {
        if (!cx.scanned) scan_buffers_of(cx, data, size);
        for (size_t i = 0; i < cx.buffers.size(); ++i) {
            const BufferDecl& b = cx.buffers[i];
            if (!b.has_uri || !is_data_uri(b.uri) || line.compare(strlen(head), b.uri.size(), b.uri) != 0) continue;
            long long n = data_uri_bytes(b.uri);
            if (n < 0)
                snprintf(msg, sizeof msg, "buffer %zu: its data URI is not valid base64", i);
            else
                snprintf(msg, sizeof msg, "buffer %zu: its data URI holds %lld bytes, but its byteLength is %.17g", i, n,
                         b.byte_length);
            return msg;
        }
    }
    return without_data_payloads(line);
}

// An extension the file requires changes what its data mean: the geometry
// compressed (Draco, meshopt), quantized, or instanced. Read without it, the
// bytes become garbage or a message about accessors that names nothing the
// curator can act on, so one we do not read is refused by name. Those that
// touch only images and materials are safe to leave aside: we never decode
// images, and a part's colour comes from baseColorFactor.
void check_required_extensions(const LoadContext& cx, const char* what)
{
    static const char* const ignorable_prefixes[] = {"KHR_materials_", "KHR_texture_", "EXT_texture_", "KHR_lights_", "KHR_xmp"};
    for (const std::string& ext : cx.required) {
        bool ok = false;
        for (const char* pre : ignorable_prefixes)
            ok = ok || ext.compare(0, strlen(pre), pre) == 0;
        if (ok) continue;
        const char* hint = ext == "KHR_draco_mesh_compression" || ext == "EXT_meshopt_compression"
                               ? ": export it without mesh compression"
                           : ext == "KHR_mesh_quantization" ? ": dequantize it first (e.g. gltf-transform dequantize)"
                                                            : "";
        fail(SP_ERR_UNSUPPORTED, "%s: requires the glTF extension %.64s, which sketchpose does not read%s", what, ext.c_str(),
             hint);
    }
}

void parse_model(tinygltf::Model& model, const unsigned char* data, size_t size, const char* what, const std::string& base_dir,
                 bool use_fs, sp_character* ch)
{
    if (size > 0x7fffffffu) fail(SP_ERR_UNSUPPORTED, "%s: files over 2 GiB are not supported", what);
    tinygltf::TinyGLTF loader;
    loader.SetImageLoader(skip_image, nullptr);
    loader.SetStoreOriginalJSONForExtrasAndExtensions(true);
    LoadContext cx;
    cx.what = what;
    if (use_fs)
        loader.SetFsCallbacks(
            tinygltf::FsCallbacks{buffer_file_exists, tinygltf::ExpandFilePath, read_buffer_file, tinygltf::WriteWholeFile, &cx});
    else
        loader.SetFsCallbacks(tinygltf::FsCallbacks{no_file_exists, no_expand, no_read, no_write, nullptr});
    std::string terr, twarn;
    bool ok;
    if (size >= 4 && !memcmp(data, "glTF", 4)) {
        size_t total = check_glb(data, size, what);
        scan_buffers_of(cx, data, total);
        check_required_extensions(cx, what);
        ok = loader.LoadBinaryFromMemory(&model, &terr, &twarn, data, (unsigned)total, base_dir);
    } else {
        size_t i = 0;
        while (i < size && (data[i] == ' ' || data[i] == '\n' || data[i] == '\r' || data[i] == '\t'))
            ++i;
        if (i == size) fail(SP_ERR_PARSE, "%s: empty file", what);
        if (data[i] != '{') {
            if (size - i >= 3 && !memcmp(data + i, "\xEF\xBB\xBF", 3))
                fail(SP_ERR_PARSE, "%s: starts with a UTF-8 byte-order mark, which glTF JSON must not have (save it without one)",
                     what);
            if (strchr("[\"-0123456789tfn", data[i]))
                fail(SP_ERR_PARSE, "%s: the top level is not a JSON object (glTF JSON is one)", what);
            fail(SP_ERR_PARSE, "%s: neither glTF JSON nor a .glb", what);
        }
        scan_buffers_of(cx, data, size);
        check_required_extensions(cx, what);
        ok = loader.LoadASCIIFromString(&model, &terr, &twarn, reinterpret_cast<const char*>(data), (unsigned)size, base_dir);
    }
    if (!ok) {
        if (!cx.message.empty()) fail(SP_ERR_IO, "%s", cx.message.c_str());
        std::string line = first_line(terr);
        if (line.empty()) line = first_line(twarn);
        if (line.empty()) line = "not a valid glTF 2.0 file";
        sp_result code = SP_ERR_PARSE;
        if (line.find("File not found") != std::string::npos || line.find("Failed to load") != std::string::npos ||
            line.find("cannot be resolved") != std::string::npos)
            code = SP_ERR_IO;
        fail(code, "%s: %s", what, explain(cx, data, size, line).c_str());
    }
    // glTF 2.0 says a loader refuses an asset of another major version: its
    // meaning may differ in ways no warning could name (one of "3.0" loaded silently).
    const std::string& ver = model.asset.version;
    if (ver.compare(0, 2, "2.") != 0)
        fail(SP_ERR_UNSUPPORTED, "%s: glTF version '%.16s': sketchpose reads glTF 2.x", what, ver.c_str());
    if (!twarn.empty()) sp_character_warn(ch, "glTF: %s", without_data_payloads(first_line(twarn)).c_str());
    // glTF forbids both, and viewers differ in which they use: ours is said.
    for (int n : cx.matrix_and_trs) {
        const std::string& name = (size_t)n < model.nodes.size() ? model.nodes[(size_t)n].name : std::string();
        sp_character_warn(ch, "node %d%s%.64s%s has both a matrix and translation/rotation/scale: the matrix is used", n,
                          name.empty() ? "" : " '", name.c_str(), name.empty() ? "" : "'");
    }
}

// ---- accessors ------------------------------------------------------------

struct View {
    const unsigned char* base = nullptr;
    size_t stride = 0, count = 0;
    int comp = 0, ncomp = 0;
    bool normalized = false;
    int index = -1;
    std::shared_ptr<std::vector<unsigned char>> own; // a sparse accessor's elements, made dense
};

// The bytes [offset, offset + size) of buffer view `bv_index`, checked.
const unsigned char* view_bytes(const tinygltf::Model& m, int bv_index, size_t offset, size_t size, const char* what,
                                const char* usage)
{
    if (bv_index < 0 || (size_t)bv_index >= m.bufferViews.size())
        fail(SP_ERR_INVALID, "%s: %s refers to buffer view %d, but there are %zu", what, usage, bv_index, m.bufferViews.size());
    const tinygltf::BufferView& bv = m.bufferViews[(size_t)bv_index];
    if (bv.buffer < 0 || (size_t)bv.buffer >= m.buffers.size())
        fail(SP_ERR_INVALID, "%s: buffer view %d refers to buffer %d, but there are %zu", what, bv_index, bv.buffer,
             m.buffers.size());
    const std::vector<unsigned char>& buf = m.buffers[(size_t)bv.buffer].data;
    if (bv.byteOffset > buf.size() || bv.byteLength > buf.size() - bv.byteOffset)
        fail(SP_ERR_INVALID, "%s: buffer view %d reads past the end of buffer %d", what, bv_index, bv.buffer);
    if (offset > bv.byteLength || size > bv.byteLength - offset)
        fail(SP_ERR_INVALID, "%s: %s reads past the end of buffer view %d", what, usage, bv_index);
    return buf.data() + bv.byteOffset + offset;
}

// Bytes of one element of accessor `index` (*ncomp its components), checked,
// as is its count.
size_t element_bytes(const tinygltf::Accessor& a, int index, const char* what, int* ncomp)
{
    int csize = tinygltf::GetComponentSizeInBytes((uint32_t)a.componentType);
    *ncomp = tinygltf::GetNumComponentsInType((uint32_t)a.type);
    if (csize <= 0 || *ncomp <= 0) fail(SP_ERR_INVALID, "%s: accessor %d has an invalid type or component type", what, index);
    if (a.count > (1u << 28)) fail(SP_ERR_UNSUPPORTED, "%s: accessor %d has %zu elements (too many)", what, index, a.count);
    return (size_t)csize * (size_t)*ncomp;
}

View make_view(const tinygltf::Accessor& a, int index, const unsigned char* base, size_t stride, int ncomp)
{
    View v;
    v.base = base;
    v.stride = stride;
    v.count = a.count;
    v.comp = a.componentType;
    v.ncomp = ncomp;
    v.normalized = a.normalized;
    v.index = index;
    return v;
}

// Accessor `index` read in place from its buffer view, every bound checked.
View plain_view(const tinygltf::Model& m, int index, const char* what)
{
    const tinygltf::Accessor& a = m.accessors[(size_t)index];
    char usage[32];
    snprintf(usage, sizeof usage, "accessor %d", index);
    const unsigned char* start = view_bytes(m, a.bufferView, 0, 0, what, usage); // the view and its buffer
    int ncomp;
    size_t elem = element_bytes(a, index, what, &ncomp);
    const tinygltf::BufferView& bv = m.bufferViews[(size_t)a.bufferView];
    size_t stride = bv.byteStride ? bv.byteStride : elem;
    if (stride < elem) fail(SP_ERR_INVALID, "%s: accessor %d: byteStride %zu is smaller than an element", what, index, stride);
    if (a.count > 0) view_bytes(m, a.bufferView, a.byteOffset, stride * (a.count - 1) + elem, what, usage);
    return make_view(a, index, start + a.byteOffset, stride, ncomp);
}

// glTF's sparse accessors (and those without a buffer view, all zeros):
// the base elements, then the listed ones replaced, copied into one dense
// array the View owns.
View dense_view(const tinygltf::Model& m, int index, const char* what)
{
    const tinygltf::Accessor& a = m.accessors[(size_t)index];
    int ncomp;
    size_t elem = element_bytes(a, index, what, &ncomp);
    if (a.bufferView < 0) {
        // Zeros cost the file nothing: a 3 KB file claiming 2^28 of them
        // had gigabytes made before its counts were compared. No more than
        // the file's buffers hold (or 16 MiB) is a mesh's worth.
        size_t held = 0;
        for (const tinygltf::Buffer& b : m.buffers)
            held += b.data.size();
        if (a.count * elem > std::max(held, (size_t)1 << 24))
            fail(SP_ERR_INVALID,
                 "%s: accessor %d claims %zu elements without a buffer view (%zu bytes of zeros; the buffers hold %zu)", what,
                 index, a.count, a.count * elem, held);
    }
    auto own = std::make_shared<std::vector<unsigned char>>(a.count * elem + 1, 0);
    unsigned char* out = own->data();
    if (a.bufferView >= 0) {
        View base = plain_view(m, index, what);
        for (size_t i = 0; i < a.count; ++i)
            memcpy(out + i * elem, base.base + i * base.stride, elem);
    }
    if (a.sparse.isSparse) {
        const auto& sp = a.sparse;
        if (sp.count < 1 || (size_t)sp.count > a.count)
            fail(SP_ERR_INVALID, "%s: accessor %d: sparse count %d is not 1..%zu", what, index, sp.count, a.count);
        int isize = tinygltf::GetComponentSizeInBytes((uint32_t)sp.indices.componentType);
        if (sp.indices.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
            sp.indices.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
            sp.indices.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
            fail(SP_ERR_INVALID, "%s: accessor %d: sparse indices must be unsigned bytes, shorts or ints", what, index);
        char usage[64];
        snprintf(usage, sizeof usage, "accessor %d's sparse indices", index);
        const unsigned char* idx =
            view_bytes(m, sp.indices.bufferView, (size_t)sp.indices.byteOffset, (size_t)sp.count * (size_t)isize, what, usage);
        snprintf(usage, sizeof usage, "accessor %d's sparse values", index);
        const unsigned char* val =
            view_bytes(m, sp.values.bufferView, (size_t)sp.values.byteOffset, (size_t)sp.count * elem, what, usage);
        for (int k = 0; k < sp.count; ++k) {
            uint32_t at = 0;
            if (isize == 1) {
                at = idx[k];
            } else if (isize == 2) {
                uint16_t u;
                memcpy(&u, idx + 2 * (size_t)k, 2);
                at = u;
            } else {
                memcpy(&at, idx + 4 * (size_t)k, 4);
            }
            if (at >= a.count)
                fail(SP_ERR_INVALID, "%s: accessor %d: sparse index %u is past its %zu elements", what, index, at, a.count);
            memcpy(out + (size_t)at * elem, val + (size_t)k * elem, elem);
        }
    }
    View v = make_view(a, index, out, elem, ncomp);
    v.own = own;
    return v;
}

View view_accessor(const tinygltf::Model& m, int index, const char* what, const char* usage)
{
    if (index < 0 || (size_t)index >= m.accessors.size())
        fail(SP_ERR_INVALID, "%s: %s refers to accessor %d, but there are %zu", what, usage, index, m.accessors.size());
    const tinygltf::Accessor& a = m.accessors[(size_t)index];
    return a.sparse.isSparse || a.bufferView < 0 ? dense_view(m, index, what) : plain_view(m, index, what);
}

// One component as a double; normalized integers map to [0, 1] / [-1, 1].
double read_comp(const View& v, size_t i, int c)
{
    const unsigned char* p = v.base + i * v.stride;
    switch (v.comp) {
    case TINYGLTF_COMPONENT_TYPE_FLOAT: {
        float f;
        memcpy(&f, p + 4 * c, 4);
        return f;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
        return v.normalized ? p[c] / 255.0 : p[c];
    case TINYGLTF_COMPONENT_TYPE_BYTE: {
        double x = (int8_t)p[c];
        return v.normalized ? std::max(x / 127.0, -1.0) : x;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
        uint16_t s;
        memcpy(&s, p + 2 * c, 2);
        return v.normalized ? s / 65535.0 : s;
    }
    case TINYGLTF_COMPONENT_TYPE_SHORT: {
        int16_t s;
        memcpy(&s, p + 2 * c, 2);
        return v.normalized ? std::max(s / 32767.0, -1.0) : s;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
        uint32_t u;
        memcpy(&u, p + 4 * c, 4);
        return u;
    }
    default:
        return 0.0;
    }
}

void expect(const View& v, int type_ncomp, std::initializer_list<int> comps, bool need_normalized_ints, const char* what,
            const char* usage)
{
    bool comp_ok = std::find(comps.begin(), comps.end(), v.comp) != comps.end();
    if (v.ncomp != type_ncomp || !comp_ok)
        fail(SP_ERR_INVALID, "%s: %s (accessor %d) has the wrong type or component type", what, usage, v.index);
    if (need_normalized_ints && v.comp != TINYGLTF_COMPONENT_TYPE_FLOAT && !v.normalized)
        fail(SP_ERR_INVALID, "%s: %s (accessor %d) must be float or normalized integers", what, usage, v.index);
    // Why: read as fractions, joint numbers and indices would all become 0.
    if (!need_normalized_ints && v.comp != TINYGLTF_COMPONENT_TYPE_FLOAT && v.normalized)
        fail(SP_ERR_INVALID, "%s: %s (accessor %d) holds integers and must not be normalized", what, usage, v.index);
}

// ---- node graph -----------------------------------------------------------

struct Trs {
    sp_vec3 t{0, 0, 0};
    sp_quat r{0, 0, 0, 1};
    sp_vec3 s{1, 1, 1};
};

Trs decompose(const sp_mat4& a)
{
    Trs r;
    sp_gltf_decompose(&a, &r.t, &r.r, &r.s);
    return r;
}

Trs node_trs(const tinygltf::Node& n, int index, const char* what)
{
    Trs r;
    if (n.matrix.size() == 16) {
        sp_mat4 a;
        for (int k = 0; k < 16; ++k) {
            a.m[k] = n.matrix[(size_t)k];
            if (!(std::fabs(a.m[k]) < 1e30)) fail(SP_ERR_INVALID, "%s: node %d has a non-finite or huge matrix", what, index);
        }
        return decompose(a);
    }
    if (!n.matrix.empty()) fail(SP_ERR_INVALID, "%s: node %d: matrix must have 16 numbers", what, index);
    if (!n.translation.empty() && n.translation.size() != 3)
        fail(SP_ERR_INVALID, "%s: node %d: translation must have 3 numbers", what, index);
    if (!n.rotation.empty() && n.rotation.size() != 4)
        fail(SP_ERR_INVALID, "%s: node %d: rotation must have 4 numbers", what, index);
    if (!n.scale.empty() && n.scale.size() != 3) fail(SP_ERR_INVALID, "%s: node %d: scale must have 3 numbers", what, index);
    if (n.translation.size() == 3) r.t = sp_v3(n.translation[0], n.translation[1], n.translation[2]);
    if (n.rotation.size() == 4) r.r = sp_quat{n.rotation[0], n.rotation[1], n.rotation[2], n.rotation[3]};
    if (n.scale.size() == 3) r.s = sp_v3(n.scale[0], n.scale[1], n.scale[2]);
    // Why: everything else in glTF is float32, and our export writes floats.
    const double big = 1e30;
    double all[10] = {r.t.x, r.t.y, r.t.z, r.r.x, r.r.y, r.r.z, r.r.w, r.s.x, r.s.y, r.s.z};
    for (double x : all)
        if (!(std::fabs(x) < big)) fail(SP_ERR_INVALID, "%s: node %d has a non-finite or huge transform", what, index);
    return r;
}

sp_mat4 node_local(const tinygltf::Node& n, int index, const char* what)
{
    if (n.matrix.size() == 16) {
        sp_mat4 a;
        for (int k = 0; k < 16; ++k)
            a.m[k] = n.matrix[(size_t)k];
        return a;
    }
    Trs t = node_trs(n, index, what);
    return sp_mat4_trs(t.t, sp_quat_norm(t.r), t.s);
}

std::string joint_name(const tinygltf::Node& n, int index, const std::vector<std::string>& used)
{
    std::string base = n.name.empty() ? "node" + std::to_string(index) : n.name;
    if (base.size() >= SP_NAME_MAX) base.resize(SP_NAME_MAX - 1);
    std::string name = base;
    if (std::find(used.begin(), used.end(), name) != used.end()) {
        std::string suffix = "_" + std::to_string(index);
        name = base.substr(0, std::min(base.size(), (size_t)SP_NAME_MAX - 1 - suffix.size())) + suffix;
    }
    return name;
}

template <class T> T* c_array(const std::vector<T>& v)
{
    T* p = static_cast<T*>(malloc(sizeof(T) * (v.size() ? v.size() : 1)));
    if (!p) throw std::bad_alloc();
    if (!v.empty()) memcpy(p, v.data(), sizeof(T) * v.size());
    return p;
}

struct Skinned {
    std::vector<double> rest;
    std::vector<uint16_t> joints;
    std::vector<float> weights;
};

// Reads POSITION/JOINTS_0/WEIGHTS_0 of one primitive, joints remapped to the rig.
void read_skinned(const tinygltf::Model& m, const tinygltf::Primitive& prim, int mesh, int pi, const std::vector<int>& skin_map,
                  int skin, const char* what, Skinned& out)
{
    char usage[96];
    auto attr = [&](const char* name) {
        auto it = prim.attributes.find(name);
        return it == prim.attributes.end() ? -1 : it->second;
    };
    int ipos = attr("POSITION"), ijnt = attr("JOINTS_0"), iwgt = attr("WEIGHTS_0");
    if (ipos < 0) fail(SP_ERR_INVALID, "%s: mesh %d primitive %d has no POSITION", what, mesh, pi);
    if (ijnt < 0 || iwgt < 0)
        fail(SP_ERR_INVALID, "%s: mesh %d primitive %d has no JOINTS_0/WEIGHTS_0 (not skinned)", what, mesh, pi);
    snprintf(usage, sizeof usage, "mesh %d primitive %d POSITION", mesh, pi);
    View pos = view_accessor(m, ipos, what, usage);
    expect(pos, 3, {TINYGLTF_COMPONENT_TYPE_FLOAT}, false, what, usage);
    snprintf(usage, sizeof usage, "mesh %d primitive %d JOINTS_0", mesh, pi);
    View jnt = view_accessor(m, ijnt, what, usage);
    expect(jnt, 4, {TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT}, false, what, usage);
    snprintf(usage, sizeof usage, "mesh %d primitive %d WEIGHTS_0", mesh, pi);
    View wgt = view_accessor(m, iwgt, what, usage);
    expect(wgt, 4, {TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT},
           true, what, usage);
    if (jnt.count != pos.count || wgt.count != pos.count)
        fail(SP_ERR_INVALID, "%s: mesh %d primitive %d: POSITION, JOINTS_0 and WEIGHTS_0 have different counts", what, mesh, pi);
    size_t n = pos.count;
    out.rest.resize(3 * n);
    out.joints.resize(4 * n);
    out.weights.resize(4 * n);
    for (size_t i = 0; i < n; ++i) {
        for (int c = 0; c < 3; ++c) {
            double x = read_comp(pos, i, c);
            if (!std::isfinite(x))
                fail(SP_ERR_INVALID, "%s: mesh %d primitive %d: vertex %zu has a non-finite POSITION", what, mesh, pi, i);
            out.rest[3 * i + (size_t)c] = x;
        }
        double w[4];
        unsigned j[4];
        for (int c = 0; c < 4; ++c) {
            w[c] = read_comp(wgt, i, c);
            j[c] = (unsigned)read_comp(jnt, i, c);
            if (!std::isfinite(w[c]) || w[c] < 0)
                fail(SP_ERR_INVALID, "%s: mesh %d primitive %d: vertex %zu has an invalid weight", what, mesh, pi, i);
            if (j[c] >= skin_map.size()) {
                if (w[c] > 0)
                    fail(SP_ERR_INVALID, "%s: mesh %d primitive %d: vertex %zu uses joint %u, but skin %d has %zu joints", what,
                         mesh, pi, i, j[c], skin, skin_map.size());
                j[c] = 0;
            }
        }
        // Merge repeated joints (the validator rejects duplicates with weight).
        for (int a = 0; a < 4; ++a)
            for (int b = a + 1; b < 4; ++b)
                if (j[a] == j[b] && w[b] > 0) w[a] += w[b], w[b] = 0;
        if (!(w[0] + w[1] + w[2] + w[3] > 0))
            fail(SP_ERR_INVALID, "%s: mesh %d primitive %d: vertex %zu has all skin weights zero%s", what, mesh, pi, i,
                 attr("WEIGHTS_1") >= 0 ? " in WEIGHTS_0 (WEIGHTS_1 is not read: at most 4 joints a vertex; re-export with 4)"
                                        : "");
        for (int c = 0; c < 4; ++c) {
            out.joints[4 * i + (size_t)c] = (uint16_t)skin_map[j[c]];
            out.weights[4 * i + (size_t)c] = (float)w[c];
        }
    }
}

std::vector<uint32_t> read_indices(const tinygltf::Model& m, const tinygltf::Primitive& prim, int mesh, int pi, size_t nverts,
                                   const char* what)
{
    std::vector<uint32_t> idx;
    if (prim.indices < 0) {
        idx.resize(nverts);
        for (size_t i = 0; i < nverts; ++i)
            idx[i] = (uint32_t)i;
        return idx;
    }
    char usage[64];
    snprintf(usage, sizeof usage, "mesh %d primitive %d indices", mesh, pi);
    View v = view_accessor(m, prim.indices, what, usage);
    expect(v, 1,
           {TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT, TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT},
           false, what, usage);
    idx.resize(v.count);
    for (size_t i = 0; i < v.count; ++i) {
        double x = read_comp(v, i, 0);
        if (x >= (double)nverts)
            fail(SP_ERR_INVALID, "%s: mesh %d primitive %d: index %.0f is out of range (%zu vertices)", what, mesh, pi, x,
                 nverts);
        idx[i] = (uint32_t)x;
    }
    return idx;
}

// Base colour of a primitive's material (linear RGBA); true when the
// material has a base colour texture (never read: grey).
bool material_color(const tinygltf::Model& m, int material, const char* what, float rgba[4])
{
    rgba[0] = rgba[1] = rgba[2] = rgba[3] = 1.0f;
    if (material < 0) return false;
    if ((size_t)material >= m.materials.size())
        fail(SP_ERR_INVALID, "%s: a primitive refers to material %d, but there are %zu", what, material, m.materials.size());
    const tinygltf::PbrMetallicRoughness& pbr = m.materials[(size_t)material].pbrMetallicRoughness;
    if (pbr.baseColorFactor.size() == 4)
        for (int c = 0; c < 4; ++c) {
            double x = pbr.baseColorFactor[(size_t)c];
            rgba[c] = std::isfinite(x) ? (float)std::min(1.0, std::max(0.0, x)) : 1.0f;
        }
    if (pbr.baseColorTexture.index < 0) return false;
    for (int c = 0; c < 3; ++c)
        rgba[c] *= SP_GLTF_TEXTURE_GREY;
    return true;
}

// glTF requires an inverse bind matrix to be finite with a fourth row of
// [0, 0, 0, 1]; one that is not (e.g. all zeros) would throw the joint's
// vertices to the origin or to NaN, so it is refused. Within 1e-5 of that row
// is exporter rounding, made exact. A singular matrix is legal but flattens
// every vertex the joint moves: a warning.
void check_inverse_bind(sp_mat4& a, int skin, size_t k, const tinygltf::Model& m, const char* what, sp_character* ch)
{
    int node = m.skins[(size_t)skin].joints[k];
    const std::string& name = m.nodes[(size_t)node].name;
    char who[160];
    snprintf(who, sizeof who, "skin %d joint %zu (node %d%s%.64s%s)", skin, k, node, name.empty() ? "" : " '", name.c_str(),
             name.empty() ? "" : "'");
    for (int c = 0; c < 16; ++c)
        if (!std::isfinite(a.m[c])) fail(SP_ERR_INVALID, "%s: %s: its inverse bind matrix has a non-finite element", what, who);
    const double tol = 1e-5;
    if (!(std::fabs(a.m[3]) <= tol && std::fabs(a.m[7]) <= tol && std::fabs(a.m[11]) <= tol && std::fabs(a.m[15] - 1) <= tol))
        fail(SP_ERR_INVALID, "%s: %s: its inverse bind matrix has the fourth row [%g, %g, %g, %g], not [0, 0, 0, 1]", what, who,
             a.m[3], a.m[7], a.m[11], a.m[15]);
    a.m[3] = a.m[7] = a.m[11] = 0, a.m[15] = 1;
    // The test the stick figure and the deriver skip such a joint by, so that
    // the warning and what they leave out agree (a scale of 1e-8 along one
    // axis flattens as surely as a zero column); relative, so that a file's
    // unit does not matter.
    sp_mat4 inv;
    if (!sp_mat4_inverse_rel(&a, SP_MAT4_FLAT, &inv))
        sp_character_warn(ch, "%s: its inverse bind matrix is singular: the vertices it moves are flattened", who);
}

struct Importer {
    const tinygltf::Model& m;
    const char* what;
    sp_character* ch;
    std::vector<int> parent;                   // node -> parent node
    std::vector<int> order;                    // reachable nodes, depth first
    std::vector<int> node2joint;               // node -> rig joint or -1
    std::map<int, std::vector<int>> skin_maps; // skin -> (skin joint -> rig joint)
    bool warned_influences = false;

    // We skin with 4 joints a vertex: a second set is dropped, and only a
    // word here says so (renormalising the first set's weights hides it).
    void warn_extra_influences(const tinygltf::Primitive& prim, int mesh, int pi)
    {
        if (warned_influences || (!prim.attributes.count("JOINTS_1") && !prim.attributes.count("WEIGHTS_1"))) return;
        sp_character_warn(ch, "mesh %d primitive %d: JOINTS_1/WEIGHTS_1 ignored (at most 4 joints a vertex)", mesh, pi);
        warned_influences = true;
    }

    // Morph targets are not read: the base shape is the part's. Said, since
    // default weights (the node's, else the mesh's) other than 0 give a
    // shape in viewers that the part will not have.
    std::vector<bool> warned_morph_mesh{};
    void warn_morph_targets(const tinygltf::Mesh& mesh, const tinygltf::Node& nd)
    {
        bool has = false;
        for (const tinygltf::Primitive& prim : mesh.primitives)
            has = has || !prim.targets.empty();
        warned_morph_mesh.resize(m.meshes.size());
        if (!has || warned_morph_mesh[(size_t)nd.mesh]) return;
        warned_morph_mesh[(size_t)nd.mesh] = true;
        const std::vector<double>& w = nd.weights.empty() ? mesh.weights : nd.weights;
        bool weighted = false;
        for (double x : w)
            weighted = weighted || x != 0;
        sp_character_warn(ch, "mesh %d: morph targets ignored%s", nd.mesh,
                          weighted ? ": its default weights are not applied (the shape without them is used; bake them first)"
                                   : " (the shape without them is used)");
    }

    void check_graph()
    {
        size_t N = m.nodes.size();
        parent.assign(N, -1);
        for (size_t n = 0; n < N; ++n)
            for (int c : m.nodes[n].children) {
                if (c < 0 || (size_t)c >= N)
                    fail(SP_ERR_INVALID, "%s: node %zu has child %d, but there are %zu nodes", what, n, c, N);
                if ((size_t)c == n || parent[(size_t)c] >= 0)
                    fail(SP_ERR_INVALID,
                         "%s: node %d has more than one parent or is its own child (the node graph must be a forest)", what, c);
                parent[(size_t)c] = (int)n;
            }
        // Every node has at most one parent; a cycle is then a parent chain longer than N.
        for (size_t n = 0; n < N; ++n) {
            size_t steps = 0;
            for (int p = parent[n]; p >= 0; p = parent[(size_t)p])
                if (++steps > N) fail(SP_ERR_INVALID, "%s: the node graph has a cycle through node %zu", what, n);
        }
    }

    // Depth-first order of the scene's nodes (children in file order).
    void walk_scene(std::vector<int>& roots)
    {
        std::vector<char> seen(m.nodes.size(), 0);
        std::vector<int> stack;
        for (int r : roots) {
            if (r < 0 || (size_t)r >= m.nodes.size())
                fail(SP_ERR_INVALID, "%s: the scene refers to node %d, but there are %zu", what, r, m.nodes.size());
            stack.push_back(r);
            while (!stack.empty()) {
                int n = stack.back();
                stack.pop_back();
                if (seen[(size_t)n]) continue;
                seen[(size_t)n] = 1;
                order.push_back(n);
                const std::vector<int>& ch2 = m.nodes[(size_t)n].children;
                for (auto it = ch2.rbegin(); it != ch2.rend(); ++it)
                    stack.push_back(*it);
            }
        }
    }

    sp_curve_tag tag_of(const std::string& json)
    {
        sp_curve_tag tag;
        sp_error e = {};
        if (sp_gltf_curve_extras(json.empty() ? nullptr : json.c_str(), &tag, what, &e) != SP_OK)
            fail(SP_ERR_INVALID, "%s", e.text);
        return tag;
    }

    const std::vector<int>& skin_map(int skin)
    {
        auto it = skin_maps.find(skin);
        if (it != skin_maps.end()) return it->second;
        std::vector<int> map;
        for (int jn : m.skins[(size_t)skin].joints) {
            int j = (jn >= 0 && (size_t)jn < node2joint.size()) ? node2joint[(size_t)jn] : -1;
            if (j < 0)
                fail(SP_ERR_UNSUPPORTED, "%s: skin %d uses node %d, which is not a joint of the character's skeleton", what, skin,
                     jn);
            map.push_back(j);
        }
        return skin_maps[skin] = map;
    }

    void run()
    {
        sp_rig* rig = &ch->rig;
        check_graph();
        std::vector<int> roots;
        int scene = -1;
        if (!m.scenes.empty()) {
            scene = m.defaultScene >= 0 ? m.defaultScene : 0;
            if ((size_t)scene >= m.scenes.size()) fail(SP_ERR_INVALID, "%s: default scene %d does not exist", what, scene);
            roots = m.scenes[(size_t)scene].nodes;
        } else {
            for (size_t n = 0; n < m.nodes.size(); ++n)
                if (parent[n] < 0) roots.push_back((int)n);
        }
        walk_scene(roots);

        // The character's skin: the first skinned mesh node that is not a curve.
        int skin = -1;
        std::vector<int> mesh_skins;
        for (int n : order) {
            const tinygltf::Node& nd = m.nodes[(size_t)n];
            if (nd.mesh < 0 || nd.skin < 0) continue;
            if ((size_t)nd.mesh >= m.meshes.size())
                fail(SP_ERR_INVALID, "%s: node %d refers to mesh %d, but there are %zu", what, n, nd.mesh, m.meshes.size());
            if ((size_t)nd.skin >= m.skins.size())
                fail(SP_ERR_INVALID, "%s: node %d refers to skin %d, but there are %zu", what, n, nd.skin, m.skins.size());
            if (tag_of(nd.extras_json_string).is_curve) continue;
            if (skin < 0) skin = nd.skin;
            if (std::find(mesh_skins.begin(), mesh_skins.end(), nd.skin) == mesh_skins.end()) mesh_skins.push_back(nd.skin);
        }
        ch->mesh_skins = (int)mesh_skins.size();
        if (skin < 0) fail(SP_ERR_UNSUPPORTED, "%s: no skinned mesh (a node with a mesh and a skin) in the scene", what);
        const tinygltf::Skin& sk = m.skins[(size_t)skin];
        if (sk.joints.empty()) fail(SP_ERR_INVALID, "%s: skin %d has no joints", what, skin);
        size_t N = m.nodes.size();
        std::vector<int> skin_index(N, -1);
        for (size_t k = 0; k < sk.joints.size(); ++k) {
            int jn = sk.joints[k];
            if (jn < 0 || (size_t)jn >= N)
                fail(SP_ERR_INVALID, "%s: skin %d uses node %d, but there are %zu nodes", what, skin, jn, N);
            if (skin_index[(size_t)jn] >= 0) fail(SP_ERR_INVALID, "%s: skin %d lists node %d twice", what, skin, jn);
            skin_index[(size_t)jn] = (int)k;
        }
        if (sk.joints.size() > 65535) fail(SP_ERR_UNSUPPORTED, "%s: skin %d has too many joints", what, skin);
        std::vector<sp_mat4> ibm(sk.joints.size(), sp_mat4_identity());
        if (sk.inverseBindMatrices >= 0) {
            char usage[64];
            snprintf(usage, sizeof usage, "skin %d inverseBindMatrices", skin);
            View v = view_accessor(m, sk.inverseBindMatrices, what, usage);
            expect(v, 16, {TINYGLTF_COMPONENT_TYPE_FLOAT}, false, what, usage);
            if (v.count < sk.joints.size())
                fail(SP_ERR_INVALID, "%s: skin %d has fewer inverse bind matrices than joints", what, skin);
            for (size_t k = 0; k < sk.joints.size(); ++k) {
                for (int c = 0; c < 16; ++c)
                    ibm[k].m[c] = read_comp(v, k, c);
                check_inverse_bind(ibm[k], skin, k, m, what, ch);
            }
        }

        // Rig joints: skin joints and their ancestors, depth first from the
        // topmost ancestors, in the order the scene reaches them.
        std::vector<char> needed(N, 0);
        for (int jn : sk.joints)
            for (int p = jn; p >= 0 && !needed[(size_t)p]; p = parent[(size_t)p])
                needed[(size_t)p] = 1;
        auto top_of = [&](int n) {
            while (parent[(size_t)n] >= 0)
                n = parent[(size_t)n];
            return n;
        };
        std::vector<int> tops;
        for (int n : order)
            if (needed[(size_t)n] && std::find(tops.begin(), tops.end(), top_of(n)) == tops.end()) tops.push_back(top_of(n));
        size_t in_scene = tops.size();
        for (int jn : sk.joints)
            if (std::find(tops.begin(), tops.end(), top_of(jn)) == tops.end()) tops.push_back(top_of(jn));
        if (tops.size() > in_scene) sp_character_warn(ch, "part of the skeleton of skin %d is not in the scene", skin);
        node2joint.assign(N, -1);
        std::vector<int> joint_nodes, stack;
        for (int t : tops) {
            stack.push_back(t);
            while (!stack.empty()) {
                int n = stack.back();
                stack.pop_back();
                if (!needed[(size_t)n] || node2joint[(size_t)n] >= 0) continue;
                node2joint[(size_t)n] = (int)joint_nodes.size();
                joint_nodes.push_back(n);
                const std::vector<int>& kids = m.nodes[(size_t)n].children;
                for (auto it = kids.rbegin(); it != kids.rend(); ++it)
                    stack.push_back(*it);
            }
        }
        int J = (int)joint_nodes.size();
        if (J > 65535) fail(SP_ERR_UNSUPPORTED, "%s: %d joints (65535 at most)", what, J);
        rig->joints = static_cast<sp_joint*>(calloc((size_t)J, sizeof(sp_joint)));
        if (!rig->joints) throw std::bad_alloc();
        rig->joint_count = J;
        std::unique_ptr<bool[]> is_skin(new bool[(size_t)J]), has_rest(new bool[(size_t)J]);
        std::vector<sp_vec3> node_t((size_t)J), node_s((size_t)J);
        std::vector<sp_quat> node_r((size_t)J);
        std::vector<std::string> names;
        sp_import im = {};
        im.what = what;
        for (int j = 0; j < J; ++j) {
            int n = joint_nodes[(size_t)j];
            const tinygltf::Node& nd = m.nodes[(size_t)n];
            sp_joint* jt = &rig->joints[j];
            std::string name = joint_name(nd, n, names);
            names.push_back(name);
            snprintf(jt->name, sizeof jt->name, "%s", name.c_str());
            jt->parent = parent[(size_t)n] >= 0 ? node2joint[(size_t)parent[(size_t)n]] : -1;
            Trs t = node_trs(nd, n, what);
            jt->rest_t = t.t, jt->rest_r = t.r, jt->rest_s = t.s;
            node_t[(size_t)j] = t.t, node_r[(size_t)j] = t.r, node_s[(size_t)j] = t.s;
            is_skin[(size_t)j] = skin_index[(size_t)n] >= 0;
            jt->inverse_bind = is_skin[(size_t)j] ? ibm[(size_t)skin_index[(size_t)n]] : sp_mat4_identity();
            bool dofs = false, rest = false;
            sp_error e = {};
            if (sp_gltf_joint_extras(rig, j, nd.extras_json_string.empty() ? nullptr : nd.extras_json_string.c_str(), &dofs,
                                     &rest, what, &e) != SP_OK)
                fail(SP_ERR_INVALID, "%s", e.text);
            has_rest[(size_t)j] = rest;
            im.any_dofs |= dofs;
        }

        read_meshes(skin);
        read_animations();
        read_camera();

        im.is_skin = is_skin.get();
        im.has_rest = has_rest.get();
        im.node_t = node_t.data();
        im.node_r = node_r.data();
        im.node_s = node_s.data();
        std::string scene_extras = scene >= 0 ? m.scenes[(size_t)scene].extras_json_string : std::string();
        im.scene_extras = scene_extras.empty() ? nullptr : scene_extras.c_str();
        sp_error e = {};
        sp_result r = sp_gltf_finish(ch, &im, &e);
        if (r != SP_OK) fail(r, "%s", e.text);
    }

    // The surface being read: per vertex, then triangles of absolute indices.
    struct Surface {
        std::vector<double> rest;
        std::vector<uint16_t> joints;
        std::vector<float> weights, colors;
        std::vector<uint32_t> tris;
    };
    using AttrKey = std::array<int, 3>;                              // POSITION, JOINTS_0, WEIGHTS_0 accessors
    using ColorKey = std::tuple<AttrKey, int, std::array<float, 4>>; // + COLOR_0, material colour
    // Where an attribute set's vertices went. Exporters that split a mesh by
    // material give every primitive the one vertex array: copied per
    // primitive, 2,000 of them ran a 2 MB file out of memory. The first
    // colouring copies the array whole and in order (so files that share
    // nothing load as they always did); another colouring copies only the
    // vertices its triangles use.
    struct Placement {
        bool whole = false;
        size_t base = 0;
        std::unordered_map<uint32_t, uint32_t> at; // source vertex -> surface vertex
    };
    std::map<AttrKey, size_t> attr_base{};
    std::map<ColorKey, Placement> placements{};

    // COLOR_0 of a primitive with nv vertices, checked; count 0 when it has none.
    View vertex_colors(const tinygltf::Primitive& prim, int mesh, size_t pi, size_t nv)
    {
        View cv;
        auto cit = prim.attributes.find("COLOR_0");
        if (cit == prim.attributes.end()) return cv;
        char usage[64];
        snprintf(usage, sizeof usage, "mesh %d primitive %zu COLOR_0", mesh, pi);
        cv = view_accessor(m, cit->second, what, usage);
        if ((cv.ncomp != 3 && cv.ncomp != 4) || cv.count != nv)
            fail(SP_ERR_INVALID, "%s: %s has the wrong type or count", what, usage);
        // Why: integers read as 0-255 would all clamp to white.
        bool unorm = (cv.comp == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE || cv.comp == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT) &&
                     cv.normalized;
        if (cv.comp != TINYGLTF_COMPONENT_TYPE_FLOAT && !unorm)
            fail(SP_ERR_INVALID, "%s: %s (accessor %d) must be float or normalized unsigned bytes or shorts", what, usage,
                 cv.index);
        return cv;
    }

    static void add_color(Surface& s, const View& cv, size_t i, const std::array<float, 4>& rgba)
    {
        for (int c = 0; c < 4; ++c) {
            float x = rgba[(size_t)c];
            if (c < cv.ncomp && cv.count) {
                double k = read_comp(cv, i, c);
                x *= (float)(std::isfinite(k) ? std::min(1.0, std::max(0.0, k)) : 1.0);
            }
            s.colors.push_back(x);
        }
    }

    // The surface vertices of a triangle primitive's indices (appending the
    // vertices it brings), or an empty list when an identical primitive was
    // read before (a mesh on two nodes of one skin draws the same triangles).
    std::vector<uint32_t> place_primitive(const tinygltf::Primitive& prim, int mesh, size_t pi, int skin, Surface& s,
                                          std::set<std::tuple<ColorKey, int, int>>& seen)
    {
        auto attr = [&](const char* name) {
            auto it = prim.attributes.find(name);
            return it == prim.attributes.end() ? -1 : it->second;
        };
        AttrKey ak = {attr("POSITION"), attr("JOINTS_0"), attr("WEIGHTS_0")};
        std::array<float, 4> rgba;
        if (material_color(m, prim.material, what, rgba.data()) && !ch->textured) {
            ch->textured = true;
            sp_character_warn(ch, "its base colour texture is not used: sketchpose reads no images, so pictures and "
                                  "saved files show it grey");
        }
        ColorKey ck{ak, attr("COLOR_0"), rgba};
        auto found = attr_base.find(ak);
        if (found == attr_base.end()) {
            Skinned sk;
            warn_extra_influences(prim, mesh, (int)pi);
            read_skinned(m, prim, mesh, (int)pi, skin_map(skin), skin, what, sk);
            size_t nv = sk.rest.size() / 3, base = s.rest.size() / 3;
            if (base + nv > 0x7fffffff) fail(SP_ERR_UNSUPPORTED, "%s: too many vertices", what);
            View cv = vertex_colors(prim, mesh, pi, nv);
            s.rest.insert(s.rest.end(), sk.rest.begin(), sk.rest.end());
            s.joints.insert(s.joints.end(), sk.joints.begin(), sk.joints.end());
            s.weights.insert(s.weights.end(), sk.weights.begin(), sk.weights.end());
            for (size_t i = 0; i < nv; ++i)
                add_color(s, cv, i, rgba);
            attr_base[ak] = base;
            Placement& pl = placements[ck];
            pl.whole = true, pl.base = base;
        }
        if (!seen.insert({ck, prim.indices, prim.mode}).second) return {};
        size_t nv = m.accessors[(size_t)ak[0]].count, src = attr_base[ak];
        std::vector<uint32_t> idx = read_indices(m, prim, mesh, (int)pi, nv, what);
        Placement& pl = placements[ck];
        if (pl.whole) {
            for (uint32_t& i : idx)
                i += (uint32_t)pl.base;
            return idx;
        }
        View cv = vertex_colors(prim, mesh, pi, nv);
        for (uint32_t& i : idx) {
            auto at = pl.at.find(i);
            if (at != pl.at.end()) {
                i = at->second;
                continue;
            }
            size_t from = src + i, to = s.rest.size() / 3;
            if (to >= 0x7fffffff) fail(SP_ERR_UNSUPPORTED, "%s: too many vertices", what);
            // Copied out first: the vectors may grow while their own elements are read.
            for (int c = 0; c < 3; ++c) {
                double x = s.rest[3 * from + (size_t)c];
                s.rest.push_back(x);
            }
            for (int c = 0; c < 4; ++c) {
                uint16_t j = s.joints[4 * from + (size_t)c];
                float w = s.weights[4 * from + (size_t)c];
                s.joints.push_back(j);
                s.weights.push_back(w);
            }
            add_color(s, cv, i, rgba);
            pl.at[i] = (uint32_t)to;
            i = (uint32_t)to;
        }
        return idx;
    }

    void read_meshes(int skin)
    {
        sp_rig* rig = &ch->rig;
        Surface s;
        std::set<std::tuple<ColorKey, int, int>> seen;
        bool warned_unskinned = false, warned_lines = false;
        for (int n : order) {
            const tinygltf::Node& nd = m.nodes[(size_t)n];
            if (nd.mesh < 0) continue;
            if ((size_t)nd.mesh >= m.meshes.size())
                fail(SP_ERR_INVALID, "%s: node %d refers to mesh %d, but there are %zu", what, n, nd.mesh, m.meshes.size());
            if (nd.skin >= 0 && (size_t)nd.skin >= m.skins.size())
                fail(SP_ERR_INVALID, "%s: node %d refers to skin %d, but there are %zu", what, n, nd.skin, m.skins.size());
            sp_curve_tag node_tag = tag_of(nd.extras_json_string);
            const tinygltf::Mesh& mesh = m.meshes[(size_t)nd.mesh];
            warn_morph_targets(mesh, nd);
            for (size_t pi = 0; pi < mesh.primitives.size(); ++pi) {
                const tinygltf::Primitive& prim = mesh.primitives[pi];
                // tinygltf takes any integer; an unknown mode would otherwise
                // be skipped quietly and surface later as a missing mesh.
                if (prim.mode < TINYGLTF_MODE_POINTS || prim.mode > TINYGLTF_MODE_TRIANGLE_FAN)
                    fail(SP_ERR_INVALID, "%s: mesh %d primitive %zu: mode %d is not a glTF primitive mode", what, nd.mesh, pi,
                         prim.mode);
                int mode = prim.mode;
                // POINTS: skinned vertices without faces (what we export for a mesh without triangles).
                bool triangles = mode == TINYGLTF_MODE_TRIANGLES || mode == TINYGLTF_MODE_TRIANGLE_STRIP ||
                                 mode == TINYGLTF_MODE_TRIANGLE_FAN || mode == TINYGLTF_MODE_POINTS;
                bool lines = mode == TINYGLTF_MODE_LINE_STRIP || mode == TINYGLTF_MODE_LINE_LOOP;
                sp_curve_tag tag = node_tag;
                sp_curve_tag ptag = tag_of(prim.extras_json_string);
                if (ptag.is_curve) tag = ptag;
                if (lines && tag.is_curve) {
                    read_curve(nd, n, prim, nd.mesh, (int)pi, mode, tag, skin);
                    continue;
                }
                if (!triangles || tag.is_curve) {
                    // A curve's extras on a primitive that is not a strip or a
                    // loop (a re-export's LINES): said as such, not as missing extras.
                    if (tag.is_curve)
                        sp_character_warn(ch,
                                          "ignored mesh %d primitive %zu: an sp_abstraction curve must be a LINE_STRIP or "
                                          "LINE_LOOP, this one is mode %d (%s)",
                                          nd.mesh, pi, mode, mode == TINYGLTF_MODE_LINE ? "LINES" : "not lines");
                    else if (!warned_lines)
                        sp_character_warn(ch, "ignored line primitives without sp_abstraction extras (mesh %d)", nd.mesh);
                    warned_lines = warned_lines || !tag.is_curve;
                    continue;
                }
                if (nd.skin != skin) {
                    if (!warned_unskinned)
                        sp_character_warn(ch, "ignored mesh %d on node %d: not skinned by the character's skin", nd.mesh, n);
                    warned_unskinned = true;
                    continue;
                }
                std::vector<uint32_t> idx = place_primitive(prim, nd.mesh, pi, skin, s, seen);
                auto tri = [&](uint32_t a, uint32_t b, uint32_t c) {
                    s.tris.push_back(a), s.tris.push_back(b), s.tris.push_back(c);
                };
                if (mode == TINYGLTF_MODE_TRIANGLES) {
                    if (idx.size() % 3)
                        fail(SP_ERR_INVALID, "%s: mesh %d primitive %zu: %zu indices is not a multiple of 3", what, nd.mesh, pi,
                             idx.size());
                    for (size_t i = 0; i + 2 < idx.size(); i += 3)
                        tri(idx[i], idx[i + 1], idx[i + 2]);
                } else if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
                    for (size_t i = 0; i + 2 < idx.size(); ++i)
                        if (i % 2 == 0)
                            tri(idx[i], idx[i + 1], idx[i + 2]);
                        else
                            tri(idx[i + 1], idx[i], idx[i + 2]);
                } else if (mode == TINYGLTF_MODE_TRIANGLE_FAN) {
                    for (size_t i = 1; i + 1 < idx.size(); ++i)
                        tri(idx[0], idx[i], idx[i + 1]);
                }
            }
        }
        if (s.rest.empty() && warned_lines)
            fail(SP_ERR_INVALID, "%s: the skinned mesh is only lines (LINES, LINE_STRIP or LINE_LOOP): no surface to pose", what);
        if (s.rest.empty()) fail(SP_ERR_INVALID, "%s: the skinned mesh has no vertices", what);
        // All at one point (zeroed positions, an accessor without data) frames
        // a view of no size: strokes synthesised from it were 1e9 pixels long.
        bool one_point = true;
        for (size_t i = 3; one_point && i < s.rest.size(); ++i)
            one_point = s.rest[i] == s.rest[i % 3];
        if (one_point)
            fail(SP_ERR_INVALID, "%s: the skinned mesh's %zu vertices are all at one point: no surface to pose", what,
                 s.rest.size() / 3);
        if (s.tris.size() / 3 > 0x7fffffff) fail(SP_ERR_UNSUPPORTED, "%s: too many triangles", what);
        rig->rest = c_array(s.rest);
        rig->joints4 = c_array(s.joints);
        rig->weights4 = c_array(s.weights);
        rig->vertex_count = (int)(s.rest.size() / 3);
        rig->triangles = c_array(s.tris);
        rig->triangle_count = (int)(s.tris.size() / 3);
        ch->colors = c_array(s.colors);
    }

    void read_curve(const tinygltf::Node& nd, int n, const tinygltf::Primitive& prim, int mesh, int pi, int mode,
                    const sp_curve_tag& tag, int skin)
    {
        int use_skin = skin;
        if (nd.skin >= 0 && nd.skin != skin) use_skin = nd.skin;
        if (m.skins[(size_t)use_skin].joints.empty()) fail(SP_ERR_INVALID, "%s: skin %d has no joints", what, use_skin);
        Skinned s;
        warn_extra_influences(prim, mesh, pi);
        read_skinned(m, prim, mesh, pi, skin_map(use_skin), use_skin, what, s);
        size_t nv = s.rest.size() / 3;
        std::vector<uint32_t> idx = read_indices(m, prim, mesh, pi, nv, what);
        if (idx.size() < 2)
            fail(SP_ERR_INVALID, "%s: curve on node %d (mesh %d primitive %d) has fewer than 2 points", what, n, mesh, pi);
        Skinned c;
        for (uint32_t i : idx) {
            c.rest.insert(c.rest.end(), s.rest.begin() + 3 * i, s.rest.begin() + 3 * i + 3);
            c.joints.insert(c.joints.end(), s.joints.begin() + 4 * i, s.joints.begin() + 4 * i + 4);
            c.weights.insert(c.weights.end(), s.weights.begin() + 4 * i, s.weights.begin() + 4 * i + 4);
        }
        std::string name = tag.curve[0] ? tag.curve : (nd.name.empty() ? "curve" + std::to_string(n) : nd.name);
        if (pi > 0) name += "_" + std::to_string(pi);
        if (name.size() >= SP_NAME_MAX) name.resize(SP_NAME_MAX - 1);
        int a = sp_rig_find_abstraction(&ch->rig, tag.abstraction);
        sp_correspondence corr = tag.has_correspondence ? tag.correspondence : SP_CORR_ORDERED;
        if (a >= 0 && tag.has_correspondence && ch->rig.abstractions[a].correspondence != corr)
            sp_character_warn(ch, "abstraction '%s': curves disagree on sp_correspondence; the first one wins", tag.abstraction);
        if (sp_gltf_append_curve(&ch->rig, tag.abstraction, corr, name.c_str(), mode == TINYGLTF_MODE_LINE_LOOP, (int)idx.size(),
                                 c.rest.data(), c.joints.data(), c.weights.data()) != SP_OK)
            throw std::bad_alloc();
    }

    void read_animations()
    {
        sp_rig* rig = &ch->rig;
        if (m.animations.empty()) return;
        rig->animations = static_cast<sp_animation*>(calloc(m.animations.size(), sizeof(sp_animation)));
        if (!rig->animations) throw std::bad_alloc();
        for (size_t ai = 0; ai < m.animations.size(); ++ai) {
            const tinygltf::Animation& an = m.animations[ai];
            sp_animation* out = &rig->animations[rig->animation_count++];
            std::string name = an.name.empty() ? "animation" + std::to_string(ai) : an.name;
            snprintf(out->name, sizeof out->name, "%s", name.c_str());
            if (an.channels.empty()) continue;
            out->channels = static_cast<sp_anim_channel*>(calloc(an.channels.size(), sizeof(sp_anim_channel)));
            if (!out->channels) throw std::bad_alloc();
            bool warned = false, warned_morph_anim = false;
            for (size_t ci = 0; ci < an.channels.size(); ++ci) {
                const tinygltf::AnimationChannel& c = an.channels[ci];
                int node = c.target_node;
                sp_anim_path path;
                if (c.target_path == "translation")
                    path = SP_ANIM_TRANSLATION;
                else if (c.target_path == "rotation")
                    path = SP_ANIM_ROTATION;
                else if (c.target_path == "scale")
                    path = SP_ANIM_SCALE;
                else { // morph weights: the shape has no targets here to animate
                    if (!warned_morph_anim)
                        sp_character_warn(ch, "animation '%s': morph-weight channels ignored (morph targets are not read)",
                                          out->name);
                    warned_morph_anim = true;
                    continue;
                }
                if (node < 0 || (size_t)node >= m.nodes.size())
                    fail(SP_ERR_INVALID, "%s: animation %zu channel %zu targets node %d, but there are %zu", what, ai, ci, node,
                         m.nodes.size());
                if (node2joint[(size_t)node] < 0) {
                    if (!warned)
                        sp_character_warn(ch, "animation '%s': channels on nodes outside the skeleton ignored", out->name);
                    warned = true;
                    continue;
                }
                if (c.sampler < 0 || (size_t)c.sampler >= an.samplers.size())
                    fail(SP_ERR_INVALID, "%s: animation %zu channel %zu refers to sampler %d, but there are %zu", what, ai, ci,
                         c.sampler, an.samplers.size());
                const tinygltf::AnimationSampler& s = an.samplers[(size_t)c.sampler];
                sp_interp interp = SP_INTERP_LINEAR;
                if (s.interpolation == "STEP")
                    interp = SP_INTERP_STEP;
                else if (s.interpolation == "CUBICSPLINE")
                    interp = SP_INTERP_CUBICSPLINE;
                else if (!s.interpolation.empty() && s.interpolation != "LINEAR")
                    fail(SP_ERR_INVALID, "%s: animation %zu sampler %d: unknown interpolation '%s'", what, ai, c.sampler,
                         s.interpolation.c_str());
                char usage[80];
                snprintf(usage, sizeof usage, "animation %zu sampler %d input", ai, c.sampler);
                View in = view_accessor(m, s.input, what, usage);
                expect(in, 1, {TINYGLTF_COMPONENT_TYPE_FLOAT}, false, what, usage);
                snprintf(usage, sizeof usage, "animation %zu sampler %d output", ai, c.sampler);
                View ov = view_accessor(m, s.output, what, usage);
                int comps = path == SP_ANIM_ROTATION ? 4 : 3;
                if (path == SP_ANIM_ROTATION)
                    expect(ov, 4,
                           {TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_COMPONENT_TYPE_BYTE, TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE,
                            TINYGLTF_COMPONENT_TYPE_SHORT, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT},
                           true, what, usage);
                else
                    expect(ov, 3, {TINYGLTF_COMPONENT_TYPE_FLOAT}, false, what, usage);
                size_t per = interp == SP_INTERP_CUBICSPLINE ? 3 : 1;
                if (in.count < 1 || ov.count != in.count * per)
                    fail(SP_ERR_INVALID, "%s: animation %zu sampler %d: %zu outputs for %zu keys%s (%zu wanted)", what, ai,
                         c.sampler, ov.count, in.count,
                         per == 3 ? " of CUBICSPLINE, 3 a key: in-tangent, value, out-tangent" : "", in.count * per);
                sp_anim_channel* oc = &out->channels[out->channel_count];
                oc->joint = node2joint[(size_t)node];
                oc->path = path;
                oc->interp = interp;
                oc->times = static_cast<float*>(malloc(sizeof(float) * in.count));
                oc->values = static_cast<float*>(malloc(sizeof(float) * ov.count * (size_t)comps));
                ++out->channel_count; // counted now so that sp_rig_free releases it on failure
                if (!oc->times || !oc->values) throw std::bad_alloc();
                oc->key_count = (int)in.count;
                for (size_t k = 0; k < in.count; ++k)
                    oc->times[k] = (float)read_comp(in, k, 0);
                for (size_t k = 0; k < ov.count; ++k)
                    for (int cc = 0; cc < comps; ++cc)
                        oc->values[k * (size_t)comps + (size_t)cc] = (float)read_comp(ov, k, cc);
            }
        }
    }

    // Two finite numbers within [lo, hi] in a JSON list of two.
    static bool two_numbers(const cJSON* a, double* x, double* y, double lo, double hi)
    {
        const cJSON *p = cJSON_GetArrayItem(a, 0), *q = cJSON_GetArrayItem(a, 1);
        if (!cJSON_IsArray(a) || cJSON_GetArraySize(a) != 2 || !cJSON_IsNumber(p) || !cJSON_IsNumber(q)) return false;
        *x = p->valuedouble, *y = q->valuedouble;
        return *x >= lo && *x <= hi && *y >= lo && *y <= hi;
    }

    void read_camera()
    {
        for (int n : order) {
            const tinygltf::Node& nd = m.nodes[(size_t)n];
            if (nd.camera < 0) continue;
            if ((size_t)nd.camera >= m.cameras.size())
                fail(SP_ERR_INVALID, "%s: node %d refers to camera %d, but there are %zu", what, n, nd.camera, m.cameras.size());
            const tinygltf::Camera& c = m.cameras[(size_t)nd.camera];
            sp_mat4 world = node_local(nd, n, what);
            for (int p = parent[(size_t)n]; p >= 0; p = parent[(size_t)p]) {
                sp_mat4 l = node_local(m.nodes[(size_t)p], p, what);
                world = sp_mat4_mul(&l, &world);
            }
            sp_camera cam = {};
            if (!sp_mat4_inverse(&world, &cam.view)) fail(SP_ERR_INVALID, "%s: camera node %d has a singular transform", what, n);
            int w = SP_GLTF_CANVAS_W, h = SP_GLTF_CANVAS_H;
            double cx = -1, cy = -1;
            if (!c.extras_json_string.empty()) {
                cJSON* ex = cJSON_Parse(c.extras_json_string.c_str());
                // Malformed, they are refused as a malformed sp_dofs is: a
                // principal point of 1e308 put inf into every fit, exit 0, and
                // a canvas of [0, 0] became 640x480 without a word (an outside review).
                const cJSON* cv = cJSON_GetObjectItemCaseSensitive(ex, "sp_canvas");
                const cJSON* pp = cJSON_GetObjectItemCaseSensitive(ex, "sp_principal");
                double a = 0, b = 0;
                const char* bad = NULL;
                if (cv && !two_numbers(cv, &a, &b, 16, 16384))
                    bad = "sp_canvas must be [width, height], each 16 to 16384 pixels";
                else if (cv)
                    w = (int)a, h = (int)b;
                if (pp && !bad && !two_numbers(pp, &cx, &cy, -1e6, 1e6))
                    bad = "sp_principal must be [x, y], each within +-1e6 pixels";
                cJSON_Delete(ex);
                if (bad) fail(SP_ERR_INVALID, "%s: camera %d: %s", what, nd.camera, bad);
            }
            cam.width = w, cam.height = h;
            cam.cx = cx >= 0 ? cx : 0.5 * w;
            cam.cy = cy >= 0 ? cy : 0.5 * h;
            if (c.type == "orthographic") {
                double xm = std::fabs(c.orthographic.xmag), ym = std::fabs(c.orthographic.ymag);
                // Within 1e-6..1e6 units: xmag 1e-300 gave a scale of 1e302 px a unit.
                if (!(xm >= 1e-6 && xm <= 1e6) || !(ym >= 1e-6 && ym <= 1e6))
                    fail(SP_ERR_INVALID, "%s: camera %d: xmag and ymag must be within 1e-6..1e6 (not zero)", what, nd.camera);
                cam.kind = SP_CAMERA_ORTHOGRAPHIC;
                cam.scale = std::min(0.5 * w / xm, 0.5 * h / ym);
                cam.zfar = c.orthographic.zfar;
                cam.znear = c.orthographic.znear > 0 ? c.orthographic.znear : 1e-4 * cam.zfar;
            } else if (c.type == "perspective") {
                double f = c.perspective.yfov;
                if (!(f >= 1e-6 && f < 3.14159))
                    fail(SP_ERR_INVALID, "%s: camera %d: yfov must be in (0, pi), at least 1e-6", what, nd.camera);
                cam.kind = SP_CAMERA_PERSPECTIVE;
                cam.scale = 0.5 * h / std::tan(0.5 * f);
                cam.znear = c.perspective.znear;
                cam.zfar = c.perspective.zfar > 0 ? c.perspective.zfar : 1e4 * cam.znear;
            } else {
                fail(SP_ERR_INVALID, "%s: camera %d has an unknown type '%s'", what, nd.camera, c.type.c_str());
            }
            if (!(cam.znear > 0) || !(cam.zfar > cam.znear) || !std::isfinite(cam.zfar))
                fail(SP_ERR_INVALID, "%s: camera %d has an invalid clip range", what, nd.camera);
            ch->camera = cam;
            ch->has_camera = true;
            return;
        }
    }
};

void import(tinygltf::Model& model, const char* what, sp_character* ch)
{
    Importer im{model, what, ch, {}, {}, {}, {}};
    im.run();
}

// The exception firewall of the readers (STYLE.md): nothing thrown leaves for C,
// and a character half read is freed. A Failure's text names the file already.
template <class Body> sp_result read_firewall(const char* what, sp_character* out, sp_error* err, Body body)
{
    try {
        return body();
    } catch (const Failure& f) {
        sp_character_free(out);
        return sp_fail(err, f.code, "%s", f.text.c_str());
    } catch (const std::bad_alloc&) {
        sp_character_free(out);
        return sp_fail(err, SP_ERR_NO_MEMORY, "%s: out of memory", what);
    } catch (...) {
        sp_character_free(out);
        return sp_fail(err, SP_ERR_INTERNAL, "%s: internal error in the glTF reader", what);
    }
}

} // namespace

extern "C" sp_result sp_gltf_load_memory(const void* data, size_t size, const char* what, sp_character* out, sp_error* err)
{
    memset(out, 0, sizeof *out);
    if (!what) what = "glTF";
    return read_firewall(what, out, err, [&] {
        tinygltf::Model model;
        parse_model(model, static_cast<const unsigned char*>(data), size, what, "", false, out);
        import(model, what, out);
        return SP_OK;
    });
}

extern "C" sp_result sp_gltf_load(const char* path, sp_character* out, sp_error* err)
{
    memset(out, 0, sizeof *out);
    return read_firewall(path, out, err, [&] {
        // Whole and sized first (sp_file_read): a device such as /dev/zero is
        // refused, not read until the memory runs out; at most 2 GiB, as a buffer.
        void* data = nullptr;
        size_t size = 0;
        sp_result r = sp_file_read(path, (size_t)0x7fffffff, &data, &size, err);
        if (r != SP_OK) return r;
        std::unique_ptr<void, decltype(&free)> bytes(data, &free);
        std::string dir = path;
        size_t slash = dir.rfind('/');
        dir = slash == std::string::npos ? "." : dir.substr(0, slash == 0 ? 1 : slash);
        tinygltf::Model model;
        parse_model(model, static_cast<const unsigned char*>(bytes.get()), size, path, dir, true, out);
        import(model, path, out);
        return SP_OK;
    });
}

namespace
{

// The JSON text of a .gltf, or of a .glb's first chunk: the header and that
// chunk only, not the binary one (a glb of 2 GiB is not read twice). Empty
// for a file that is neither: whatever does not open with '{' is no glTF
// JSON (commands ask this of every input, and a 570 MB database was read
// whole for it).
std::string gltf_json_text(const char* path)
{
    struct stat st;
    if (stat(path, &st) != 0 || !S_ISREG(st.st_mode) || st.st_size > 0x7fffffff) return std::string();
    std::unique_ptr<FILE, decltype(&fclose)> f(fopen(path, "rb"), &fclose);
    if (!f) return std::string();
    unsigned char head[20];
    size_t got = fread(head, 1, sizeof head, f.get());
    size_t len = (size_t)st.st_size, lead = 0;
    while (lead < got && strchr(" \t\r\n", head[lead]))
        ++lead;
    if (got == sizeof head && !memcmp(head, "glTF", 4))
        len = std::min((size_t)le32(head + 12), len - got);
    else if ((lead < got && head[lead] != '{') || fseek(f.get(), 0, SEEK_SET) != 0)
        return std::string();
    std::string text(len, '\0');
    text.resize(fread(&text[0], 1, len, f.get()));
    return text;
}

} // namespace

extern "C" sp_result sp_gltf_external_files(const char* path, char*** files, int* count, sp_error* err)
{
    *files = nullptr;
    *count = 0;
    try {
        std::string text = gltf_json_text(path);
        std::unique_ptr<cJSON, decltype(&cJSON_Delete)> root(cJSON_ParseWithLength(text.data(), text.size()), &cJSON_Delete);
        std::string dir = path;
        size_t slash = dir.rfind('/');
        dir = slash == std::string::npos ? "." : dir.substr(0, slash == 0 ? 1 : slash);
        std::vector<std::string> names;
        for (const char* key : {"buffers", "images"}) {
            const cJSON* list = cJSON_GetObjectItemCaseSensitive(root.get(), key);
            if (!cJSON_IsArray(list)) continue;
            const cJSON* it;
            cJSON_ArrayForEach(it, list)
            {
                const cJSON* uri = cJSON_GetObjectItemCaseSensitive(it, "uri");
                // Only paths relative to the file are read (read_buffer_file): an
                // absolute or scheme uri names nothing the loader opens.
                if (!cJSON_IsString(uri) || !uri->valuestring[0] || is_data_uri(uri->valuestring)) continue;
                std::string name = url_decode(uri->valuestring);
                if (!is_absolute_uri(name)) names.push_back(dir + "/" + name);
            }
        }
        if (names.empty()) return SP_OK;
        char** out = static_cast<char**>(calloc(names.size(), sizeof(char*)));
        if (!out) throw std::bad_alloc();
        for (size_t i = 0; i < names.size(); ++i)
            if (!(out[i] = strdup(names[i].c_str()))) {
                sp_gltf_files_free(out, (int)i);
                throw std::bad_alloc();
            }
        *files = out;
        *count = (int)names.size();
        return SP_OK;
    } catch (const std::bad_alloc&) {
        return sp_fail(err, SP_ERR_NO_MEMORY, "%s: out of memory", path);
    } catch (...) {
        return sp_fail(err, SP_ERR_INTERNAL, "%s: internal error in the glTF reader", path);
    }
}

extern "C" void sp_gltf_files_free(char** files, int count)
{
    for (int i = 0; i < count; ++i)
        free(files[i]);
    free(files);
}

// ---- export ---------------------------------------------------------------

namespace
{

using tinygltf::Value;

Value num_array(const double* v, int n)
{
    Value::Array a;
    for (int i = 0; i < n; ++i)
        a.push_back(Value(v[i]));
    return Value(std::move(a));
}

// cJSON tree -> tinygltf value (sp_part, a scene's extras).
Value from_cjson(const cJSON* j)
{
    if (cJSON_IsBool(j)) return Value(cJSON_IsTrue(j) ? true : false);
    if (cJSON_IsNumber(j)) {
        double d = j->valuedouble;
        if (d == std::floor(d) && std::fabs(d) < 2e9) return Value((int)d);
        return Value(d);
    }
    if (cJSON_IsString(j)) return Value(std::string(j->valuestring));
    if (cJSON_IsArray(j)) {
        Value::Array a;
        const cJSON* it;
        cJSON_ArrayForEach(it, j) a.push_back(from_cjson(it));
        return Value(std::move(a));
    }
    if (cJSON_IsObject(j)) {
        Value::Object o;
        const cJSON* it;
        cJSON_ArrayForEach(it, j) o[it->string] = from_cjson(it);
        return Value(std::move(o));
    }
    return Value();
}

struct Writer {
    tinygltf::Model m;

    Writer()
    {
        m.asset.version = "2.0";
        m.asset.generator = "sketchpose";
        m.buffers.emplace_back();
    }

    int view(const void* data, size_t bytes, int target)
    {
        std::vector<unsigned char>& buf = m.buffers[0].data;
        // Why 4: every accessor's component size divides 4, and glTF wants
        // vertex attributes 4-byte aligned.
        while (buf.size() % 4)
            buf.push_back(0);
        tinygltf::BufferView bv;
        bv.buffer = 0;
        bv.byteOffset = buf.size();
        bv.byteLength = bytes;
        bv.target = target;
        const unsigned char* p = static_cast<const unsigned char*>(data);
        buf.insert(buf.end(), p, p + bytes);
        m.bufferViews.push_back(bv);
        return (int)m.bufferViews.size() - 1;
    }

    int accessor(const void* data, size_t count, int comp, int type, int target, bool minmax = false, bool normalized = false)
    {
        int ncomp = tinygltf::GetNumComponentsInType((uint32_t)type);
        int csize = tinygltf::GetComponentSizeInBytes((uint32_t)comp);
        tinygltf::Accessor a;
        a.bufferView = view(data, count * (size_t)ncomp * (size_t)csize, target);
        a.byteOffset = 0;
        a.componentType = comp;
        a.type = type;
        a.count = count;
        a.normalized = normalized;
        if (minmax && comp == TINYGLTF_COMPONENT_TYPE_FLOAT) {
            const float* f = static_cast<const float*>(data);
            a.minValues.assign((size_t)ncomp, 0.0);
            a.maxValues.assign((size_t)ncomp, 0.0);
            for (size_t i = 0; i < count; ++i)
                for (int c = 0; c < ncomp; ++c) {
                    double x = f[i * (size_t)ncomp + (size_t)c];
                    if (i == 0 || x < a.minValues[(size_t)c]) a.minValues[(size_t)c] = x;
                    if (i == 0 || x > a.maxValues[(size_t)c]) a.maxValues[(size_t)c] = x;
                }
        }
        m.accessors.push_back(a);
        return (int)m.accessors.size() - 1;
    }

    // POSITION / JOINTS_0 / WEIGHTS_0 of skinned points.
    void skinned_attributes(tinygltf::Primitive& prim, int n, const double* rest, const uint16_t* joints, const float* weights)
    {
        std::vector<float> pos(3 * (size_t)n), w(4 * (size_t)n);
        std::vector<uint16_t> j(4 * (size_t)n);
        for (size_t i = 0; i < 3 * (size_t)n; ++i) {
            pos[i] = (float)rest[i];
            if (!std::isfinite(pos[i])) fail(SP_ERR_INVALID, "a point's position is beyond the float range of glTF");
        }
        for (size_t i = 0; i < (size_t)n; ++i) {
            double ww[4];
            uint16_t jj[4];
            for (int k = 0; k < 4; ++k)
                ww[k] = weights[4 * i + (size_t)k], jj[k] = joints[4 * i + (size_t)k];
            for (int a = 0; a < 4; ++a)
                for (int b = a + 1; b < 4; ++b)
                    if (jj[a] == jj[b] && ww[b] > 0) ww[a] += ww[b], ww[b] = 0;
            double sum = ww[0] + ww[1] + ww[2] + ww[3];
            int big = 0;
            for (int k = 0; k < 4; ++k) {
                ww[k] = sum > 0 ? ww[k] / sum : (k == 0);
                if (ww[k] == 0) jj[k] = 0; // unused influences point at joint 0
                if (ww[k] > ww[big]) big = k;
            }
            // Why: the validator checks the float sum; put the rounding on the largest weight.
            float f[4], fs = 0;
            for (int k = 0; k < 4; ++k)
                f[k] = (float)ww[k];
            for (int k = 0; k < 4; ++k)
                if (k != big) fs += f[k];
            f[big] = 1.0f - fs;
            for (int k = 0; k < 4; ++k)
                w[4 * i + (size_t)k] = f[k], j[4 * i + (size_t)k] = jj[k];
        }
        prim.attributes["POSITION"] = accessor(pos.data(), (size_t)n, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3,
                                               TINYGLTF_TARGET_ARRAY_BUFFER, true);
        prim.attributes["JOINTS_0"] = accessor(j.data(), (size_t)n, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT, TINYGLTF_TYPE_VEC4,
                                               TINYGLTF_TARGET_ARRAY_BUFFER);
        prim.attributes["WEIGHTS_0"] =
            accessor(w.data(), (size_t)n, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC4, TINYGLTF_TARGET_ARRAY_BUFFER);
    }
};

// An embedded abstraction (points in mesh triangles) becomes skinned points:
// barycentric rest positions and the four strongest blended joint weights.
void embedded_to_skinned(const sp_rig* rig, const sp_abstraction* a, std::vector<double>& rest, std::vector<uint16_t>& joints,
                         std::vector<float>& weights)
{
    size_t n = (size_t)a->point_count;
    rest.assign(3 * n, 0.0);
    joints.assign(4 * n, 0);
    weights.assign(4 * n, 0.0f);
    for (size_t i = 0; i < n; ++i) {
        std::map<int, double> acc;
        for (int k = 0; k < 3; ++k) {
            uint32_t v = a->tri_vertices[3 * i + (size_t)k];
            double b = a->bary[3 * i + (size_t)k];
            for (int c = 0; c < 3; ++c)
                rest[3 * i + (size_t)c] += b * rig->rest[3 * (size_t)v + (size_t)c];
            for (int c = 0; c < 4; ++c)
                acc[rig->joints4[4 * (size_t)v + (size_t)c]] += b * rig->weights4[4 * (size_t)v + (size_t)c];
        }
        std::vector<std::pair<double, int>> best;
        for (auto& kv : acc)
            if (kv.second > 0) best.push_back({kv.second, kv.first});
        std::sort(best.rbegin(), best.rend());
        for (size_t k = 0; k < best.size() && k < 4; ++k)
            joints[4 * i + k] = (uint16_t)best[k].second, weights[4 * i + k] = (float)best[k].first;
        if (best.empty()) weights[4 * i] = 1.0f;
    }
}

// A rig's joint nodes at parameters p, appended in rig order (node index =
// first index + joint index), named prefix + joint name.
void write_joint_nodes(Writer& w, const sp_rig* rig, const double* p, const std::string& prefix)
{
    tinygltf::Model& m = w.m;
    int base = (int)m.nodes.size();
    for (int j = 0; j < rig->joint_count; ++j) {
        const sp_joint* jt = &rig->joints[j];
        tinygltf::Node nd;
        nd.name = prefix + jt->name;
        sp_vec3 t, s;
        sp_quat r;
        sp_rig_local_trs(rig, j, p, &t, &r, &s);
        r = sp_quat_norm(r);
        nd.translation = {t.x, t.y, t.z};
        nd.rotation = {r.x, r.y, r.z, r.w};
        nd.scale = {s.x, s.y, s.z};
        Value::Array dofs;
        for (int k = 0; k < jt->param_count; ++k) {
            const sp_param* q = &rig->params[jt->first_param + k];
            Value::Object d;
            d["channel"] = Value(std::string(sp_channel_name(q->channel)));
            d["min"] = Value(q->min);
            d["max"] = Value(q->max);
            d["group"] = Value(std::string(q->group == SP_GROUP_SHAPE ? "shape" : "pose"));
            dofs.push_back(Value(std::move(d)));
        }
        Value::Object rest;
        double rt[3] = {jt->rest_t.x, jt->rest_t.y, jt->rest_t.z},
               rr[4] = {jt->rest_r.x, jt->rest_r.y, jt->rest_r.z, jt->rest_r.w},
               rs[3] = {jt->rest_s.x, jt->rest_s.y, jt->rest_s.z};
        rest["translation"] = num_array(rt, 3);
        rest["rotation"] = num_array(rr, 4);
        rest["scale"] = num_array(rs, 3);
        Value::Object ex;
        ex["sp_dofs"] = Value(std::move(dofs));
        ex["sp_rest"] = Value(std::move(rest));
        nd.extras = Value(std::move(ex));
        if (jt->parent >= 0) m.nodes[(size_t)(base + jt->parent)].children.push_back(base + j);
        m.nodes.push_back(nd);
    }
}

// The skin of a rig whose joint nodes start at `base`; returns its index.
int write_skin(Writer& w, const sp_rig* rig, int base, const std::string& name)
{
    int J = rig->joint_count;
    tinygltf::Skin skin;
    skin.name = name;
    std::vector<float> ibm(16 * (size_t)J);
    for (int j = 0; j < J; ++j) {
        skin.joints.push_back(base + j);
        for (int k = 0; k < 16; ++k) {
            ibm[16 * (size_t)j + (size_t)k] = (float)rig->joints[j].inverse_bind.m[k];
            if (!std::isfinite(ibm[16 * (size_t)j + (size_t)k]))
                fail(SP_ERR_INVALID, "joint '%s': inverse bind matrix beyond the float range of glTF", rig->joints[j].name);
        }
        // The validator insists on an exact affine last row.
        ibm[16 * (size_t)j + 3] = ibm[16 * (size_t)j + 7] = ibm[16 * (size_t)j + 11] = 0.0f;
        ibm[16 * (size_t)j + 15] = 1.0f;
    }
    skin.inverseBindMatrices = w.accessor(ibm.data(), (size_t)J, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_MAT4, 0);
    w.m.skins.push_back(skin);
    return (int)w.m.skins.size() - 1;
}

// A mesh of one primitive on a new root node of the scene, skinned by skin_index (extras: the node's, or null).
void add_skinned_node(tinygltf::Model& m, tinygltf::Scene& scene, tinygltf::Primitive& prim, const std::string& mesh_name,
                      const std::string& name, int skin_index, Value extras)
{
    tinygltf::Mesh mesh;
    mesh.name = mesh_name;
    mesh.primitives.push_back(prim);
    m.meshes.push_back(mesh);
    tinygltf::Node nd;
    nd.name = name;
    nd.mesh = (int)m.meshes.size() - 1;
    nd.skin = skin_index;
    nd.extras = std::move(extras);
    scene.nodes.push_back((int)m.nodes.size());
    m.nodes.push_back(nd);
}

// The skinned triangle mesh of a character (with its material) on a new root node.
void write_mesh(Writer& w, tinygltf::Scene& scene, const sp_character* ch, int skin_index, const std::string& mesh_name,
                const std::string& node_name)
{
    tinygltf::Model& m = w.m;
    const sp_rig* rig = &ch->rig;
    if (rig->vertex_count <= 0) return;
    size_t nv = (size_t)rig->vertex_count;
    tinygltf::Primitive prim;
    w.skinned_attributes(prim, rig->vertex_count, rig->rest, rig->joints4, rig->weights4);
    std::vector<double> nrm(3 * nv, 0.0);
    for (int t = 0; t < rig->triangle_count; ++t) {
        const uint32_t* tri = rig->triangles + 3 * (size_t)t;
        sp_vec3 a = sp_v3(rig->rest[3 * tri[0]], rig->rest[3 * tri[0] + 1], rig->rest[3 * tri[0] + 2]);
        sp_vec3 b = sp_v3(rig->rest[3 * tri[1]], rig->rest[3 * tri[1] + 1], rig->rest[3 * tri[1] + 2]);
        sp_vec3 c = sp_v3(rig->rest[3 * tri[2]], rig->rest[3 * tri[2] + 1], rig->rest[3 * tri[2] + 2]);
        sp_vec3 fn = sp_v3_cross(sp_v3_sub(b, a), sp_v3_sub(c, a)); // area weighted
        for (int k = 0; k < 3; ++k)
            nrm[3 * tri[k]] += fn.x, nrm[3 * tri[k] + 1] += fn.y, nrm[3 * tri[k] + 2] += fn.z;
    }
    std::vector<float> nf(3 * nv);
    for (size_t i = 0; i < nv; ++i) {
        sp_vec3 n = sp_v3(nrm[3 * i], nrm[3 * i + 1], nrm[3 * i + 2]);
        double l = sp_v3_len(n);
        n = l > 1e-300 && std::isfinite(l) ? sp_v3_scale(n, 1.0 / l) : sp_v3(0, 0, 1);
        nf[3 * i] = (float)n.x, nf[3 * i + 1] = (float)n.y, nf[3 * i + 2] = (float)n.z;
    }
    prim.attributes["NORMAL"] =
        w.accessor(nf.data(), nv, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, TINYGLTF_TARGET_ARRAY_BUFFER);
    tinygltf::Material mat;
    mat.name = "sp_vertex_color";
    mat.pbrMetallicRoughness.metallicFactor = 0.0;
    mat.pbrMetallicRoughness.roughnessFactor = 0.8;
    if (ch->colors) {
        std::vector<float> col(4 * nv);
        for (size_t i = 0; i < 4 * nv; ++i)
            col[i] = std::isfinite(ch->colors[i]) ? std::min(1.0f, std::max(0.0f, ch->colors[i])) : 1.0f;
        prim.attributes["COLOR_0"] =
            w.accessor(col.data(), nv, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC4, TINYGLTF_TARGET_ARRAY_BUFFER);
    } else {
        mat.pbrMetallicRoughness.baseColorFactor = {SP_GLTF_TEXTURE_GREY, SP_GLTF_TEXTURE_GREY, SP_GLTF_TEXTURE_GREY, 1.0};
    }
    m.materials.push_back(mat);
    prim.material = (int)m.materials.size() - 1;
    if (rig->triangle_count > 0) {
        prim.mode = TINYGLTF_MODE_TRIANGLES;
        size_t ni = 3 * (size_t)rig->triangle_count;
        if (nv <= 65535) {
            std::vector<uint16_t> idx(ni);
            for (size_t i = 0; i < ni; ++i)
                idx[i] = (uint16_t)rig->triangles[i];
            prim.indices = w.accessor(idx.data(), ni, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT, TINYGLTF_TYPE_SCALAR,
                                      TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
        } else {
            prim.indices = w.accessor(rig->triangles, ni, TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, TINYGLTF_TYPE_SCALAR,
                                      TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
        }
    } else {
        prim.mode = TINYGLTF_MODE_POINTS;
    }
    add_skinned_node(m, scene, prim, mesh_name, node_name, skin_index, Value());
}

// Ink drawn on a scene part: a LINE_STRIP node per line, skinned by the part's skin.
void write_lines(Writer& w, tinygltf::Scene& scene, const sp_gltf_scene_part* part, int joint_count, int skin_index,
                 const std::string& prefix)
{
    tinygltf::Model& m = w.m;
    if (part->line_count > 0 && !part->lines) fail(SP_ERR_INVALID, "%s: %d ink lines missing", prefix.c_str(), part->line_count);
    for (int l = 0; l < part->line_count; ++l) {
        const sp_gltf_scene_line* ln = &part->lines[l];
        if (ln->point_count < 2 || !ln->rest || !ln->joints || !ln->weights)
            fail(SP_ERR_INVALID, "%s: ink line %d has no points", prefix.c_str(), l);
        for (size_t k = 0; k < 4 * (size_t)ln->point_count; ++k)
            if (ln->joints[k] >= joint_count)
                fail(SP_ERR_INVALID, "%s: ink line %d names a joint it does not have", prefix.c_str(), l);
        tinygltf::Primitive prim;
        w.skinned_attributes(prim, ln->point_count, ln->rest, ln->joints, ln->weights);
        prim.mode = TINYGLTF_MODE_LINE_STRIP;
        tinygltf::Material mat;
        mat.name = "sp_ink";
        mat.pbrMetallicRoughness.metallicFactor = 0.0;
        mat.pbrMetallicRoughness.roughnessFactor = 1.0;
        for (int c = 0; c < 4; ++c)
            mat.pbrMetallicRoughness.baseColorFactor[(size_t)c] =
                std::isfinite(ln->color[c]) ? std::min(1.0, std::max(0.0, (double)ln->color[c])) : 0.0;
        m.materials.push_back(mat);
        prim.material = (int)m.materials.size() - 1;
        add_skinned_node(m, scene, prim, prefix + "ink" + std::to_string(l), prefix + "ink" + std::to_string(l), skin_index,
                         Value());
    }
}

// Abstractions: a node per curve, skinned by the rig's skin.
void write_abstractions(Writer& w, tinygltf::Scene& scene, const sp_rig* rig, int skin_index, const std::string& prefix)
{
    tinygltf::Model& m = w.m;
    for (int a = 0; a < rig->abstraction_count; ++a) {
        const sp_abstraction* ab = &rig->abstractions[a];
        std::vector<double> er;
        std::vector<uint16_t> ej;
        std::vector<float> ew;
        const double* rest = ab->rest;
        const uint16_t* joints = ab->joints;
        const float* weights = ab->weights;
        if (!rest) {
            embedded_to_skinned(rig, ab, er, ej, ew);
            rest = er.data(), joints = ej.data(), weights = ew.data();
        }
        for (int c = 0; c < ab->curve_count; ++c) {
            const sp_curve* cv = &ab->curves[c];
            tinygltf::Primitive prim;
            size_t f = (size_t)cv->first_point;
            w.skinned_attributes(prim, cv->point_count, rest + 3 * f, joints + 4 * f, weights + 4 * f);
            prim.mode = cv->closed ? TINYGLTF_MODE_LINE_LOOP : TINYGLTF_MODE_LINE_STRIP;
            Value::Object ex;
            ex["sp_abstraction"] = Value(std::string(ab->name));
            ex["sp_curve"] = Value(std::string(cv->name));
            ex["sp_correspondence"] = Value(std::string(ab->correspondence == SP_CORR_CLOSEST ? "closest" : "ordered"));
            std::string name = prefix + ab->name + "/" + cv->name;
            add_skinned_node(m, scene, prim, name, name, skin_index, Value(std::move(ex)));
        }
    }
}

// One sampler and channel per animation channel; targets are joint nodes `base + joint`.
void write_channels(Writer& w, const sp_animation* an, int base, tinygltf::Animation& out)
{
    for (int c = 0; c < an->channel_count; ++c) {
        const sp_anim_channel* ac = &an->channels[c];
        if (ac->key_count < 1) continue;
        int comps = ac->path == SP_ANIM_ROTATION ? 4 : 3;
        size_t per = ac->interp == SP_INTERP_CUBICSPLINE ? 3 : 1;
        size_t nvals = (size_t)ac->key_count * per * (size_t)comps;
        std::vector<float> vals(ac->values, ac->values + nvals);
        if (comps == 4 && per == 1)
            for (size_t k = 0; k < (size_t)ac->key_count; ++k) {
                sp_quat q = sp_quat_norm(sp_quat{vals[4 * k], vals[4 * k + 1], vals[4 * k + 2], vals[4 * k + 3]});
                vals[4 * k] = (float)q.x, vals[4 * k + 1] = (float)q.y, vals[4 * k + 2] = (float)q.z,
                         vals[4 * k + 3] = (float)q.w;
            }
        tinygltf::AnimationSampler s;
        s.input = w.accessor(ac->times, (size_t)ac->key_count, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_SCALAR, 0, true);
        s.output = w.accessor(vals.data(), (size_t)ac->key_count * per, TINYGLTF_COMPONENT_TYPE_FLOAT,
                              comps == 4 ? TINYGLTF_TYPE_VEC4 : TINYGLTF_TYPE_VEC3, 0);
        s.interpolation = ac->interp == SP_INTERP_STEP ? "STEP" : ac->interp == SP_INTERP_CUBICSPLINE ? "CUBICSPLINE" : "LINEAR";
        out.samplers.push_back(s);
        tinygltf::AnimationChannel ch2;
        ch2.sampler = (int)out.samplers.size() - 1;
        ch2.target_node = base + ac->joint;
        ch2.target_path = ac->path == SP_ANIM_TRANSLATION ? "translation" : ac->path == SP_ANIM_ROTATION ? "rotation" : "scale";
        out.channels.push_back(ch2);
    }
}

// A camera node in the scene (its world matrix is the inverse of the view),
// with the canvas and principal point as extras. Why the size check: a
// camera framing float-range coordinates cannot be written back; nothing
// is written then (an importer frames the rest pose itself).
void write_camera(tinygltf::Model& m, tinygltf::Scene& scene, const sp_camera& cam, const char* node_name)
{
    sp_mat4 world;
    bool ok = cam.scale > 0 && cam.width > 0 && cam.height > 0 && sp_mat4_inverse(&cam.view, &world);
    for (int k = 0; ok && k < 16; ++k)
        ok = std::fabs(world.m[k]) < 1e30;
    if (!ok) return;
    tinygltf::Camera c;
    if (cam.kind == SP_CAMERA_ORTHOGRAPHIC) {
        c.type = "orthographic";
        c.orthographic.xmag = 0.5 * cam.width / cam.scale;
        c.orthographic.ymag = 0.5 * cam.height / cam.scale;
        c.orthographic.znear = cam.znear > 0 ? cam.znear : 0.0;
        c.orthographic.zfar = cam.zfar > c.orthographic.znear ? cam.zfar : c.orthographic.znear + 1.0;
    } else {
        c.type = "perspective";
        c.perspective.yfov = 2.0 * std::atan(0.5 * cam.height / cam.scale);
        c.perspective.aspectRatio = (double)cam.width / cam.height;
        c.perspective.znear = cam.znear > 0 ? cam.znear : 1e-3;
        c.perspective.zfar = cam.zfar > c.perspective.znear ? cam.zfar : c.perspective.znear * 1e4;
    }
    Value::Object ex;
    double canvas[2] = {(double)cam.width, (double)cam.height}, pp[2] = {cam.cx, cam.cy};
    ex["sp_canvas"] = num_array(canvas, 2);
    ex["sp_principal"] = num_array(pp, 2);
    c.extras = Value(std::move(ex));
    m.cameras.push_back(c);
    Trs t = decompose(world);
    tinygltf::Node nd;
    nd.name = node_name;
    nd.camera = (int)m.cameras.size() - 1;
    nd.translation = {t.t.x, t.t.y, t.t.z};
    nd.rotation = {t.r.x, t.r.y, t.r.z, t.r.w};
    scene.nodes.push_back((int)m.nodes.size());
    m.nodes.push_back(nd);
}

tinygltf::Model build_model(const sp_character* ch, const double* params_in)
{
    const sp_rig* rig = &ch->rig;
    int J = rig->joint_count;
    std::vector<double> p((size_t)rig->param_count + 1);
    if (params_in)
        std::copy(params_in, params_in + rig->param_count, p.begin());
    else if (ch->pose)
        std::copy(ch->pose, ch->pose + rig->param_count, p.begin());
    else
        sp_rig_defaults(rig, p.data());
    sp_rig_clamp(rig, p.data());

    Writer w;
    tinygltf::Model& m = w.m;
    // Joint nodes 0..J-1 in rig order, so node index = joint index.
    write_joint_nodes(w, rig, p.data(), "");
    tinygltf::Scene scene;
    for (int j = 0; j < J; ++j)
        if (rig->joints[j].parent < 0) scene.nodes.push_back(j);
    write_skin(w, rig, 0, "");
    write_mesh(w, scene, ch, 0, "character", "character_mesh");
    write_abstractions(w, scene, rig, 0, "");

    // Animations: one sampler per channel, targets are the joint nodes.
    for (int a = 0; a < rig->animation_count; ++a) {
        const sp_animation* an = &rig->animations[a];
        tinygltf::Animation out;
        out.name = an->name;
        write_channels(w, an, 0, out);
        // Why skip: an animation without channels is invalid glTF.
        if (!out.channels.empty()) m.animations.push_back(out);
    }

    write_camera(m, scene, ch->camera, "sketch_view");

    // Scene extras: the pose (exact values) and the part description.
    Value::Object params;
    for (int k = 0; k < rig->param_count; ++k)
        params[rig->params[k].name] = Value(p[(size_t)k]);
    Value::Object pose;
    pose["parameters"] = Value(std::move(params));
    Value::Object sx;
    // Why not always: tinygltf writes an empty object as null, which the loader
    // warns of; a rig without parameters (a baked black box) has no pose to keep.
    if (rig->param_count > 0) sx["sp_pose"] = Value(std::move(pose));
    if (ch->has_part) {
        cJSON* part = nullptr;
        sp_error e = {};
        sp_result r = sp_part_to_cjson(&ch->part, &part, &e);
        if (r != SP_OK) fail(r, "%s", e.text);
        std::unique_ptr<cJSON, void (*)(cJSON*)> owner(part, cJSON_Delete); // freed also when from_cjson throws
        sx["sp_part"] = from_cjson(part);
    }
    if (!sx.empty()) scene.extras = Value(std::move(sx)); // an empty object would be written as null
    scene.name = "sketchpose";
    m.scenes.push_back(scene);
    m.defaultScene = 0;
    return m;
}

// Several parts in one scene (sp_gltf_save_scene): per part a placement
// node over its joints, its own skin and mesh; one animation for everything.
tinygltf::Model build_scene(const sp_gltf_scene_desc* d)
{
    if (!d || d->part_count <= 0 || !d->parts) fail(SP_ERR_INVALID, "a scene needs at least one part");
    Writer w;
    tinygltf::Model& m = w.m;
    tinygltf::Scene scene;
    tinygltf::Animation anim;
    anim.name = d->animation_name ? d->animation_name : "animation";
    for (int i = 0; i < d->part_count; ++i) {
        const sp_gltf_scene_part* part = &d->parts[i];
        const sp_character* ch = part->character;
        if (!ch) fail(SP_ERR_INVALID, "part %d has no character", i);
        const sp_rig* rig = &ch->rig;
        std::string name = part->name ? std::string(part->name) : "part" + std::to_string(i);
        std::vector<double> p((size_t)rig->param_count + 1);
        if (part->params)
            std::copy(part->params, part->params + rig->param_count, p.begin());
        else if (ch->pose)
            std::copy(ch->pose, ch->pose + rig->param_count, p.begin());
        else
            sp_rig_defaults(rig, p.data());
        sp_rig_clamp(rig, p.data());
        // The placement node: a similarity, so that it is exactly a glTF TRS.
        Trs t = decompose(part->placement);
        double s = t.s.x;
        if (!(s > 0) || std::fabs(t.s.y - s) > 1e-6 * s || std::fabs(t.s.z - s) > 1e-6 * s)
            fail(SP_ERR_INVALID, "part %d (%s): the placement is not a rotation, uniform scale and translation", i, name.c_str());
        double all[10] = {t.t.x, t.t.y, t.t.z, t.r.x, t.r.y, t.r.z, t.r.w, s, s, s};
        for (double x : all)
            if (!(std::fabs(x) < 1e30)) fail(SP_ERR_INVALID, "part %d (%s): non-finite or huge placement", i, name.c_str());
        int place = (int)m.nodes.size();
        {
            tinygltf::Node nd;
            nd.name = name;
            nd.translation = {t.t.x, t.t.y, t.t.z};
            nd.rotation = {t.r.x, t.r.y, t.r.z, t.r.w};
            nd.scale = {s, s, s};
            m.nodes.push_back(nd);
            scene.nodes.push_back(place);
        }
        int base = (int)m.nodes.size();
        write_joint_nodes(w, rig, p.data(), name + "/");
        for (int j = 0; j < rig->joint_count; ++j)
            if (rig->joints[j].parent < 0) m.nodes[(size_t)place].children.push_back(base + j);
        int skin = write_skin(w, rig, base, name);
        m.skins[(size_t)skin].skeleton = place;
        write_mesh(w, scene, ch, skin, name + "/mesh", name + "/mesh");
        write_lines(w, scene, part, rig->joint_count, skin, name + "/");
        if (d->abstractions) write_abstractions(w, scene, rig, skin, name + "/");
        if (part->animation) write_channels(w, part->animation, base, anim);
        int nk = part->placement_key_count;
        if (nk > 0) {
            if (!part->placement_times || !part->placement_trs)
                fail(SP_ERR_INVALID, "part %d (%s): placement keys missing", i, name.c_str());
            std::vector<float> tt(3 * (size_t)nk), rr(4 * (size_t)nk), ss(3 * (size_t)nk);
            for (int k = 0; k < nk; ++k) {
                const float* v = part->placement_trs + 8 * (size_t)k;
                for (int c = 0; c < 8; ++c)
                    if (!std::isfinite(v[c])) fail(SP_ERR_INVALID, "part %d (%s): non-finite placement key", i, name.c_str());
                if (k > 0 && !(part->placement_times[k] > part->placement_times[k - 1]))
                    fail(SP_ERR_INVALID, "part %d (%s): placement key times must increase", i, name.c_str());
                sp_quat q = sp_quat_norm(sp_quat{v[3], v[4], v[5], v[6]});
                for (int c = 0; c < 3; ++c)
                    tt[3 * (size_t)k + (size_t)c] = v[c], ss[3 * (size_t)k + (size_t)c] = v[7];
                rr[4 * (size_t)k] = (float)q.x, rr[4 * (size_t)k + 1] = (float)q.y, rr[4 * (size_t)k + 2] = (float)q.z,
                       rr[4 * (size_t)k + 3] = (float)q.w;
            }
            int input =
                w.accessor(part->placement_times, (size_t)nk, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_SCALAR, 0, true);
            const std::vector<float>* outs[3] = {&tt, &rr, &ss};
            const char* paths[3] = {"translation", "rotation", "scale"};
            for (int c = 0; c < 3; ++c) {
                tinygltf::AnimationSampler smp;
                smp.input = input;
                smp.output = w.accessor(outs[c]->data(), (size_t)nk, TINYGLTF_COMPONENT_TYPE_FLOAT,
                                        c == 1 ? TINYGLTF_TYPE_VEC4 : TINYGLTF_TYPE_VEC3, 0);
                smp.interpolation = "LINEAR";
                anim.samplers.push_back(smp);
                tinygltf::AnimationChannel chn;
                chn.sampler = (int)anim.samplers.size() - 1;
                chn.target_node = place;
                chn.target_path = paths[c];
                anim.channels.push_back(chn);
            }
        }
    }
    // Why skip: an animation without channels is invalid glTF.
    if (!anim.channels.empty()) m.animations.push_back(anim);
    if (d->camera) write_camera(m, scene, *d->camera, "view");
    if (d->extras_json) {
        cJSON* ex = cJSON_Parse(d->extras_json);
        if (!ex || !cJSON_IsObject(ex)) {
            cJSON_Delete(ex);
            fail(SP_ERR_INVALID, "the scene extras are not a JSON object");
        }
        scene.extras = from_cjson(ex);
        cJSON_Delete(ex);
    }
    scene.name = "sketchpose";
    m.scenes.push_back(scene);
    m.defaultScene = 0;
    return m;
}

std::string serialize(const sp_character* ch, const double* params, bool binary)
{
    tinygltf::Model m = build_model(ch, params);
    tinygltf::TinyGLTF writer;
    std::ostringstream os;
    if (!writer.WriteGltfSceneToStream(&m, os, !binary, binary)) fail(SP_ERR_INTERNAL, "tinygltf could not serialise the model");
    return os.str();
}

// The exception firewall of the writers: every message starts with `what`, the file or "glb".
template <class Body> sp_result write_firewall(const char* what, sp_error* err, Body body)
{
    try {
        return body();
    } catch (const Failure& f) {
        return sp_fail(err, f.code, "%s: %s", what, f.text.c_str());
    } catch (const std::bad_alloc&) {
        return sp_fail(err, SP_ERR_NO_MEMORY, "%s: out of memory", what);
    } catch (...) {
        return sp_fail(err, SP_ERR_INTERNAL, "%s: internal error in the glTF writer", what);
    }
}

} // namespace

// The serialised file to disk, whole or not at all, with a one-line error naming it.
static sp_result write_file(const char* path, const std::string& bytes, sp_error* err)
{
    return sp_file_write(path, bytes.data(), bytes.size(), err);
}

extern "C" sp_result sp_gltf_save(const sp_character* ch, const double* params, const char* path, sp_error* err)
{
    return write_firewall(path, err, [&] {
        std::string bytes = serialize(ch, params, sp_path_ext_is(path, "glb"));
        return write_file(path, bytes, err);
    });
}

extern "C" sp_result sp_gltf_save_memory(const sp_character* ch, const double* params, void** data, size_t* size, sp_error* err)
{
    *data = nullptr;
    *size = 0;
    return write_firewall("glb", err, [&] {
        std::string bytes = serialize(ch, params, true);
        void* p = malloc(bytes.size());
        if (!p) throw std::bad_alloc();
        memcpy(p, bytes.data(), bytes.size());
        *data = p;
        *size = bytes.size();
        return SP_OK;
    });
}

extern "C" sp_result sp_gltf_save_scene(const sp_gltf_scene_desc* desc, const char* path, sp_error* err)
{
    return write_firewall(path, err, [&] {
        tinygltf::Model m = build_scene(desc);
        tinygltf::TinyGLTF writer;
        std::ostringstream os;
        bool binary = sp_path_ext_is(path, "glb");
        if (!writer.WriteGltfSceneToStream(&m, os, !binary, binary))
            fail(SP_ERR_INTERNAL, "tinygltf could not serialise the scene");
        std::string bytes = os.str();
        return write_file(path, bytes, err);
    });
}
