// model_load.c: reading a new model on a thread of its own (desc.background_model).
// A model is tens of megabytes: its checksum and parse held a kiosk's frame
// far past its budget (BENCHMARKS.md, "A new model while the kiosk runs").
// The thread reads through a read-only connection of its own; the pipeline
// goes on with the model it has and takes the new one at a poll.
#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#include "dragon_internal.h"
#include "sp/clock.h"

// A read that failed for a reason that may pass (the file briefly away,
// busy, no memory) is tried again this long after, at a poll.
enum { RETRY_MS = 30000 };

struct dragon_loader {
    pthread_t thread;
    atomic_bool done; // the fields below are the thread's until it is set
    char path[1024];
    dev_t dev; // the file the pipeline had open when the read began
    ino_t ino;
    bool same_file; // the path named that file before the read and after it
    bool opened;    // the database opened: SP_ERR_INVALID then means no model stored
    sp_clf* clf;
    int64_t id, head;
    char sha[65];
    sp_result r;
    char error[512];
};

static void* load_main(void* arg)
{
    dragon_loader* l = arg;
    sp_error err = {0};
    sp_db* db = NULL;
    dev_t dev;
    ino_t ino;
    l->same_file = dragon_file_id(l->path, &dev, &ino) && dev == l->dev && ino == l->ino;
    // A file renamed over the path is the poll's to open: it removes the old
    // file's WAL first, which a connection opened here would apply to the new file.
    // Waiting little for a lock: the poll that reopens a replaced file waits
    // for this read, and a read that fails is tried again later.
    l->r = l->same_file ? sp_db_open_wait(l->path, SP_DB_READONLY, 100, &db, &err)
                        : sp_fail(&err, SP_ERR_IO, "%s: the database file was replaced", l->path);
    l->opened = l->r == SP_OK;
    if (l->opened) {
        bool known = sp_db_model_head(db, &l->head, l->sha, &err) == SP_OK;
        l->r = sp_db_load_model(db, &l->clf, &l->id, &err);
        if (!known || l->id != l->head) l->sha[0] = 0; // the checksum is the model's own only when the rows agree
        sp_db_close(db);
    }
    l->same_file = l->same_file && dragon_file_id(l->path, &dev, &ino) && dev == l->dev && ino == l->ino;
    snprintf(l->error, sizeof l->error, "%s", l->r == SP_OK ? "" : err.text);
    atomic_store_explicit(&l->done, true, memory_order_release);
    return NULL;
}

bool dragon_model_load_start(sp_dragon* d)
{
    if (d->loader) return true; // one at a time: taking it checks the head again
    dragon_loader* l = calloc(1, sizeof *l);
    if (!l) return false;
    snprintf(l->path, sizeof l->path, "%s", d->db_path);
    l->dev = d->dev, l->ino = d->ino;
    atomic_init(&l->done, false);
    if (pthread_create(&l->thread, NULL, load_main, l) != 0) {
        free(l);
        return false;
    }
    d->loader = l;
    d->model_retry_at = 0;
    return true;
}

bool dragon_model_load_take(sp_dragon* d, bool wait)
{
    dragon_loader* l = d->loader;
    if (!l || (!wait && !atomic_load_explicit(&l->done, memory_order_acquire))) return false;
    pthread_join(l->thread, NULL);
    d->loader = NULL;
    bool taken = false;
    if (l->dev != d->dev || l->ino != d->ino) {
        // The pipeline reopened another file since (one renamed over it):
        // what was read may be the old file's model, of the same id as the new one's.
        sp_clf_destroy(l->clf);
        free(l);
        if (!wait && d->db) dragon_reload_model(d, false); // the checksums tell
        return false;
    }
    if (!l->same_file) {
        // The path named another file, or none, during the read: the poll
        // reopens a file renamed over it; one moved away and back is read again later.
        sp_clf_destroy(l->clf);
        free(l);
        d->model_retry_at = sp_now_ms() + RETRY_MS;
        return false;
    }
    if (l->r == SP_OK) {
        sp_clf_destroy(d->clf);
        d->clf = l->clf;
        d->model_id = l->id;
        snprintf(d->model_sha, sizeof d->model_sha, "%s", l->sha);
        d->model_error[0] = 0;
        taken = true;
    } else if (l->r == SP_ERR_INVALID && l->opened) {
        // No model stored any more (a database replaced by one without): as the poll would.
        sp_clf_destroy(d->clf);
        d->clf = NULL, d->model_id = 0, d->model_sha[0] = 0;
        snprintf(d->model_error, sizeof d->model_error, "%s", l->error);
        taken = true;
    } else {
        // Unreadable: the model in use stays, as a reload on the poll keeps
        // it. A stored model that does not parse stays so until a new one is
        // stored; anything else may pass, so it is read again later.
        sp_clf_destroy(l->clf);
        if (l->r != SP_ERR_PARSE) d->model_retry_at = sp_now_ms() + RETRY_MS;
    }
    free(l);
    return taken;
}

void dragon_model_retry(sp_dragon* d)
{
    if (d->loader || !(d->model_retry_at > 0) || sp_now_ms() < d->model_retry_at || !d->db) return;
    d->model_retry_at = 0;
    dragon_reload_model(d, true);
}

bool sp_dragon_model_loading(const sp_dragon* d)
{
    return d->loader != NULL;
}

bool sp_dragon_model_update(sp_dragon* d)
{
    if (!dragon_model_load_take(d, false)) return false;
    // A model stored while this one was read: read that too.
    if (d->db) dragon_reload_model(d, true);
    return true;
}
