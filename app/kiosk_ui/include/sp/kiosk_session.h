/// session.h: recorded and scripted kiosk sessions (JSON), for --record and --script.
///
/// The file (one event a line when written by the kiosk):
///
///     {"format": "sketchpose-kiosk-session", "version": 1,
///      "canvas": [1280, 800], "px_per_mm": 3.78, "coords": "pixels", "end_ms": 5200,
///      "events": [
///       {"t": 0, "type": "down", "x": 400, "y": 300},
///       {"t": 16, "type": "move", "x": 410, "y": 302},
///       {"t": 40, "type": "up", "x": 420, "y": 305},
///       {"t": 900, "type": "press", "target": "play"},
///       {"t": 1000, "type": "stroke", "dt": 8, "points": [[x, y], ...]},
///       {"t": 1300, "type": "mark", "name": "flash"}]}
///
/// `t` is milliseconds since the session started, non-decreasing. "stroke" is
/// shorthand for a down, moves `dt` ms apart (default 8) and an up. "press"
/// taps a UI target by name wherever the current layout put it (scripts
/// written without knowing the screen). "mark" names a moment: the replay
/// saves a screenshot there (beside --screenshot, "-<name>" added to its
/// name); names are 1-32 of [A-Za-z0-9_-]. `coords` "unit" means x, y are
/// fractions of the framebuffer; "pixels" (default) are scaled from `canvas`
/// to the framebuffer when they differ, by one scale for both axes with the
/// canvas centred, so that drawings keep their shape on a screen of another
/// shape. `end_ms` (default: the last event's
/// time) is when the replay stops and takes its screenshot and export.
#ifndef SP_KIOSK_SESSION_H
#define SP_KIOSK_SESSION_H

#include <stdbool.h>
#include <stddef.h>

#include "sp/kiosk_event.h"
#include "sp/result.h"

/// Largest "canvas" side, pixels: the kiosk's --size limit (a bigger window
/// the X server refuses).
#define SP_KIOSK_SESSION_MAX_CANVAS 8192
/// Latest event time and "end_ms" of a session, ms (1 hour): a replay runs
/// 60 frames per virtual second, so this keeps one within minutes.
#define SP_KIOSK_SESSION_MAX_MS 3600000.0

/// Most events one session may hold (after expanding "stroke" shorthands).
#define SP_KIOSK_SESSION_MAX_EVENTS 20000000

/// A named moment of a scripted session.
typedef struct sp_kiosk_mark {
    double t_ms;
    char name[33];
} sp_kiosk_mark;

typedef struct sp_kiosk_session {
    int canvas_w, canvas_h; ///< framebuffer size the coordinates refer to (0: unknown = the replay's)
    double px_per_mm;       ///< the recording screen's density (0: unknown)
    bool unit_coords;       ///< x, y are fractions of the framebuffer
    double end_ms;          ///< replay ends here (>= the last event's t)
    int count, cap;
    sp_kiosk_event* events; ///< count events, t non-decreasing
    int mark_count;
    sp_kiosk_mark* marks; ///< mark_count, t non-decreasing (scripts only; never recorded)
} sp_kiosk_session;

/// Parses a session document of `len` bytes; `name` is used in messages.
/// Every error names the file and the event, e.g. "s.json: events[12]: unknown type \"tap\"".
sp_result sp_kiosk_session_parse(const char* text, size_t len, const char* name, sp_kiosk_session* out, sp_error* err);
/// Reads a session file.
sp_result sp_kiosk_session_read(const char* path, sp_kiosk_session* out, sp_error* err);
/// Writes a session (one event a line). FRAME events are skipped.
sp_result sp_kiosk_session_write(const char* path, const sp_kiosk_session* s, sp_error* err);
/// Appends one event (copied); SP_ERR_NO_MEMORY or SP_ERR_INVALID (the session is full).
sp_result sp_kiosk_session_append(sp_kiosk_session* s, const sp_kiosk_event* ev);
/// Frees the events and zeroes the session.
void sp_kiosk_session_free(sp_kiosk_session* s);
/// An event of the session in the coordinates of a fb_w x fb_h framebuffer.
sp_kiosk_event sp_kiosk_session_map(const sp_kiosk_session* s, const sp_kiosk_event* ev, int fb_w, int fb_h);

#endif
