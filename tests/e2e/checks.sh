# checks.sh: the checks the command-line scripts (gltf_cli.sh, posing_cli.sh,
# gltf_validate.sh) share; sourced after they set SRC, WORK (an existing
# folder) and fails=0.

fail() { echo "FAIL: $*"; fails=$((fails + 1)); }

# expect CODE CMD...: runs CMD, keeps stdout/stderr in $WORK/out, $WORK/err.
expect() {
    want="$1"
    shift
    "$@" >"$WORK/out" 2>"$WORK/err"
    got=$?
    [ "$got" = "$want" ] || fail "exit $got (wanted $want): $* -- $(head -c 300 "$WORK/err")"
}

# node_tools PKG: sets TOOLS to the npm test tools' folder (tests/tools, or
# $SP_TEST_TOOLS_DIR) and returns 0 when node and package PKG are installed
# there; returns 1 when not, after failing the script (exit 1) instead when
# SP_TEST_REQUIRE_TOOLS=1 (tools/sp test, which installs them, sets it): as
# fixtures.h's sp_fixture_node_tools.
node_tools() {
    TOOLS="${SP_TEST_TOOLS_DIR:-$SRC/tests/tools}"
    command -v node >/dev/null 2>&1 && [ -d "$TOOLS/node_modules/$1" ] && return 0
    if [ "${SP_TEST_REQUIRE_TOOLS:-}" = 1 ]; then
        echo "FAIL: node or $TOOLS/node_modules/$1 is not installed, and SP_TEST_REQUIRE_TOOLS=1: failing, not skipping"
        exit 1
    fi
    return 1
}

# one_line_naming NAME: stderr is one line that names NAME.
one_line_naming() {
    [ "$(wc -l <"$WORK/err")" -eq 1 ] || fail "stderr is not one line: $(cat "$WORK/err")"
    grep -q "$1" "$WORK/err" || fail "stderr does not name $1: $(cat "$WORK/err")"
}
