/// cli.h: option parsing shared by every sketchpose subcommand and the kiosk.
///
///     const char* rig = NULL; int size_w = 0;
///     sp_opt opts[] = {
///         {"--rig", SP_OPT_STRING, &rig, "R.gltf", "the rigged character", true},
///         ...};
///     int rc = sp_cli_parse(argc, argv, "sketchpose render", "render a rig", opts, n);
///     if (rc >= 0) return rc;   // --help (0) or bad usage (2), already reported
#ifndef SP_CLI_H
#define SP_CLI_H

#include <limits.h>
#include <stdbool.h>
#include <stdio.h>

typedef enum sp_opt_kind {
    SP_OPT_FLAG,    ///< bool*, no value
    SP_OPT_STRING,  ///< const char**
    SP_OPT_INT,     ///< int*
    SP_OPT_DOUBLE,  ///< double*
    SP_OPT_LIST,    ///< sp_str_list*: every value up to the next option
    SP_OPT_IN,      ///< const char**: a file the command reads
    SP_OPT_OUT,     ///< const char**: a file the command writes
    SP_OPT_IN_LIST, ///< sp_str_list*: files the command reads
} sp_opt_kind;

typedef struct sp_str_list {
    int count;
    const char* items[256];
} sp_str_list;

typedef struct sp_opt {
    const char* name;   ///< "--rig"
    sp_opt_kind kind;
    void* out;
    const char* arg;    ///< value placeholder for --help, e.g. "R.gltf"
    const char* help;
    bool required;
} sp_opt;

/// Parses argv[1..) against opts. Returns -1 when the command should run,
/// 0 after printing --help, 2 after printing a usage error to stderr.
/// It also refuses (one line, exit 2) an output that names the same file as
/// an input ("--report s.json is the same file as --strokes: it would be
/// overwritten") or as another output.
int sp_cli_parse(int argc, char** argv, const char* cmd, const char* summary, const sp_opt* opts, int nopts);
/// sp_cli_parse for a command that also takes positional arguments, shown in
/// --help's usage line after `cmd` ("FILES..."); messages start with `cmd` alone.
int sp_cli_parse_pos(int argc, char** argv, const char* cmd, const char* positional, const char* summary, const sp_opt* opts,
                     int nopts);

/// strtod of a decimal number only ([+-]digits[.digits][e[+-]digits]):
/// hexadecimal, inf and nan read nothing (*end = s). errno as strtod sets it.
double sp_cli_strtod(const char* s, char** end);

/// Parses "WxH" into two ints of 16..8192; false if malformed or out of range.
bool sp_cli_parse_size(const char* s, int* w, int* h);

/// Out-of-range check of a parsed option: true when lo <= v <= hi, else
/// prints "<cmd>: <name> must be lo..hi, got v" and returns false (exit 2).
bool sp_cli_check_int(const char* cmd, const char* name, int v, int lo, int hi);
/// The same for a number in [lo, hi], or (lo, hi] when lo_open.
bool sp_cli_check_double(const char* cmd, const char* name, double v, double lo, bool lo_open, double hi);

/// A name option's value (a category, a part name; NULL: not given): true
/// when it is a plain name as the part database takes it
/// (sp_part_name_is_plain), else prints "<cmd>: <name> wants a plain name
/// ..., got 'VALUE'" with the value escaped (sp_text_printable: a newline
/// or an escape code never reaches the terminal raw) and returns false (exit 2).
bool sp_cli_check_name(const char* cmd, const char* name, const char* value);

/// What an output file holds. The file name's extension says which, so a
/// command checks it before any work (sp_cli_check_out).
typedef enum sp_cli_out_kind {
    SP_CLI_OUT_GLTF,    ///< .glb (binary glTF) or .gltf (JSON, buffers embedded), either case
    SP_CLI_OUT_PNG,     ///< .png, either case
    SP_CLI_OUT_STROKES, ///< a stroke file (sketchpose-strokes JSON): .json, either case
} sp_cli_out_kind;

/// Usage check of an output option: NULL (not given) passes; a name that
/// does not end as `kind` wants prints "<cmd>: <name> writes glTF: the file
/// name must end in .glb or .gltf, got 'x.txt'" and returns false (exit 2,
/// nothing written), where the writer would have put glTF JSON into x.txt.
/// A path under /dev/ (/dev/stdout) or naming a FIFO or a device passes: it
/// is written into as it is (glTF as JSON unless it ends in .glb).
bool sp_cli_check_out(const char* cmd, const char* name, const char* path, sp_cli_out_kind kind);

