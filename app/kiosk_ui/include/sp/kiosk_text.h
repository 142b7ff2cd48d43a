/// kiosk_text.h: every word a kiosk visitor reads, in one place.
///
/// How to use (the renderer and the UI state machine; tests read the same table):
///
///     char buf[SP_KIOSK_NAME_MAX];
///     sp_kiosk_part_name("torso", buf, sizeof buf);     // "Body": a part's name on chips, the parts row, ...
///     sp_kiosk_text(SP_KTEXT_PROMPT);                   // "Draw one part of your dragon in one line: ..."
///
/// A part has one name everywhere (chips, the refusal's parts row, prompts,
/// hints), chosen for a child: the category ids stored in files ("torso",
/// "hind_legs") stay as they are and are never shown. The sentences that
/// list parts use the same names, in lower case.
#ifndef SP_KIOSK_TEXT_H
#define SP_KIOSK_TEXT_H

#include <stddef.h>

/// Longest part name written by sp_kiosk_part_name (with its terminator).
enum { SP_KIOSK_NAME_MAX = 48 };

/// Writes the name a visitor sees for a category ("torso" -> "Body",
/// "hind_legs" -> "Back legs"; an unknown category is prettified:
/// "spiky_tail" -> "Spiky tail") and returns out. NULL or "" gives "".
const char* sp_kiosk_part_name(const char* category, char* out, size_t cap);

/// Where a category goes in the parts row (the attract screen's drawing
/// order: body, head, wings, tail, front legs, back legs); unknown
/// categories come after every known one (SP_KIOSK_PART_ORDER_UNKNOWN).
int sp_kiosk_part_order(const char* category);
enum { SP_KIOSK_PART_ORDER_UNKNOWN = 1000 };

/// The sentences.
typedef enum sp_kiosk_text_id {
    SP_KTEXT_TITLE,                 ///< the attract screen's title
    SP_KTEXT_ATTRACT,               ///< the attract screen's line under it (lists the parts)
    SP_KTEXT_TOUCH_TO_START,        ///< the attract screen's button
    SP_KTEXT_PROMPT,                ///< an empty canvas: what to do (lists the parts)
    SP_KTEXT_TAP,                   ///< a tap on the canvas (not a line)
    SP_KTEXT_NEED_PART,             ///< a button that needs a part, with none
    SP_KTEXT_REDRAW,                ///< Redraw armed
    SP_KTEXT_DRAW_AGAIN,            ///< Redraw tapped while a refused stroke is offered: it went
    SP_KTEXT_CONFIRM_CLEAR,         ///< Start over, first tap
    SP_KTEXT_TURN,                  ///< Turn mode
    SP_KTEXT_LABEL,                 ///< the label chip tapped
    SP_KTEXT_MORE,                  ///< the chip that opens the parts row for the last part
    SP_KTEXT_PICK_PART,             ///< the parts row opened for the last part
    SP_KTEXT_UNRECOGNISED,          ///< a refused stroke (its guesses and the parts row are offered)
    SP_KTEXT_UNRECOGNISED_NO_OFFER, ///< a refused stroke when nothing can be offered
    SP_KTEXT_TOO_SMALL,             ///< a refused stroke too small for a part
    SP_KTEXT_DETAIL,                ///< a small line drawn on a part: kept as a detail, its guesses and the parts row offered
    SP_KTEXT_TRICKY,                ///< no part could take the stroke's shape
    SP_KTEXT_NOT_READY,             ///< no model or no parts: staff needed
    SP_KTEXT_FULL,                  ///< the dragon has as many parts as it can take
    SP_KTEXT_REFIT_FAILED,          ///< a guess chip's part did not fit the stroke
    SP_KTEXT_WAITING,               ///< a part drawn while no body is on the canvas
    SP_KTEXT_NO_SURFACE,            ///< a part drawn at a body that cannot hold parts (it stays where drawn)
    SP_KTEXT_SAVED,                 ///< the save banner's first line, before the code
    SP_KTEXT_CODE_USE,              ///< the save banner's second line: what the code is for
    SP_KTEXT_SAVE_FAILED,           ///< saving failed
    SP_KTEXT_SAVING,                ///< Save tapped: shown while the dragon and its postcard are written
    SP_KTEXT_COUNTDOWN,             ///< under the idle countdown
    SP_KTEXT_LOADING,               ///< the first start, while the database is built
    SP_KTEXT_POSTCARD_TITLE,        ///< on the saved postcard
    SP_KTEXT_POSTCARD_CODE,         ///< on the saved postcard, before the code
    SP_KTEXT_BUTTON_UNDO,           ///< the toolbar's buttons, under their icons
    SP_KTEXT_BUTTON_REDRAW,
    SP_KTEXT_BUTTON_START_OVER,
    SP_KTEXT_BUTTON_SURE, ///< Start over asking for its second tap
    SP_KTEXT_BUTTON_PLAY,
    SP_KTEXT_BUTTON_PAUSE,
    SP_KTEXT_BUTTON_TURN,
    SP_KTEXT_BUTTON_DRAW, ///< Turn, while turning: back to drawing
    SP_KTEXT_BUTTON_SAVE,
    SP_KTEXT_COUNT
} sp_kiosk_text_id;

/// The sentence (never NULL; "" for an invalid id).
const char* sp_kiosk_text(sp_kiosk_text_id id);

#endif
