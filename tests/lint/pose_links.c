// pose_links: a program made of the posing commands alone (sp_pose_cmds).
// The lint test runs it (`pose --help` must work) and reads its dynamic
// dependencies: posing must not need OpenCV or SQLite.
#include "commands.h"

int main(void)
{
    char name[] = "pose", help[] = "--help";
    char* argv[] = {name, help, 0};
    return cmd_pose(2, argv);
}
