// model_load.c: reading a new model on a thread of its own (desc.background_model).
// A model is tens of megabytes: its checksum and parse held a kiosk's frame
// for 0.15-0.4 s on the default database. The thread reads through a
// read-only connection of its own; the pipeline goes on with the model it
// has and takes the new one at a poll.
#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#include "dragon_internal.h"

struct dragon_loader {
    pthread_t thread;
    atomic_bool done; // the fields below are the thread's until it is set
    char path[1024];
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
    l->r = sp_db_open(l->path, SP_DB_READONLY, &db, &err);
    if (l->r == SP_OK) {
        bool known = sp_db_model_head(db, &l->head, l->sha, &err) == SP_OK;
        l->r = sp_db_load_model(db, &l->clf, &l->id, &err);
        if (!known || l->id != l->head) l->sha[0] = 0; // the checksum is the model's own only when the rows agree
        sp_db_close(db);
    }
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
    atomic_init(&l->done, false);
    if (pthread_create(&l->thread, NULL, load_main, l) != 0) {
        free(l);
        return false;
    }
    d->loader = l;
    return true;
}

bool dragon_model_load_take(sp_dragon* d, bool wait)
{
    dragon_loader* l = d->loader;
    if (!l || (!wait && !atomic_load_explicit(&l->done, memory_order_acquire))) return false;
    pthread_join(l->thread, NULL);
    d->loader = NULL;
    bool taken = l->r == SP_OK;
    if (taken) {
        sp_clf_destroy(d->clf);
        d->clf = l->clf;
        d->model_id = l->id;
        snprintf(d->model_sha, sizeof d->model_sha, "%s", l->sha);
        d->model_error[0] = 0;
    } else if (l->r != SP_ERR_INVALID) {
        // Unreadable: the model in use stays, as a reload on the poll keeps it.
        sp_clf_destroy(l->clf);
    } else {
        // No model stored any more (a database replaced by one without): as the poll would.
        sp_clf_destroy(d->clf);
        d->clf = NULL, d->model_id = 0, d->model_sha[0] = 0;
        snprintf(d->model_error, sizeof d->model_error, "%s", l->error);
        taken = true;
    }
    free(l);
    return taken;
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
