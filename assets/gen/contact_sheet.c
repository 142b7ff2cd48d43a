// contact_sheet.c: sp-contact-sheet --out SHEET.png [--cols N] A.png B.png ...:
// lays equally sized renders out in a grid (row by row, 6 px gaps), for the
// asset previews under assets/previews/ (see previews.sh).
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sp/image.h"

int main(int argc, char** argv)
{
    const char* out = NULL;
    int cols = 2, first = 0, n = 0;
    const char* files[64];
    for (int i = 1; i < argc; ++i) {
        if (!strcmp(argv[i], "--out") && i + 1 < argc)
            out = argv[++i];
        else if (!strcmp(argv[i], "--cols") && i + 1 < argc)
            cols = atoi(argv[++i]);
        else if (argv[i][0] == '-') {
            fprintf(stderr, "usage: sp-contact-sheet --out SHEET.png [--cols N] A.png B.png ...\n");
            return 2;
        } else if (n < 64)
            files[n++] = argv[i];
    }
    (void)first;
    if (!out || n == 0 || cols < 1) {
        fprintf(stderr, "usage: sp-contact-sheet --out SHEET.png [--cols N] A.png B.png ...\n");
        return 2;
    }
    enum { GAP = 6 };
    sp_image sheet = {0}, img = {0};
    sp_error err = {0};
    int w = 0, h = 0, rows = (n + cols - 1) / cols, rc = 0;
    for (int i = 0; i < n && rc == 0; ++i) {
        if (sp_image_read_png(files[i], &img, &err) != SP_OK) {
            fprintf(stderr, "sp-contact-sheet: %s\n", err.text);
            rc = 1;
            break;
        }
        if (i == 0) {
            w = img.width, h = img.height;
            int sw = cols * w + (cols + 1) * GAP, sh = rows * h + (rows + 1) * GAP;
            if (sp_image_alloc(&sheet, sw, sh) != SP_OK) {
                fprintf(stderr, "sp-contact-sheet: out of memory\n");
                rc = 1;
                break;
            }
            for (size_t k = 0; k < (size_t)sw * (size_t)sh; ++k)
                memcpy(sheet.rgba + 4 * k, (const uint8_t[4]){250, 250, 250, 255}, 4);
        } else if (img.width != w || img.height != h) {
            fprintf(stderr, "sp-contact-sheet: %s is %dx%d, the first image %dx%d\n", files[i], img.width, img.height, w, h);
            rc = 1;
            break;
        }
        int ox = GAP + (i % cols) * (w + GAP), oy = GAP + (i / cols) * (h + GAP);
        for (int y = 0; y < h; ++y)
            memcpy(sp_image_at(&sheet, ox, oy + y), sp_image_at(&img, 0, y), 4 * (size_t)w);
    }
    if (rc == 0 && sp_image_write_png(&sheet, out, &err) != SP_OK) {
        fprintf(stderr, "sp-contact-sheet: %s\n", err.text);
        rc = 1;
    }
    sp_image_free(&img);
    sp_image_free(&sheet);
    return rc;
}
