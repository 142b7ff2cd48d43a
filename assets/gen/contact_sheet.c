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
    int cols = 2, n = 0;
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
    if (!out || n == 0 || cols < 1) {
        fprintf(stderr, "usage: sp-contact-sheet --out SHEET.png [--cols N] A.png B.png ...\n");
        return 2;
    }
    sp_image img[64], sheet = {0};
    memset(img, 0, sizeof img);
    sp_error err = {0};
    int rc = 0;
    for (int i = 0; i < n && rc == 0; ++i)
        if (sp_image_read_png(files[i], &img[i], &err) != SP_OK) {
            fprintf(stderr, "sp-contact-sheet: %s\n", err.text);
            rc = 1;
        }
    if (rc == 0 && sp_image_sheet(img, n, cols, 6, &sheet) != SP_OK) {
        fprintf(stderr, "sp-contact-sheet: the images differ in size (all must be %dx%d) or there is no memory\n", img[0].width,
                img[0].height);
        rc = 1;
    }
    if (rc == 0 && sp_image_write_png(&sheet, out, &err) != SP_OK) {
        fprintf(stderr, "sp-contact-sheet: %s\n", err.text);
        rc = 1;
    }
    for (int i = 0; i < n; ++i)
        sp_image_free(&img[i]);
    sp_image_free(&sheet);
    return rc;
}
