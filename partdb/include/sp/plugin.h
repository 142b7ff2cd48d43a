/// sp/plugin.h: a black-box rig from a plugin shared object (sp/blackbox.h's
/// ABI), as sp/gltf.h reads a skinned one from a glTF: the solver opens no file.
#ifndef SP_PLUGIN_H
#define SP_PLUGIN_H

#include "sp/blackbox.h"

/// dlopen()s a shared object, calls its SP_BLACKBOX_ENTRY and opens the
/// result (sp_blackbox_open); sp_blackbox_destroy unloads it. One-line
/// errors name the file: missing file, not a regular file, not a (complete)
/// shared object, missing entry symbol, entry returned NULL, wrong ABI
/// version or struct size, inconsistent counts, NaN or failing evaluation.
sp_result sp_blackbox_load_plugin(const char* path, sp_blackbox** out, sp_error* err);

#endif
