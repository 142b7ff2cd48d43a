#!/bin/sh
# gltf_validate.sh SKETCHPOSE SRC_DIR WORK_DIR [SHARED_DATA]: exports the
# hand-made fixtures (and the Khronos samples when ../shared/data exists),
# posed, and runs the Khronos glTF validator on each: 0 errors required.
# Exits 77 (CTest SKIP_RETURN_CODE) when node or tests/tools/node_modules is
# missing (run `npm ci` in tests/tools), 1 then under SP_TEST_REQUIRE_TOOLS=1.
set -u
SP="$1"
SRC="$2"
WORK="$3/gltf_validate.$$"
SHARED="${4:-}"
. "$SRC/tests/e2e/checks.sh" # node_tools
if ! node_tools gltf-validator; then
    echo "SKIP: node or $TOOLS/node_modules/gltf-validator is missing (run: cd tests/tools && npm ci)"
    exit 77
fi
mkdir -p "$WORK"
printf '{"parameters": {"root.rz": 0.5, "root.s": 1.5, "root.tx": 0.1, "tip.rx": -0.25}}\n' >"$WORK/pose.json"
fails=0
check() { # check RIG OUT [POSE]
    if [ -n "${3:-}" ]; then
        "$SP" export --rig "$1" --pose "$3" --out "$2" >/dev/null || { echo "FAIL: export $1"; fails=$((fails + 1)); return; }
    else
        "$SP" export --rig "$1" --out "$2" >/dev/null || { echo "FAIL: export $1"; fails=$((fails + 1)); return; }
    fi
    if node "$TOOLS/validate.js" "$2" >"$WORK/report.json"; then
        echo "ok   $(basename "$2"): 0 errors"
    else
        echo "FAIL: $(basename "$2") does not validate:"
        cat "$WORK/report.json"
        fails=$((fails + 1))
    fi
}
check "$SRC/tests/e2e/data/two_bone_extras.gltf" "$WORK/two_bone_extras.glb" "$WORK/pose.json"
check "$SRC/tests/e2e/data/two_bone_extras.gltf" "$WORK/two_bone_extras.gltf" "$WORK/pose.json"
check "$SRC/tests/e2e/data/two_bone.gltf" "$WORK/two_bone.glb"
if [ -n "$SHARED" ] && [ -d "$SHARED/gltf" ]; then
    check "$SHARED/gltf/CesiumMan/CesiumMan.glb" "$WORK/CesiumMan.glb"
    check "$SHARED/gltf/CesiumMan/glTF/CesiumMan.gltf" "$WORK/CesiumMan.gltf"
    check "$SHARED/gltf/RiggedFigure/RiggedFigure.glb" "$WORK/RiggedFigure.glb"
    check "$SHARED/gltf/RiggedSimple/RiggedSimple.glb" "$WORK/RiggedSimple.glb"
    check "$SHARED/gltf/SimpleSkin/SimpleSkin.gltf" "$WORK/SimpleSkin.glb"
else
    echo "note: ../shared/data absent, validated the hand-made fixtures only"
fi
rm -rf "$WORK"
[ "$fails" -eq 0 ] || exit 1
