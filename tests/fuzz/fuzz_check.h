// fuzz_check.h: what every fuzz target asks of a refusal.
#ifndef SP_FUZZ_CHECK_H
#define SP_FUZZ_CHECK_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sp/result.h"

// Every refusal comes with a one-line message; a finding (abort) otherwise.
static inline void sp_fuzz_one_line(const sp_error* err)
{
    if (!err->text[0] || memchr(err->text, '\n', sizeof err->text)) {
        fprintf(stderr, "bad error message: \"%s\"\n", err->text);
        abort();
    }
}

#endif
