// blackbox_plugin.c: loading a black-box rig from a shared object with
// dlopen/dlsym of its one entry symbol (SP_BLACKBOX_ENTRY).
#include <dlfcn.h>
#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

#include "blackbox_internal.h"

void sp__blackbox_unload(void* dl)
{
    if (dl) dlclose(dl);
}

sp_result sp_blackbox_load_plugin(const char* path, sp_blackbox** out, sp_error* err)
{
    *out = NULL;
    struct stat st;
    if (stat(path, &st) != 0) return sp_fail(err, SP_ERR_IO, "%s: %s", path, strerror(errno));
    if (S_ISDIR(st.st_mode)) return sp_fail(err, SP_ERR_IO, "%s: is a directory, not a plugin", path);
    // A bare file name would make dlopen search the library path instead of
    // loading the file the user named.
    char local[4096];
    const char* file = path;
    if (!strchr(path, '/')) {
        snprintf(local, sizeof local, "./%s", path);
        file = local;
    }
    dlerror();
    void* dl = dlopen(file, RTLD_NOW | RTLD_LOCAL);
    if (!dl) {
        const char* why = dlerror();
        return sp_fail(err, SP_ERR_PARSE, "%s: cannot load it as a shared object (%s)", path, why ? why : "unknown reason");
    }
    dlerror();
    void* sym = dlsym(dl, SP_BLACKBOX_ENTRY);
    if (!sym) {
        dlclose(dl);
        return sp_fail(err, SP_ERR_INVALID, "%s: no symbol %s (not a sketchpose black-box plugin)", path, SP_BLACKBOX_ENTRY);
    }
    // ISO C has no cast from an object pointer to a function pointer; POSIX
    // guarantees the representation is the same.
    sp_blackbox_entry_fn entry;
    memcpy(&entry, &sym, sizeof entry);
    const sp_blackbox_rig* rig = entry();
    if (!rig) {
        dlclose(dl);
        return sp_fail(err, SP_ERR_INVALID, "%s: %s() returned no rig", path, SP_BLACKBOX_ENTRY);
    }
    sp_result r = sp_blackbox_open(rig, path, out, err);
    if (r != SP_OK) {
        dlclose(dl);
        return r;
    }
    (*out)->dl = dl;
    return SP_OK;
}
