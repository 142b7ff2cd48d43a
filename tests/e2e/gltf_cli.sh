#!/bin/sh
# gltf_cli.sh SKETCHPOSE SRC_DIR WORK_DIR: `sketchpose inspect` and `export`
# on the hand-made fixtures in tests/e2e/data: JSON on stdout, exit codes
# 0/1/2, one-line errors naming the file, pose files good and bad.
set -u
SP="$1"
DATA="$2/tests/e2e/data"
WORK="$3/gltf_cli.$$"
mkdir -p "$WORK"
fails=0
. "$2/tests/e2e/checks.sh" # fail, expect, one_line_naming

expect 0 "$SP" inspect --help
grep -q -- "--rig" "$WORK/out" || fail "inspect --help does not mention --rig"
expect 2 "$SP" inspect
expect 2 "$SP" inspect --rig
expect 2 "$SP" inspect --rig x.gltf --bogus
expect 0 "$SP" export --help
expect 2 "$SP" export --rig "$DATA/two_bone.gltf"

expect 0 "$SP" inspect --rig "$DATA/two_bone_extras.gltf"
for key in '"vertices":	4' '"name":	"root.s"' '"group":	"shape"' '"name":	"outline"' '"correspondence":	"closest"' '"parent":	null' '"parent":	"root"' '"animations":' '"warnings":'; do
    grep -q "$key" "$WORK/out" || fail "inspect output lacks $key"
done
expect 0 "$SP" inspect --rig "$DATA/two_bone.gltf"
grep -q '"name":	"stick"' "$WORK/out" || fail "no derived stick abstraction"
grep -q '"name":	"tip.ry"' "$WORK/out" || fail "no derived rotation DOFs"
grep -q '"max":	2.0943951023931' "$WORK/out" || fail "derived DOF limit is not 120 degrees"

expect 1 "$SP" inspect --rig "$DATA/does_not_exist.gltf"
one_line_naming does_not_exist.gltf
printf '{"asset": {"version": "2.0"}, "nodes": [' >"$WORK/broken.gltf"
expect 1 "$SP" inspect --rig "$WORK/broken.gltf"
one_line_naming broken.gltf
printf 'glTF\002\000\000\000\377\377\000\000' >"$WORK/short.glb"
expect 1 "$SP" inspect --rig "$WORK/short.glb"
one_line_naming short.glb

# Export with a pose file; the export loads again.
printf '{"parameters": {"root.rz": 0.5, "root.s": 1.5, "tip.rx": -0.25}}\n' >"$WORK/pose.json"
expect 0 "$SP" export --rig "$DATA/two_bone_extras.gltf" --pose "$WORK/pose.json" --out "$WORK/posed.glb"
[ -s "$WORK/posed.glb" ] || fail "export wrote nothing"
expect 0 "$SP" inspect --rig "$WORK/posed.glb"
grep -q '"name":	"root.s"' "$WORK/out" || fail "the export lost root.s"
expect 0 "$SP" export --rig "$DATA/two_bone.gltf" --out "$WORK/plain.gltf"
expect 0 "$SP" inspect --rig "$WORK/plain.gltf"

# The file name says the format: anything but .glb or .gltf (either case) is
# bad usage, one line, and nothing is written (x.txt got glTF JSON before).
for bad in x.txt x.obj x.glb.bak noext; do
    expect 2 "$SP" export --rig "$DATA/two_bone_extras.gltf" --out "$WORK/$bad"
    one_line_naming "export: --out writes glTF: the file name must end in .glb or .gltf, got '.*$bad'"
    [ -e "$WORK/$bad" ] && fail "a refused export wrote $bad"
done
expect 0 "$SP" export --rig "$DATA/two_bone_extras.gltf" --out "$WORK/UPPER.GLB"
[ "$(head -c 4 "$WORK/UPPER.GLB")" = glTF ] || fail "--out UPPER.GLB is not a binary glTF"

# Bad pose files: exit 1, one line naming the file and the problem.
printf '{"parameters": {"root.nope": 1}}' >"$WORK/unknown.json"
expect 1 "$SP" export --rig "$DATA/two_bone_extras.gltf" --pose "$WORK/unknown.json" --out "$WORK/x.glb"
one_line_naming unknown.json
grep -q "root.nope" "$WORK/err" || fail "the error does not name the parameter"
printf '{"parameters": {"root.rz": NaN}}' >"$WORK/nan.json"
expect 1 "$SP" export --rig "$DATA/two_bone_extras.gltf" --pose "$WORK/nan.json" --out "$WORK/x.glb"
one_line_naming nan.json
printf '{"parameters": {"root.rz": 1e999}}' >"$WORK/inf.json"
expect 1 "$SP" export --rig "$DATA/two_bone_extras.gltf" --pose "$WORK/inf.json" --out "$WORK/x.glb"
one_line_naming inf.json
printf '{"parameters": {"root.rz": "up"}}' >"$WORK/str.json"
expect 1 "$SP" export --rig "$DATA/two_bone_extras.gltf" --pose "$WORK/str.json" --out "$WORK/x.glb"
one_line_naming str.json
# Out of bounds: clamped with a warning, still exit 0.
printf '{"parameters": {"root.rz": 7}}' >"$WORK/far.json"
expect 0 "$SP" export --rig "$DATA/two_bone_extras.gltf" --pose "$WORK/far.json" --out "$WORK/far.glb"
grep -q "clamped" "$WORK/err" || fail "no clamp warning on stderr"
grep -q '"clamped":1' "$WORK/out" || fail "export did not report the clamp"
expect 1 "$SP" export --rig "$DATA/two_bone_extras.gltf" --out "$WORK/no/such/dir/x.glb"
one_line_naming x.glb

rm -rf "$WORK"
if [ "$fails" -gt 0 ]; then
    echo "$fails checks failed"
    exit 1
fi
echo "all gltf CLI checks passed"
