// blackbox_internal.h: the host's view of a black-box rig, shared by
// blackbox.c and the solver's model of it.
#ifndef SP_BLACKBOX_INTERNAL_H
#define SP_BLACKBOX_INTERNAL_H

#include <stddef.h>

#include "sp/blackbox.h"

struct sp_blackbox {
    // The rig's description and parameters as validated: a plugin that
    // changed its counts or functions afterwards would be read past its
    // arrays. What they point to (rest, triangles, curves) is the rig's.
    sp_blackbox_rig rig;
    sp_blackbox_param* desc_params;
    char what[512]; // names the rig in messages (the plugin's path)
    void (*on_destroy)(void* user); // after the rig's release (a plugin's dlclose), or NULL
    void* on_destroy_user;
    int P, n;       // parameters, vertices
    int abstraction_count;
    sp_abstraction* abs; // the abstractions as the solver's types (curves only)
    int* first;          // abstraction_count + 1: first point of each in evaluate()'s output
    int total;           // abstraction points in all
    sp_param* params;    // P: the parameters as the rig's type (names, bounds, defaults, groups)
    double diag;         // rest mesh bounding-box diagonal
};

// evaluate() with no clamping and no message: SP_ERR_INTERNAL when it
// returned non-zero (*rc), SP_ERR_INVALID for a non-finite output value
// (*bad: its index, vertices first, then abstraction values).
sp_result sp__blackbox_eval_raw(const sp_blackbox* bb, const double* p, double* x, double* z, int* rc, size_t* bad);
// The one-line message for a failed sp__blackbox_eval_raw; `where` says when.
sp_result sp__blackbox_eval_message(const sp_blackbox* bb, sp_result r, int rc, size_t bad, const char* where, sp_error* err);

#endif
