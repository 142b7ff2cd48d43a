/// sp/result.h: the result enum and error message shared by every module.
///
/// Fallible calls return an `sp_result` and, when they fail, write one line
/// into an `sp_error` that names the file (if any) and the problem, e.g.
/// "CesiumMan.glb: accessor 7 reads past the end of buffer 0". Callers print
/// `err.text` as is. Contract violations (NULL where a pointer is required)
/// are asserts, not results.
#ifndef SP_RESULT_H
#define SP_RESULT_H

#include <stdarg.h>
#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef enum sp_result {
    SP_OK = 0,
    SP_ERR_IO,          ///< a file could not be opened, read or written
    SP_ERR_PARSE,       ///< the bytes are not the format they claim to be
    SP_ERR_INVALID,     ///< well-formed but semantically wrong (bad index, NaN, cycle, ...)
    SP_ERR_UNSUPPORTED, ///< valid but outside what we handle
    SP_ERR_NO_MEMORY,   ///< an allocation failed
    SP_ERR_BUSY,        ///< a resource (database) is held by someone else
    SP_ERR_INTERNAL,    ///< a bug or an exception from a library
    SP_ERR_TIMEOUT,     ///< a time cap ran out before the work was done
} sp_result;

/// One-line error message. Zero-initialise before use.
typedef struct sp_error {
    char text[512];
} sp_error;

/// printf into err->text (if err is not NULL) and return `code`, so that
/// `return sp_fail(err, SP_ERR_PARSE, "%s: bad header", path);` reads well.
sp_result sp_fail(sp_error* err, sp_result code, const char* fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

/// The longest line sp_text_escape_controls writes, its end included: room
/// for two paths of PATH_MAX's 4096 bytes is not needed, one is.
#define SP_TEXT_LINE_MAX 4096

/// Rewrites text s (a buffer of cap bytes) on one line: a newline as \n, a
/// tab as \t, any other control character as \xNN (a name from a file may
/// hold any), cut to fit (at most SP_TEXT_LINE_MAX - 1 bytes), a cut text
/// ending in "...". sp_fail does it to every message.
void sp_text_escape_controls(char* s, size_t cap);

/// vsnprintf, then sp_text_escape_controls, into buf (cap bytes): a message
/// on one line whatever it quotes (sp_fail's, the commands' and the kiosk
/// log's own lines); one too long for buf keeps its start and its end, "..."
/// for the middle left out (the end says what is wrong).
void sp_text_vline(char* buf, size_t cap, const char* fmt, va_list ap);

/// Short stable name of a result code, e.g. "parse error".
const char* sp_result_name(sp_result r);

#ifdef __cplusplus
}
#endif
#endif