/// True when an output path is written as a stream: under /dev/ or naming a
/// FIFO or a device (no file name, no folder to write beside it).
bool sp_cli_out_is_stream(const char* path);
/// True when an output named `path` is this process's stdout: "-",
/// /dev/stdout and its spellings, or the file stdout is redirected to. A
/// command that prints its report on stdout does not print it twice there.
bool sp_cli_out_is_stdout(const char* path);
/// True when any of the n outputs (NULL: none) is stdout (sp_cli_out_is_stdout):
/// the command then prints nothing else there, its JSON too (a glTF or a PNG
/// followed by a summary is a file no reader takes; --report has it).
bool sp_cli_stdout_taken(const char* const* outs, int n);
/// True, after one line naming both, when the output `out` would overwrite
/// the input `in` or a file the input reads (a glTF's external buffers and
/// images): for inputs that are not options (sp_cli_parse checks those).
bool sp_cli_out_is_input(const char* cmd, const char* out_name, const char* out, const char* in_name, const char* in);

/// One line on stderr, printf-style, its control characters escaped
/// (sp_text_escape_controls): for messages that quote a path or a name
/// someone typed (a newline in it split the line, an escape code drove the
/// terminal: an outside review). At most SP_TEXT_LINE_MAX - 1 bytes, ending
/// in "..." when cut.
void sp_cli_say(const char* fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 1, 2)))
#endif
    ;

/// For outputs written at the end of work (a solve, a kiosk session): NULL
/// and streams pass; otherwise the file's folder must exist and be writable
/// by this user, else "<cmd>: <name> <path>: cannot write into folder 'dir'
/// (reason)", and the path must not be a folder ("<cmd>: <name> <path>: is a
/// folder, not a file"); false (exit 1), said before the work, not after it.
bool sp_cli_check_out_folder(const char* cmd, const char* name, const char* path);

/// For a folder written into at the end of work and made then, parents and
/// all (the kiosk's --export-dir): it may be missing, but a file in its place
/// or on its way, links that go round in a loop, or a nearest existing
/// folder this user cannot make files in fail every write: "<cmd>: <name>
/// <dir>: <reason> (<purpose> there)", or "...: '<folder>' on its way:
/// <reason> (the folder is made and <purpose> there)"; false (exit 1).
bool sp_cli_check_folder_to_make(const char* cmd, const char* name, const char* dir, const char* purpose);

/// sp_cli_check_out_folder of every SP_OPT_OUT option given ("-" aside): a
/// command calls it after its usage checks (bad usage is said first, exit
/// 2) and before its work; false after saying why (exit 1).
bool sp_cli_check_out_folders(const char* cmd, const sp_opt* opts, int nopts);

/// The longest solve time cap a command takes (--max-ms), ms: one hour.
#define SP_CLI_MAX_MS 3600000.0
/// Its range as --help words it (beside SP_CLI_MAX_MS, so that they agree).
#define SP_CLI_MAX_MS_RANGE "ms in (0, 3600000]"
/// --max-ms of pose, drawover and dragon: NAN (not given) passes, else ms in
/// (0, SP_CLI_MAX_MS]; false after the usage line. One check, so that the
/// three commands say the same range.
bool sp_cli_check_max_ms(const char* cmd, double ms);

/// Says what a command has done that stays done (a database change
/// committed), for the error line of a later failure to write stdout: a
/// script that sees exit 1 must learn that the change is kept all the same.
void sp_cli_done(const char* fmt, ...);
/// What sp_cli_done said last ("" when nothing).
const char* sp_cli_done_text(void);

/// Prints `s` as one word a POSIX shell reads back as `s`: as it is when it
/// holds only [A-Za-z0-9_./=:,+-], else in single quotes (a quote as '\'').
/// For command lines printed to be pasted.
void sp_cli_print_shell_word(FILE* f, const char* s);

/// Initial value of an int option whose "not given" must differ from every
/// value a user can type (sp_cli_parse refuses INT_MIN).
#define SP_CLI_UNSET INT_MIN

/// Exit codes (DESIGN.md).
enum { SP_EXIT_OK = 0, SP_EXIT_INPUT = 1, SP_EXIT_USAGE = 2 };

#endif
