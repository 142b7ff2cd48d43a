// text.c: the kiosk's words (see kiosk_text.h). Part names are chosen for a
// child ("Body", not "Torso"; "Back legs", not "Hind legs"), and every
// sentence that names parts uses the same names.
#include "sp/kiosk_text.h"

#include <stdio.h>
#include <string.h>

// In the parts row's order (the attract screen draws them in this order too).
static const struct {
    const char* category;
    const char* name;
} k_parts[] = {
    {"torso", "Body"},          {"head", "Head"}, {"wings", "Wings"}, {"tail", "Tail"}, {"front_legs", "Front legs"},
    {"hind_legs", "Back legs"}, {"legs", "Legs"},
};
enum { PART_N = sizeof k_parts / sizeof k_parts[0] };

static const char* const k_text[SP_KTEXT_COUNT] = {
    [SP_KTEXT_TITLE] = "Draw a dragon!",
    [SP_KTEXT_ATTRACT] = "One line for each part: a body, a head, wings, a tail, legs",
    [SP_KTEXT_TOUCH_TO_START] = "Touch to start",
    [SP_KTEXT_PROMPT] = "Draw one part in one line: a body, a head, wings, a tail or legs",
    [SP_KTEXT_TAP] = "Press, draw one line, then lift your finger",
    [SP_KTEXT_NEED_PART] = "Draw a dragon part first",
    [SP_KTEXT_REDRAW] = "Draw the new part: it replaces the last one",
    [SP_KTEXT_DRAW_AGAIN] = "Draw it again, in one line",
    [SP_KTEXT_CONFIRM_CLEAR] = "Tap again to start over",
    [SP_KTEXT_TURN] = "Drag to turn your dragon. Tap Draw to draw again",
    [SP_KTEXT_LABEL] = "Not right? Tap another guess",
    [SP_KTEXT_MORE] = "Other?",
    [SP_KTEXT_PICK_PART] = "Tap the part you drew",
    [SP_KTEXT_UNRECOGNISED] = "Hmm, what is that? Tap the part you drew",
    [SP_KTEXT_UNRECOGNISED_NO_OFFER] = "Hmm, what is that? Try a body, a head, wings, a tail or legs",
    // The strokes it refuses are specks, spots and dashes alike: no advice on how to draw.
    [SP_KTEXT_TOO_SMALL] = "A bit bigger please!",
    [SP_KTEXT_DETAIL] = "Drawn on your dragon! Was it a new part? Tap it",
    [SP_KTEXT_TRICKY] = "That one was tricky. Try drawing it again",
    [SP_KTEXT_NOT_READY] = "This kiosk is not ready yet. Please ask a guide",
    [SP_KTEXT_FULL] = "What a dragon! Save it, or tap Undo or Start over",
    [SP_KTEXT_REFIT_FAILED] = "That part does not fit this line. Try another one",
    [SP_KTEXT_WAITING] = "Now draw a body next to your parts",
    [SP_KTEXT_NO_SURFACE] = "That body cannot hold parts: this one stays where you drew it",
    [SP_KTEXT_SAVED] = "Saved! Your code:",
    // True to what Save does: the .glb and the postcard are named by the
    // code in the kiosk's export folder, where staff find them.
    [SP_KTEXT_CODE_USE] = "Keep this code: a guide can find your dragon's postcard with it",
    [SP_KTEXT_SAVE_FAILED] = "Sorry, saving did not work. Please ask a guide",
    [SP_KTEXT_SAVING] = "Saving your dragon...",
    [SP_KTEXT_COUNTDOWN] = "Still drawing? Touch the screen",
    [SP_KTEXT_LOADING] = "Getting the dragon parts ready...",
    [SP_KTEXT_POSTCARD_TITLE] = "My dragon",
    [SP_KTEXT_POSTCARD_CODE] = "code",
    [SP_KTEXT_BUTTON_UNDO] = "Undo",
    [SP_KTEXT_BUTTON_REDRAW] = "Redraw",
    [SP_KTEXT_BUTTON_START_OVER] = "Start over",
    [SP_KTEXT_BUTTON_SURE] = "Sure?",
    [SP_KTEXT_BUTTON_PLAY] = "Play",
    [SP_KTEXT_BUTTON_PAUSE] = "Pause",
    [SP_KTEXT_BUTTON_TURN] = "Turn",
    [SP_KTEXT_BUTTON_DRAW] = "Draw",
    [SP_KTEXT_BUTTON_SAVE] = "Save",
};

const char* sp_kiosk_text(sp_kiosk_text_id id)
{
    return (int)id >= 0 && id < SP_KTEXT_COUNT && k_text[id] ? k_text[id] : "";
}

int sp_kiosk_part_order(const char* category)
{
    for (int i = 0; category && i < PART_N; ++i)
        if (!strcmp(category, k_parts[i].category)) return i;
    return SP_KIOSK_PART_ORDER_UNKNOWN;
}

const char* sp_kiosk_part_name(const char* category, char* out, size_t cap)
{
    if (cap == 0) return out;
    int i = sp_kiosk_part_order(category);
    snprintf(out, cap, "%s", i < PART_N ? k_parts[i].name : category ? category : "");
    if (i < PART_N) return out;
    // A curator's own category: "spiky_tail" -> "Spiky tail".
    for (char* c = out; *c; ++c)
        if (*c == '_' || *c == '-') *c = ' ';
    if (out[0] >= 'a' && out[0] <= 'z') out[0] = (char)(out[0] - 'a' + 'A');
    return out;
}
