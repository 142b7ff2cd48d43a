/// event.h: the kiosk's input as plain event structs (sokol's sapp_event style).
///
/// Every GLFW callback becomes one sp_kiosk_event; so does every line of a
/// recorded or scripted session. The UI state machine (ui.h) consumes only
/// these, never GLFW or GL, so that the whole flow can be tested, recorded
/// and replayed without a window.
///
///     sp_kiosk_event ev = {.type = SP_KEV_DOWN, .t_ms = 1200, .x = 640, .y = 400};
///     sp_kiosk_ui_event(ui, &ev);
#ifndef SP_KIOSK_EVENT_H
#define SP_KIOSK_EVENT_H

#include <stdbool.h>

/// What happened. A touch arrives as DOWN, MOVEs, UP (one finger = the
/// primary mouse button).
typedef enum sp_kiosk_event_type {
    SP_KEV_NONE = 0,
    SP_KEV_DOWN,   ///< a finger (primary button) touches at (x, y)
    SP_KEV_MOVE,   ///< the pointer moved to (x, y); ignored unless a finger is down (no hover)
    SP_KEV_UP,     ///< the finger lifts at (x, y)
    SP_KEV_CANCEL, ///< the pointer was lost (focus lost, device gone): ends what the finger did, activates nothing
    SP_KEV_PRESS,  ///< scripts only: a tap on the UI target `button` (an sp_kiosk_target), wherever the layout put it
    SP_KEV_FRAME,  ///< time passed with no input (timers, animation); never recorded
    SP_KEV_TYPE_COUNT
} sp_kiosk_event_type;

/// One input event.
typedef struct sp_kiosk_event {
    sp_kiosk_event_type type;
    double t_ms; ///< milliseconds since the session started; non-decreasing (a smaller value is taken as "now")
    float x, y;  ///< framebuffer pixels, origin top-left, y down (DOWN, MOVE, UP)
    int button;  ///< DOWN/UP/MOVE: mouse button, 0 = primary (others are ignored); PRESS: an sp_kiosk_target
} sp_kiosk_event;

/// "down", "move", ...; NULL for an invalid type.
const char* sp_kiosk_event_name(sp_kiosk_event_type t);
/// Parses an event name; SP_KEV_NONE when unknown.
sp_kiosk_event_type sp_kiosk_event_parse(const char* s);

#endif
