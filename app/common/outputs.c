#include "outputs.h"

#include <errno.h>
#include <pthread.h>
#include <signal.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "sp/sketch_io.h"

sp_result sp_outputs_stage(sp_outputs* o, const char* path, const char** write_to, sp_error* err)
{
    *write_to = path;
    if (!path) return SP_OK;
    if (o->count >= SP_OUTPUTS_MAX) return sp_fail(err, SP_ERR_INTERNAL, "%s: too many outputs for one command", path);
    if (!strcmp(path, "-")) return SP_OK;
    char* target = sp_path_follow_links(path);
    if (!target) return sp_fail(err, SP_ERR_IO, "%s: cannot follow its links (a loop, or out of memory)", path);
    struct stat st;
    if (sp_path_descriptor(target) >= 0 || (stat(target, &st) == 0 && !S_ISREG(st.st_mode))) {
        // A stream, written as it goes (a folder: the writer says so).
        free(target);
        return SP_OK;
    }
    // The extension of the name as given: a link "x.glb" to "model.gltf" is
    // written as the user asked for it, a .glb.
    const char* base = strrchr(path, '/');
    base = base ? base + 1 : path;
    const char* dot = strrchr(base, '.');
    const char* ext = dot && dot != base && strlen(dot) <= 16 ? dot : "";
    char* tmp = sp_path_temp_beside(target, ext);
    if (!tmp) {
        free(target);
        return sp_fail(err, SP_ERR_NO_MEMORY, "%s: out of memory", path);
    }
    o->paths[o->count] = path;
    o->staged[o->count] = tmp;
    o->target[o->count] = target;
    ++o->count;
    *write_to = tmp;
    return SP_OK;
}

static void forget_all(sp_outputs* o)
{
    for (int i = 0; i < o->count; ++i) {
        free(o->staged[i]);
        free(o->target[i]);
        o->staged[i] = o->target[i] = NULL;
    }
    o->count = 0;
}

sp_result sp_outputs_commit(sp_outputs* o, sp_error* err)
{
    // A ^C between two renames would leave a new output beside an old one
    // (synth's strokes beside another seed's truth): the signal waits.
    sigset_t hold, was;
    sigemptyset(&hold);
    sigaddset(&hold, SIGINT), sigaddset(&hold, SIGTERM), sigaddset(&hold, SIGHUP), sigaddset(&hold, SIGQUIT);
    pthread_sigmask(SIG_BLOCK, &hold, &was);
    char* backup[SP_OUTPUTS_MAX] = {0};
    bool existed[SP_OUTPUTS_MAX] = {0};
    sp_result r = SP_OK;
    int done = 0; // outputs put in place
    for (; done < o->count; ++done) {
        if (!o->staged[done]) continue;
        const char* target = o->target[done];
        struct stat st;
        existed[done] = lstat(target, &st) == 0;
        if (existed[done] && S_ISREG(st.st_mode)) {
            chmod(o->staged[done], st.st_mode & 07777); // a replaced file keeps its permissions
            // A hard link keeps the old file until every output is in place;
            // where the file system has none, that one cannot be put back.
            backup[done] = sp_path_temp_beside(target, ".old");
            if (backup[done] && link(target, backup[done]) != 0) free(backup[done]), backup[done] = NULL;
        }
        if (rename(o->staged[done], target) != 0) {
            r = sp_fail(err, SP_ERR_IO, "%s: cannot write (%s)", o->paths[done], strerror(errno));
            break;
        }
    }
    for (int i = 0; i < o->count; ++i) {
        if (!o->staged[i]) continue;
        if (r != SP_OK && i < done) { // put back what was put in place
            if (backup[i])
                rename(backup[i], o->target[i]);
            else if (!existed[i])
                unlink(o->target[i]);
        }
        if (r != SP_OK) unlink(o->staged[i]);
        if (backup[i]) unlink(backup[i]);
        free(backup[i]);
        sp_path_sync_folder(o->target[i]); // the new names (or the old ones back) survive a power cut
    }
    forget_all(o);
    pthread_sigmask(SIG_SETMASK, &was, NULL);
    return r;
}

void sp_outputs_undo(sp_outputs* o, sp_error* err)
{
    for (int i = 0; i < o->count; ++i) {
        if (!o->staged[i]) continue;
        unlink(o->staged[i]);
        if (!err) continue;
        // Rebuilt in a second buffer: the name given may be longer than the
        // staged one, and what does not fit is cut, never overrun.
        char said[sizeof err->text];
        size_t w = 0, cap = sizeof said - 1;
        const char* s = err->text;
        size_t sl = strlen(o->staged[i]), pl = strlen(o->paths[i]);
        for (const char* hit; (hit = strstr(s, o->staged[i])); s = hit + sl) {
            size_t k = (size_t)(hit - s);
            k = k < cap - w ? k : cap - w;
            memcpy(said + w, s, k), w += k;
            k = pl < cap - w ? pl : cap - w;
            memcpy(said + w, o->paths[i], k), w += k;
        }
        size_t k = strlen(s);
        k = k < cap - w ? k : cap - w;
        memcpy(said + w, s, k), w += k;
        said[w] = 0;
        memcpy(err->text, said, w + 1);
    }
    forget_all(o);
}
