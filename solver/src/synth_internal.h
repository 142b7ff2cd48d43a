// synth_internal.h: the random pose rule (sp/synth.h, sp_synth_params), shared
// by skinned and black-box rigs so that both draw alike.
#ifndef SP_SYNTH_INTERNAL_H
#define SP_SYNTH_INTERNAL_H

#include <stdbool.h>
#include <stdint.h>

#include "sp/synth.h"

// The generator a pose of `seed` starts from.
sp_rng sp__synth_rng(uint64_t seed);
// One parameter's draw: an angle within +-amplitude of its default, a pose
// parameter the share amplitude / pi of its range either side of the
// default, any other its whole range (clamped to [min, max]).
double sp__synth_param(sp_rng* rng, double def, double min, double max, bool angle, bool pose, double amplitude);

#endif
