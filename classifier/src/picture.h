/// picture.h (private): a small picture of where the line runs which way,
/// the whole drawing at once (after Ouyang and Davis 2009, "A visual
/// approach to sketched symbol recognition").
///
/// The drawing's strokes are resampled by arc length and placed around their
/// centroid, scaled by their spread (2.5 root-mean-square radii to each side),
/// on a 24 x 24 grid. Four planes keep, per cell, how close the line's
/// direction comes to 0, 45, 90 and 135 degrees; a fifth marks where strokes
/// start and end. The planes are blurred and halved to 12 x 12. Unlike the
/// bag of local features it keeps the layout of the whole drawing (a leg
/// pair's two uprights, a wing's scallops along one edge), and unlike the
/// shape descriptor it is not mirror-invariant: the mirrored picture is a
/// separate training example.
#ifndef SP_CLF_PICTURE_H
#define SP_CLF_PICTURE_H

#include <stdbool.h>

#include "sp/result.h"
#include "sp/sketch.h"

/// Values in a picture: 5 planes of 12 x 12 cells.
#define SP_PICTURE_DIM 720

/// The picture of a stroke drawing (pixels, y down), mirrored left-right when
/// `mirrored`. Fails with SP_ERR_INVALID on a drawing without points or with a
/// non-finite coordinate, SP_ERR_UNSUPPORTED beyond SP_SKETCH_MAX_POINTS
/// points; a dot is described as one.
sp_result sp_picture_describe(const sp_sketch* s, bool mirrored, float out[SP_PICTURE_DIM], sp_error* err);

#endif
