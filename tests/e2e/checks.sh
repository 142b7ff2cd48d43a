# checks.sh: the checks the command-line scripts (gltf_cli.sh, posing_cli.sh)
# share; sourced after they set WORK (an existing folder) and fails=0.

fail() { echo "FAIL: $*"; fails=$((fails + 1)); }

# expect CODE CMD...: runs CMD, keeps stdout/stderr in $WORK/out, $WORK/err.
expect() {
    want="$1"
    shift
    "$@" >"$WORK/out" 2>"$WORK/err"
    got=$?
    [ "$got" = "$want" ] || fail "exit $got (wanted $want): $* -- $(head -c 300 "$WORK/err")"
}

# one_line_naming NAME: stderr is one line that names NAME.
one_line_naming() {
    [ "$(wc -l <"$WORK/err")" -eq 1 ] || fail "stderr is not one line: $(cat "$WORK/err")"
    grep -q "$1" "$WORK/err" || fail "stderr does not name $1: $(cat "$WORK/err")"
}
