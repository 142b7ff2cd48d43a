// sketchpose: the command line. Dispatches to cmd_<name>() (commands.h).
#include <errno.h>
#include <signal.h>
#include <stdio.h>
#include <string.h>

#include "cli.h"
#include "commands.h"
#include "sp/sketch_io.h"

typedef struct command {
    const char* name;
    const char* help;
    int (*run)(int argc, char** argv);
} command;

#define SP_CMD_ENTRY(name, help) {#name, help, cmd_##name},
static const command k_commands[] = {SP_COMMANDS(SP_CMD_ENTRY)};
#undef SP_CMD_ENTRY

static void usage(FILE* f)
{
    fprintf(f, "usage: sketchpose <command> [options]   (sketchpose <command> --help for details)\n\ncommands:\n");
    for (size_t i = 0; i < sizeof k_commands / sizeof k_commands[0]; ++i)
        fprintf(f, "  %-10s %s\n", k_commands[i].name, k_commands[i].help);
}

// The commands print their results on stdout: a write that failed (a full
// disk, a closed file) must not end as success. An earlier failure keeps its code.
static int finish(int rc)
{
    errno = 0;
    if (fflush(stdout) == 0 && !ferror(stdout)) return rc;
    int e = errno;
    const char* done = sp_cli_done_text();
    fprintf(stderr, "sketchpose: stdout: write error (%s)%s%s\n", e ? strerror(e) : "an earlier write failed",
            done[0] ? "; done all the same: " : "", done);
    return rc == SP_EXIT_OK ? SP_EXIT_INPUT : rc;
}

int main(int argc, char** argv)
{
    // Past a file-size limit (ulimit -f) a write fails with EFBIG, said in
    // one line, instead of the signal killing the command silently, even
    // after a database change was committed.
    signal(SIGXFSZ, SIG_IGN);
    if (argc < 2) {
        usage(stderr);
        return 2;
    }
    if (!strcmp(argv[1], "--help") || !strcmp(argv[1], "-h") || !strcmp(argv[1], "help")) {
        usage(stdout);
        return finish(SP_EXIT_OK);
    }
    for (size_t i = 0; i < sizeof k_commands / sizeof k_commands[0]; ++i)
        if (!strcmp(argv[1], k_commands[i].name)) return finish(k_commands[i].run(argc - 1, argv + 1));
    fprintf(stderr, "sketchpose: unknown command '%s' (try sketchpose --help)\n",
            sp_text_printable(argv[1], (char[160]){0}, 160));
    return 2;
}
