/// commands.h: the sketchpose subcommands, one X-macro line each.
/// Each `cmd_<name>(argc, argv)` lives in cmd_<name>.c, gets argv with the
/// subcommand name at argv[0], and returns the process exit code:
/// 0 success, 1 bad input, 2 bad usage (DESIGN.md).
#ifndef SP_COMMANDS_H
#define SP_COMMANDS_H

#define SP_COMMANDS(X)                                                                                                           \
    X(inspect, "print a rig's joints, parameters, abstractions and warnings as JSON")                                            \
    X(render, "render a rig (posed) with an abstraction overlaid to PNG")                                                        \
    X(export, "write a rig posed by a pose file as .glb or .gltf")                                                               \
    X(train, "train a sketch classifier on a labelled folder")                                                                   \
    X(eval, "classifier accuracy (top-1/top-3, recall, confusion), cross-validation")                                            \
    X(classify, "classify one drawing with a trained model; ranked JSON")                                                        \
    X(synth, "strokes of a random pose within bounds (tests, training)")                                                         \
    X(pose, "redraw posing: fit the rig to strokes; posed .glb, PNG, report")                                                    \
    X(drawover, "draw-over posing: curves drawn over the character, then redrawn")                                               \
    X(animate, "key poses from stroke files, solved in sequence, as one glTF animation")                                         \
    X(demo, "headless demo: the kiosk without a window; hand-drawn parts in, an animated dragon (.glb, PNG, report) out")        \
    X(dragon, "the kiosk pipeline without a window: one part per stroke; animated .glb, PNG, report")                            \
    X(derive, "a kiosk part (outline, parameters, attachment, clip) from any rigged glTF; .glb, preview PNG")                    \
    X(db, "the curators' part database: init, add-part, add-sketch, list, show, remove, check, train, export, log, review")

#define SP_DECLARE_CMD(name, help) int cmd_##name(int argc, char** argv);
SP_COMMANDS(SP_DECLARE_CMD)
#undef SP_DECLARE_CMD

/// The part database at `path` is about to be built from `assets` by the
/// default recipe (`demo` and `dragon` on a first run, a minute or so): one
/// line on stderr, and a note when the people's strokes are not there to go in.
void announce_db_build(const char* path, const char* assets);

#endif
