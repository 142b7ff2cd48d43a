// kiosk_save.c: Save (a visitor's dragon as <code>.glb and <code>.png in the
// export folder), the disk it fills, and the old saves a museum lets go.
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/statvfs.h>
#include <time.h>
#include <unistd.h>

#include "kiosk_internal.h"
#include "sp/sketch_io.h"

// Save codes: four characters that read aloud unambiguously (no 0/O, 1/I, 2/Z, 5/S, 8/B).
static const char k_code_alphabet[] = "ACEFHJKLMNPRTUVWXY3479";

// Free space under a save this large (MB) is worth a line in the log: about
// 300 saves of a six-part dragon (6 MB each) before saves stop.
enum { SAVE_WARN_MB = 2048 };

// Codes tried before a save gives up: the folder nearly full of saves.
enum { CODE_TRIES = 1000 };

sp_result kiosk_claim_code(sp_kiosk* k, char code[8], sp_error* err)
{
    for (int attempt = 0; attempt < CODE_TRIES; ++attempt) {
        uint64_t z = (k->code_state += 0x9E3779B97F4A7C15ull);
        z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
        z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
        z ^= z >> 31;
        for (int i = 0; i < 4; ++i, z /= (sizeof k_code_alphabet - 1))
            code[i] = k_code_alphabet[z % (sizeof k_code_alphabet - 1)];
        code[4] = 0;
        char path[1200];
        snprintf(path, sizeof path, "%s/%s.glb", k->export_dir, code);
        // Made, not looked for: another kiosk saving into this folder (or a
        // code that was taken) gets EEXIST and the next code, never this one.
        int fd = open(path, O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
        if (fd < 0 && errno != EEXIST) return sp_fail(err, SP_ERR_IO, "%s: cannot create (%s)", path, strerror(errno));
        if (fd < 0) continue;
        close(fd);
        // A postcard kept without its .glb (staff moved the large files off
        // a full disk) still names an earlier visitor's dragon (a second
        // review: it was written over).
        char png[1200];
        snprintf(png, sizeof png, "%s/%s.png", k->export_dir, code);
        if (access(png, F_OK) != 0) return SP_OK;
        unlink(path);
    }
    // A code already given to a visitor is never given again (it named
    // their dragon): refused, not reused.
    return sp_fail(err, SP_ERR_IO,
                   "%s: no free save code in %d tries (the folder is nearly full of saves: move old ones away, or "
                   "--keep-saves-days)",
                   k->export_dir, CODE_TRIES);
}

static sp_result make_dirs(const char* dir, sp_error* err)
{
    char buf[1024];
    snprintf(buf, sizeof buf, "%s", dir);
    if (!buf[0]) return sp_fail(err, SP_ERR_INVALID, "the export folder is not named");
    for (char* p = buf + 1;; ++p) { // each folder on the way, then dir itself
        if (*p && *p != '/') continue;
        char c = *p;
        *p = 0;
        if (mkdir(buf, 0755) == 0)
            sp_path_sync_folder(buf); // a folder made for the saves survives a power cut with them
        else if (errno != EEXIST)
            return sp_fail(err, SP_ERR_IO, "%s: cannot create (%s)", buf, strerror(errno));
        if (!(*p = c)) return SP_OK;
    }
}

double kiosk_free_mb(const char* path)
{
    struct statvfs v;
    if (statvfs(path, &v) != 0) return -1;
    return (double)v.f_bavail * (double)v.f_frsize / (1024.0 * 1024.0);
}

// A save's name: a code of the alphabet and .glb or .png.
static bool is_save_name(const char* name)
{
    size_t n = strlen(name);
    if (n != 8 || (strcmp(name + 4, ".glb") && strcmp(name + 4, ".png"))) return false;
    for (int i = 0; i < 4; ++i)
        if (!name[i] || !strchr(k_code_alphabet, name[i])) return false;
    return true;
}

void kiosk_prune_saves(sp_kiosk* k)
{
    if (k->desc.keep_saves_days <= 0 || k->prune_held) return;
    char** names = NULL;
    int count = 0, removed = 0;
    sp_error err = {0};
    if (sp_dir_list(k->export_dir, &names, &count, &err) != SP_OK) return; // no folder yet: nothing saved
    time_t now = time(NULL), newest = 0, keep = (time_t)k->desc.keep_saves_days * 86400;
    time_t* when = malloc(sizeof(time_t) * (size_t)(count > 0 ? count : 1)); // a save's time, 0: not a save
    for (int i = 0; when && i < count; ++i) {
        char path[1200];
        snprintf(path, sizeof path, "%s/%s", k->export_dir, names[i]);
        struct stat st;
        // Anything else in the folder is staff's.
        when[i] = is_save_name(names[i]) && lstat(path, &st) == 0 && S_ISREG(st.st_mode) ? st.st_mtime : 0;
        if (when[i] > newest) newest = when[i];
    }
    // A clock past every save by more than the days kept, when the kiosk
    // starts, may be a clock set wrong (a flat RTC battery, no network time
    // yet), which removed every save, and the next Save's date the rest
    // (two outside reviews); a museum closed that long keeps its saves one
    // run more.
    if (when && !k->prune_checked) {
        k->prune_checked = true;
        k->prune_held = newest > 0 && now - newest > keep;
        if (k->prune_held)
            sp_kiosk_log("%s: the clock is %.0f days past the newest save: no save is removed until the kiosk restarts "
                         "(--keep-saves-days %d; is the clock right?)",
                         k->export_dir, (double)(now - newest) / 86400.0, k->desc.keep_saves_days);
    }
    for (int i = 0; when && !k->prune_held && i < count; ++i) {
        char path[1200];
        snprintf(path, sizeof path, "%s/%s", k->export_dir, names[i]);
        if (when[i] > 0 && when[i] < now - keep && unlink(path) == 0) ++removed;
    }
    free(when);
    sp_dir_list_free(names, count);
    if (removed > 0)
        sp_kiosk_log("%s: %d files of saves older than %d days removed (--keep-saves-days)", k->export_dir, removed,
                     k->desc.keep_saves_days);
}

// Whether the folder lies on the database's disk (or either cannot be
// looked at: then the reserve holds, as it did).
static bool on_db_disk(const sp_kiosk* k, const char* folder)
{
    struct stat a, b;
    return stat(folder, &a) != 0 || stat(k->db_path, &b) != 0 || a.st_dev == b.st_dev;
}

void kiosk_run_save(sp_kiosk* k)
{
    sp_error err = {0};
    char code[8] = "", glb[1200] = "", png[1200] = "";
    sp_image img = {0};
    // Each file is written whole (sp_file_write): a visitor's code never names half a file.
    // Through a link to a folder not made yet, its target is made (the
    // link's own name exists, and its files could not be made).
    char* real = sp_path_follow_links(k->export_dir);
    sp_result r = make_dirs(real ? real : k->export_dir, &err);
    free(real);
    // The last of the database's disk is the database's: a visitor's strokes,
    // a curator's training. Saves on a disk of their own (a small USB stick)
    // keep nothing back for it: they were never made there.
    double reserve = k->desc.save_reserve_mb == 0 ? SP_KIOSK_SAVE_RESERVE_MB : k->desc.save_reserve_mb, left = -1;
    if (r == SP_OK && reserve > 0 && on_db_disk(k, k->export_dir) && (left = kiosk_free_mb(k->export_dir)) >= 0 && left < reserve)
        r = sp_fail(&err, SP_ERR_IO,
                    "%s: %.0f MB free on its disk, under the %.0f MB kept for the database: not saved (move old saves away, or "
                    "--keep-saves-days)",
                    k->export_dir, left, reserve);
    bool claimed = r == SP_OK && (r = kiosk_claim_code(k, code, &err)) == SP_OK;
    snprintf(glb, sizeof glb, "%s/%s.glb", k->export_dir, code);
    snprintf(png, sizeof png, "%s/%s.png", k->export_dir, code);
    if (r == SP_OK) r = sp_dragon_export(k->dragon, glb, &err);
    if (r == SP_OK) {
        // The export evaluates poses of its own: pose the dragon again for the picture.
        r = sp_dragon_pose_at(k->dragon, k->ui->anim_ms / 1000.0, &err);
        k->posed = false;
        if (r == SP_OK) r = kiosk_postcard(k, code, &img, &err);
        if (r == SP_OK) r = sp_image_write_png(&img, png, &err);
    }
    if (r != SP_OK && claimed) unlink(glb); // the visitor gets no code, so no file may carry it
    sp_image_free(&img);
    if (r == SP_OK) {
        ++k->stats.saves;
        snprintf(k->last_save, sizeof k->last_save, "%s/%s", k->export_dir, code);
        sp_kiosk_ui_saved(k->ui, true, code);
        kiosk_prune_saves(k);
        struct stat a, b;
        double mb = stat(glb, &a) == 0 && stat(png, &b) == 0 ? (double)(a.st_size + b.st_size) / (1024.0 * 1024.0) : 0;
        if ((left = kiosk_free_mb(k->export_dir)) >= 0 && left < SAVE_WARN_MB)
            sp_kiosk_log("%s: %.0f MB free on its disk; this save took %.1f MB, and saves stop under %.0f MB", k->export_dir,
                         left, mb, reserve > 0 ? reserve : 0.0);
    } else {
        ++k->stats.save_failures;
        sp_kiosk_log("save: %s", err.text);
        sp_kiosk_ui_saved(k->ui, false, NULL);
    }
}
