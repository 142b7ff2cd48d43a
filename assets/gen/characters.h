/// characters.h: the paper's characters for redraw posing (issue 4, item 2).
///
/// Both are built like the dragon parts (gen_mesh pieces, joints by pivot
/// and in-plane angle, a camera looking along -Z) but are whole characters:
/// no `sp_part` extras, a `stick` abstraction (a curve per bone chain,
/// ordered correspondences) and, for the cartoon man, an `outline` too.
///   - cartoon_man: faces +Z (the view along -Z is his front), big head,
///     hands and shoes, ~2.2k vertices, 91 parameters, clip `wave`.
///   - elephant: faces +X (the view along -Z is his side), a trunk, ears
///     and tusks, 49 joints, ~2k vertices, 132 parameters, clip `walk`.
#ifndef SP_CHARACTERS_H
#define SP_CHARACTERS_H

#include "sp/result.h"

/// Writes the cartoon man to `path` (.glb).
sp_result sp_character_cartoon_man(const char* path, sp_error* err);
/// Writes the elephant to `path` (.glb).
sp_result sp_character_elephant(const char* path, sp_error* err);

#endif
