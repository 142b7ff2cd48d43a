// sketchpose: the command line. Dispatches to cmd_<name>() (commands.h).
#include <stdio.h>
#include <string.h>

#include "commands.h"

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

int main(int argc, char** argv)
{
    if (argc < 2) {
        usage(stderr);
        return 2;
    }
    if (!strcmp(argv[1], "--help") || !strcmp(argv[1], "-h") || !strcmp(argv[1], "help")) {
        usage(stdout);
        return 0;
    }
    for (size_t i = 0; i < sizeof k_commands / sizeof k_commands[0]; ++i)
        if (!strcmp(argv[1], k_commands[i].name)) return k_commands[i].run(argc - 1, argv + 1);
    fprintf(stderr, "sketchpose: unknown command '%s' (try sketchpose --help)\n", argv[1]);
    return 2;
}
