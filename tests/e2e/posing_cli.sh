#!/bin/sh
# posing_cli.sh SKETCHPOSE SRC_DIR WORK_DIR [SHARED_DATA]: the posing
# commands (synth, pose, animate, drawover) from the command line: exit
# codes, machine-readable reports, bad strokes, draw-over's outputs, and the
# Khronos validator on an animate export when node and
# tests/tools/node_modules are there.
set -u
SP="$1"
SRC="$2"
WORK="$3/posing_cli.$$"
SHARED="${4:-}"
RIG="$SRC/tests/e2e/data/two_bone_extras.gltf"
mkdir -p "$WORK"
fails=0
. "$SRC/tests/e2e/checks.sh" # fail, expect, one_line_naming, node_tools
strokes() { # strokes FILE POINTS-JSON...: a stroke file with one stroke per argument
    f="$1"
    shift
    printf '{"format": "sketchpose-strokes", "version": 1, "canvas": [640, 480], "strokes": [' >"$f"
    sep=""
    for s in "$@"; do
        printf '%s{"points": %s}' "$sep" "$s" >>"$f"
        sep=", "
    done
    printf ']}\n' >>"$f"
}

for c in synth pose drawover animate; do
    expect 0 "$SP" "$c" --help
    expect 2 "$SP" "$c" --bogus
done
# Every option's help starts in one column, long names ("--representatives K") too.
"$SP" pose --help | awk '/^  --/ && (substr($0, 28, 1) != " " || substr($0, 29, 1) == " ") { bad = 1; print } END { exit bad }' >"$WORK/cols" ||
    fail "pose --help: option help out of its column: $(cat "$WORK/cols")"
expect 0 "$SP" synth --rig "$RIG" --seed 4 --out "$WORK/s.json" --truth "$WORK/t.json"
[ -s "$WORK/err" ] && fail "synth of a pose inside the view said: $(cat "$WORK/err")"
# A pose that carries the strokes off the canvas is written, and said.
echo '{"parameters": {"root.tx": 0.25, "root.s": 2, "root.rz": 1}}' >"$WORK/big.json"
expect 0 "$SP" synth --rig "$RIG" --pose "$WORK/big.json" --out "$WORK/off.json"
one_line_naming "off.json: 1 of 5 points lie outside the 640x480 canvas"
expect 0 "$SP" pose --rig "$RIG" --strokes "$WORK/s.json" --out "$WORK/posed.glb" --report "$WORK/r.json"
for key in '"ms"' '"iterations"' '"icp_rounds"' '"stopped"' '"energy_before"' '"energy_after"' '"mean_error_px"' '"max_error_px"' '"bbox_diagonal_px"' '"curves"' '"parameters"'; do
    grep -q "$key" "$WORK/r.json" || fail "report lacks $key"
done
grep -q '"stopped":' "$WORK/out" || fail "pose prints no report on stdout"
# A stick figure of the cartoon man with an arm up, drawn by hand (an
# outside tester's, tests/e2e/data): fitted with no note; the same with both
# legs drawn as one stroke leaves a leg curve far from its stroke at a small
# mean error, which the note names (it said nothing).
MAN="$SRC/assets/cartoon_man.glb"
expect 0 "$SP" pose --rig "$MAN" --strokes "$SRC/tests/e2e/data/man_arm_up.json" --report "$WORK/man.json"
grep -q '"note":	""' "$WORK/man.json" || fail "a clean stick figure got a note: $(grep '"note"' "$WORK/man.json")"
[ -s "$WORK/err" ] && fail "a clean stick figure said: $(cat "$WORK/err")"
expect 0 "$SP" pose --rig "$MAN" --strokes "$SRC/tests/e2e/data/man_arm_up_legs_one.json" --report "$WORK/man1.json"
grep -q '"note":	"loose fit: curve .leg_' "$WORK/man1.json" || fail "legs drawn as one stroke: no note: $(grep '"note"' "$WORK/man1.json")"
one_line_naming "loose fit: curve 'leg_"
# Five lines of a stick figure drawn by hand, the spine leaning (an outside
# review's), and a short stray line in a corner: the stray line is left
# out, and the figure fits (the stray line pulled the pose while the strokes
# were assigned: the spine took an arm's stroke, 9.9 px mean; a later review).
SPINE='[[320, 246], [321, 200], [322, 160], [322, 122]]' ARM_R='[[320, 197], [370, 197], [420, 197]]'
ARM_L='[[320, 197], [290, 160], [275, 110]]' LEG_R='[[320, 246], [350, 300], [370, 370]]' STRAY='[[600, 20], [630, 40]]'
strokes "$WORK/man_stray.json" "$SPINE" "$ARM_R" "$ARM_L" "$LEG_R" '[[320, 246], [300, 300], [330, 340], [300, 380]]' "$STRAY"
expect 0 "$SP" pose --rig "$MAN" --strokes "$WORK/man_stray.json" --report "$WORK/man_stray_r.json"
grep -q '"note":	"1 stroke left unused: 5 (the rest fit better without it)"' "$WORK/man_stray_r.json" ||
    fail "a stray line: $(grep '"note"' "$WORK/man_stray_r.json")"
grep -q '"curve":	"spine",$' "$WORK/man_stray_r.json" && grep -A1 '"curve":	"spine"' "$WORK/man_stray_r.json" | grep -q '"stroke":	0' ||
    fail "a stray line: the spine did not take the spine's stroke"
# The same with a leg that starts short of the hips: still loose, which is
# named after the note of the stray line (it was dropped).
strokes "$WORK/man_stray2.json" "$SPINE" "$ARM_R" "$ARM_L" "$LEG_R" '[[300, 300], [330, 340], [300, 380]]' "$STRAY"
expect 0 "$SP" pose --rig "$MAN" --strokes "$WORK/man_stray2.json" --report "$WORK/man_stray2_r.json"
grep -q '"note":	"1 stroke left unused: 5 (the rest fit better without it); loose fit: curve ' "$WORK/man_stray2_r.json" ||
    fail "a stray line hid the loose-fit note: $(grep '"note"' "$WORK/man_stray2_r.json")"
# Strokes wholly off their canvas: nothing to pose by (they were solved
# "best effort" with exit 0); one on it is enough.
strokes "$WORK/off.json" '[[2600, 100], [2700, 300]]' '[[-50, -40], [-10, -90]]'
expect 1 "$SP" pose --rig "$MAN" --strokes "$WORK/off.json"
one_line_naming "off.json: every stroke lies off its 640x480 canvas"
expect 1 "$SP" animate --rig "$MAN" --strokes "$WORK/off.json" --out "$WORK/off.glb"
one_line_naming "off.json: every stroke lies off"
strokes "$WORK/half_off.json" '[[700, 100], [760, 300]]' '[[300, 200], [340, 260]]'
expect 0 "$SP" pose --rig "$MAN" --strokes "$WORK/half_off.json"
# A tap (one point: dot eyes as a tablet records them) is left unused and
# named (it refused the drawing); taps alone are nothing to pose by.
strokes "$WORK/tap.json" '[[320, 246], [321, 200], [322, 160], [322, 122]]' '[[310, 110]]'
expect 0 "$SP" pose --rig "$MAN" --strokes "$WORK/tap.json" --report "$WORK/tap_r.json"
grep -q '"note":	"1 stroke left unused: 1 (a dot)' "$WORK/tap_r.json" || fail "a tap: $(grep '"note"' "$WORK/tap_r.json")"
strokes "$WORK/taps.json" '[[310, 110]]' '[[330, 110]]'
expect 1 "$SP" pose --rig "$MAN" --strokes "$WORK/taps.json"
one_line_naming "taps.json: stroke 0 has 1 point (no stroke has 2 or more points)"
# A point more than a canvas beyond it (a pen's glitch, a slipped
# coordinate) is refused, naming it: it flung a leg out, exit 0.
strokes "$WORK/glitch.json" '[[320, 246], [321, 200], [322, 160]]' '[[300, 200], [340, 260], [2600, 100]]'
expect 1 "$SP" pose --rig "$MAN" --strokes "$WORK/glitch.json"
one_line_naming "glitch.json: stroke 1, point 2 (2600, 100) lies more than a canvas beyond its 640x480 canvas"
expect 0 "$SP" animate --rig "$MAN" --strokes "$SRC/tests/e2e/data/man_arm_up.json" "$SRC/tests/e2e/data/man_arm_up_legs_one.json" --out "$WORK/man.glb"
one_line_naming "man_arm_up_legs_one.json: loose fit: curve 'leg_"

# The same strokes as an SVG drawing (its viewBox the canvas) pose the same;
# one with no viewBox has no canvas and is refused.
pts=$(sed -n 's/.*"points": \[\[\(.*\)\]\]}.*/\1/p' "$WORK/s.json" | sed 's/\], \[/ L /g; s/, / /g')
[ -n "$pts" ] || fail "synth's stroke file changed its layout: $(head -c 200 "$WORK/s.json")"
printf '<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 640 480"><g><path d="M %s"/></g></svg>\n' "$pts" >"$WORK/drawn.svg"
expect 0 "$SP" pose --rig "$RIG" --strokes "$WORK/drawn.svg" --report "$WORK/r_svg.json"
[ "$(grep -m1 '"mean_error_px"' "$WORK/r.json")" = "$(grep -m1 '"mean_error_px"' "$WORK/r_svg.json")" ] ||
    fail "pose of the SVG drawing differs: $(grep -m1 mean_error_px "$WORK/r.json" "$WORK/r_svg.json")"
# A viewBox that starts elsewhere (an editor's padding) keeps the drawing's
# place on the canvas: the same drawing moved by 40 px in both, the same fit.
sed 's/viewBox="0 0 640 480"><g>/viewBox="-40 -40 640 480"><g transform="translate(-40 -40)">/' "$WORK/drawn.svg" >"$WORK/padded.svg"
grep -q 'viewBox="-40' "$WORK/padded.svg" || fail "padded.svg not made: $(head -c 200 "$WORK/padded.svg")"
expect 0 "$SP" pose --rig "$RIG" --strokes "$WORK/padded.svg" --report "$WORK/r_pad.json"
[ "$(grep -m1 '"mean_error_px"' "$WORK/r.json")" = "$(grep -m1 '"mean_error_px"' "$WORK/r_pad.json")" ] ||
    fail "pose of the padded SVG differs: $(grep -m1 mean_error_px "$WORK/r.json" "$WORK/r_pad.json")"
sed 's/ viewBox="[^"]*"//' "$WORK/drawn.svg" >"$WORK/nobox.SVG"
expect 1 "$SP" pose --rig "$RIG" --strokes "$WORK/nobox.SVG"
one_line_naming "no usable viewBox"

# An output that cannot be written fails the command, and it leaves none of
# its outputs (each written whole, the ones before taken back).
rm -f "$WORK/left.glb" "$WORK/left.json"
expect 1 "$SP" pose --rig "$RIG" --strokes "$WORK/s.json" --out "$WORK/left.glb" --report "$WORK/left.json" --render "$WORK/nowhere/x.png"
one_line_naming nowhere/x.png
[ -e "$WORK/left.glb" ] && fail "pose left its .glb after --render failed"
[ -e "$WORK/left.json" ] && fail "pose left its report after --render failed"
ls -A "$WORK" | grep -q -e 'tmp' -e '^[.]sp-' && fail "pose left a temporary file: $(ls -A "$WORK" | grep -e tmp -e '^[.]sp-')"
# A folder that lets root write but takes no new file (/proc): said before
# the work, naming the folder (it came after every key was solved, as
# "No such file or directory" of the temporary file).
if [ -d /proc ]; then
    expect 1 "$SP" animate --rig "$RIG" --strokes "$WORK/s.json" "$WORK/s.json" --out /proc/a.glb
    one_line_naming "/proc/a.glb: cannot write into folder '/proc'"
fi

# Streams are not files: one stream named as two outputs overwrites nothing.
expect 0 "$SP" pose --rig "$RIG" --strokes "$WORK/s.json" --out /dev/null --report /dev/null
# The top of an integer range is in it.
expect 0 "$SP" pose --rig "$RIG" --strokes "$WORK/s.json" --max-iterations 1000000 --representatives 100000
# An abstraction the rig lacks: the rig's name and what it has, as pose says it.
expect 1 "$SP" render --rig "$RIG" --abstraction nope --out "$WORK/nope.png" --size 64x48
one_line_naming "sketchpose render: $RIG: no abstraction 'nope' (it has: "
# A named pipe is written into, whatever its name (no .png needed): the
# reader gets the PNG. timeout: a render that refused would leave cat
# waiting for a writer.
mkfifo "$WORK/pipe"
timeout 60 cat "$WORK/pipe" >"$WORK/from_pipe" &
expect 0 "$SP" render --rig "$RIG" --out "$WORK/pipe" --size 64x48
wait
head -c 8 "$WORK/from_pipe" | od -An -c | grep -q 'P   N   G' || fail "render into a named pipe: no PNG came out"

# --max-ms: one range, worded alike by the commands that take it.
expect 2 "$SP" pose --rig "$RIG" --strokes "$WORK/s.json" --max-ms 0
one_line_naming "sketchpose pose: --max-ms must be in (0, 3600000\], got 0"
expect 2 "$SP" drawover --rig "$RIG" --on "$WORK/s.json" --to "$WORK/s.json" --max-ms -5
one_line_naming "sketchpose drawover: --max-ms must be in (0, 3600000\], got -5"

# Outputs are glTF or PNG by their names: another name is bad usage, one
# line naming the option, before any solve, and no file is made (--out x.txt
# got glTF JSON, --render x.jpg a PNG).
refused_out() { # refused_out FILE OPTION: the last command wrote nothing and said why
    one_line_naming ": $2 writes .*got '.*$1'"
    [ -e "$WORK/$1" ] && fail "a refused $2 wrote $1"
}
expect 2 "$SP" pose --rig "$RIG" --strokes "$WORK/s.json" --out "$WORK/p.txt"
refused_out p.txt --out
expect 2 "$SP" pose --rig "$RIG" --strokes "$WORK/s.json" --out "$WORK/p.glb" --render "$WORK/p.jpg"
refused_out p.jpg --render
[ -e "$WORK/p.glb" ] && fail "pose wrote --out although --render was refused"
expect 2 "$SP" drawover --rig "$RIG" --on "$WORK/s.json" --to "$WORK/s.json" --render "$WORK/d.jpeg"
refused_out d.jpeg --render
expect 2 "$SP" drawover --rig "$RIG" --on "$WORK/s.json" --to "$WORK/s.json" --out "$WORK/d.fbx"
refused_out d.fbx --out
expect 2 "$SP" animate --rig "$RIG" --strokes "$WORK/s.json" --out "$WORK/a.json"
refused_out a.json --out
expect 2 "$SP" render --rig "$RIG" --out "$WORK/r.jpg"
refused_out r.jpg --out
expect 2 "$SP" synth --drawings --sheet "$WORK/sheet.svg"
refused_out sheet.svg --sheet
expect 0 "$SP" render --rig "$RIG" --out "$WORK/R.PNG" --size 64x48
[ -s "$WORK/R.PNG" ] || fail "render --out R.PNG wrote nothing"
# An option synth's mode does not use is bad usage naming it (--per-part 5
# with --rig drew one drawing, silently).
expect 2 "$SP" synth --rig "$RIG" --seed 1 --out "$WORK/pp.json" --per-part 5
one_line_naming "synth: --per-part does not apply to --rig"
[ -e "$WORK/pp.json" ] && fail "synth wrote pp.json with an option it does not take"
expect 2 "$SP" synth --concepts --sheet "$WORK/c.png" --shape top
one_line_naming "synth: --shape does not apply to --concepts"
# A stroke file is .json: the drawing readers take a .svg for SVG.
expect 2 "$SP" synth --rig "$RIG" --seed 1 --out "$WORK/s.svg"
refused_out s.svg --out
# A device or a pipe has no name to say a format; it is written into.
"$SP" render --rig "$RIG" --out /dev/stdout --size 64x48 >"$WORK/piped" 2>"$WORK/err" || fail "render --out /dev/stdout: $(cat "$WORK/err")"
[ "$(head -c 4 "$WORK/piped" | tail -c 3)" = PNG ] || fail "render --out /dev/stdout wrote no PNG"
# Into a pipe (the name leads to /proc/self/fd/1 -> "pipe:[N]", which was
# taken for a file name: "cannot write", nothing piped), /dev/fd/1 too.
for dev in /dev/stdout /dev/fd/1 /dev//stdout /dev/./fd/1; do
    { "$SP" render --rig "$RIG" --out "$dev" --size 64x48 2>"$WORK/err" || echo "exit $?" >>"$WORK/err"; } | cat >"$WORK/piped"
    [ "$(head -c 4 "$WORK/piped" | tail -c 3)" = PNG ] || fail "render --out $dev | cat: no PNG came through ($(cat "$WORK/err"))"
done
# Appended to (>>) through /dev/stdout: the file keeps what it held and the
# report goes after it, once (it was replaced whole; then printed twice).
echo "before" >"$WORK/log"
"$SP" pose --rig "$RIG" --strokes "$WORK/s.json" --report /dev/stdout >>"$WORK/log" 2>"$WORK/err" || fail "pose --report /dev/stdout >>: $(cat "$WORK/err")"
[ "$(head -n 1 "$WORK/log")" = before ] || fail "pose --report /dev/stdout >> log replaced the log"
[ "$(grep -c '"stopped"' "$WORK/log")" -eq 1 ] || fail "pose --report /dev/stdout >> log: not one report in the log"
# A descriptor this process did not get (closed, or never given) is refused
# before any work: writing through it would hit whatever it opens next (a
# database). A regular file under /dev (/dev/shm) is a file like any other,
# replaced whole or not at all (it was truncated in place).
expect 1 "$SP" render --rig "$RIG" --out /dev/fd/7 --size 64x48
one_line_naming "descriptor 7 is not open"
if [ -d /dev/shm ] && [ -w /dev/shm ]; then
    shm="/dev/shm/sp-posing-cli-$$.png"
    echo "the old picture" >"$shm"
    (ulimit -f 1; exec "$SP" render --rig "$RIG" --out "$shm" --size 800x600) 2>"$WORK/err" && fail "render past ulimit -f 1 into $shm: exit 0"
    [ "$(cat "$shm")" = "the old picture" ] || fail "render that failed left $shm changed"
    rm -f "$shm"
fi
# Two outputs on one name through a dangling link are one file (the report
# was silently lost, exit 0).
rm -f "$WORK/same.glb"
ln -sf same.glb "$WORK/l_same.glb"
expect 2 "$SP" pose --rig "$RIG" --strokes "$WORK/s.json" --out "$WORK/l_same.glb" --report "$WORK/same.glb"
one_line_naming "is the same file as --out"
[ -e "$WORK/same.glb" ] && fail "pose wrote through a link that two outputs share"

# Numbers: the parser refuses what is not one finite number; ranges name
# themselves. A typed 0 weight turns its term off (it was the default weight).
for v in nan inf -inf 1.5x 1e999 ''; do
    expect 2 "$SP" pose --rig "$RIG" --strokes "$WORK/s.json" --lambda-pose "$v"
    one_line_naming "lambda-pose expects a finite number, got '$v'"
done
expect 2 "$SP" pose --rig "$RIG" --strokes "$WORK/s.json" --max-iterations 12abc
one_line_naming "max-iterations expects an integer, got '12abc'"
expect 2 "$SP" pose --rig "$RIG" --strokes "$WORK/s.json" --max-iterations 99999999999
one_line_naming "max-iterations is out of range (see --help), got '99999999999'"
expect 0 "$SP" pose --rig "$RIG" --strokes "$WORK/s.json" --lambda-pose 0 --report "$WORK/l0.json"
tr -d ' \t\n' <"$WORK/l0.json" | grep -q '"terms_after":{[^}]*"pose":0,' || fail "--lambda-pose 0 kept W_pose"
expect 2 "$SP" render --rig "$RIG" --out "$WORK/lw.png" --line-width 0
one_line_naming "line-width must be in (0, 256\], got 0"
expect 2 "$SP" render --rig "$RIG" --out "$WORK/lw.png" --pitch 90
one_line_naming "pitch must be in \[-89, 89\], got 90"

# A picture size out of range says the range.
expect 2 "$SP" render --rig "$RIG" --out "$WORK/tiny.png" --size 1x1
one_line_naming "16..8192"
expect 2 "$SP" render --rig "$RIG" --out "$WORK/tiny.png" --size 64x1
one_line_naming "16..8192"

# Bad strokes: one clear line naming the file, exit 1.
strokes "$WORK/empty.json"
expect 1 "$SP" pose --rig "$RIG" --strokes "$WORK/empty.json"
one_line_naming empty.json
strokes "$WORK/one.json" '[[10, 10]]'
expect 1 "$SP" pose --rig "$RIG" --strokes "$WORK/one.json"
one_line_naming one.json
printf '{"format": "sketchpose-strokes", "version": 1, "strokes": [{"points": [[1, NaN], [2, 3]]}]}\n' >"$WORK/nan.json"
expect 1 "$SP" pose --rig "$RIG" --strokes "$WORK/nan.json"
one_line_naming nan.json
# Beyond 1e9 in x or in y is no drawing (a solve ran on x = 1e12).
for far in '[[1e12, 3], [2, 3]]' '[[1, 3], [2, -1e12]]'; do
    strokes "$WORK/huge_xy.json" "$far"
    expect 1 "$SP" pose --rig "$RIG" --strokes "$WORK/huge_xy.json"
    one_line_naming "huge_xy.json: stroke 0 point [01] is not finite (or beyond 1e9)"
done
expect 1 "$SP" pose --rig "$RIG" --strokes "$WORK/missing.json"
one_line_naming missing.json
expect 1 "$SP" pose --rig "$WORK/missing.glb" --strokes "$WORK/s.json"
one_line_naming missing.glb

# Hard but valid strokes (a frame round the whole canvas for two bones): a
# best-effort pose, exit 0, the report says so. Strokes wholly off the
# canvas are refused (they were solved best effort too).
strokes "$WORK/hard.json" '[[5, 5], [635, 5], [635, 475], [5, 475]]'
expect 0 "$SP" pose --rig "$RIG" --strokes "$WORK/hard.json" --report "$WORK/hard_r.json"
grep -q '"note":	"best effort' "$WORK/hard_r.json" || fail "hard strokes: no best-effort note"
strokes "$WORK/far.json" '[[100000, 100000], [100040, 100090], [100100, 100100]]'
expect 1 "$SP" pose --rig "$RIG" --strokes "$WORK/far.json" --report "$WORK/far_r.json"
one_line_naming "far.json: every stroke lies off its 640x480 canvas"
[ -e "$WORK/far_r.json" ] && fail "far strokes: a report was written"
# two_bone.gltf has no extras: a derived stick figure, ordered correspondences.
strokes "$WORK/many.json" '[[10, 10], [50, 60]]' '[[300, 300], [320, 310]]' '[[500, 40], [520, 90]]' '[[100, 400], [140, 420]]' '[[600, 460], [610, 470]]'
expect 0 "$SP" pose --rig "$SRC/tests/e2e/data/two_bone.gltf" --strokes "$WORK/many.json" --report "$WORK/many_r.json"
grep -q '"unused_strokes":	[1-9]' "$WORK/many_r.json" || fail "more strokes than curves: unused strokes not reported"
# A million points: resampled, bounded by the time cap, no hang.
awk 'BEGIN { printf "{\"format\": \"sketchpose-strokes\", \"version\": 1, \"canvas\": [640, 480], \"strokes\": [{\"points\": ["; for (i = 0; i < 1000000; ++i) printf "%s[%.3f, %.3f]", (i ? ", " : ""), 200 + 150 * i / 1000000, 100 + 200 * i / 1000000 + 3 * sin(i); print "]}]}" }' >"$WORK/huge.json"
expect 0 "$SP" pose --rig "$RIG" --strokes "$WORK/huge.json" --max-ms 5000

# drawover: the cartoon man's stick figure drawn over him at his stored pose,
# redrawn in another pose. The report names the drawn curves; the posed .glb
# keeps the file's own abstractions, not the curves drawn over it.
C="$SRC/assets/cartoon_man.glb"
printf '{"parameters": {}}\n' >"$WORK/rest.json"
expect 0 "$SP" synth --rig "$C" --pose "$WORK/rest.json" --out "$WORK/on.json"
expect 0 "$SP" synth --rig "$C" --seed 3 --amplitude 0.3 --out "$WORK/to.json"
expect 0 "$SP" drawover --rig "$C" --on "$WORK/on.json" --to "$WORK/to.json" --out "$WORK/d.glb" --render "$WORK/d.png" --report "$WORK/d_r.json"
for key in '"stopped"' '"mean_error_px"' '"curve":	"stroke0"' '"parameters"'; do
    grep -q "$key" "$WORK/d_r.json" || fail "drawover report lacks $key"
done
grep -q '"stopped":' "$WORK/out" || fail "drawover prints no report on stdout"
[ -s "$WORK/d.png" ] || fail "drawover wrote no picture"
expect 0 "$SP" inspect --rig "$WORK/d.glb"
grep -q '"name":	"outline"' "$WORK/out" || fail "drawover --out lost the outline"
grep -q '"name":	"drawover"' "$WORK/out" && fail "drawover --out kept the drawn curves"
expect 1 "$SP" drawover --rig "$C" --on "$WORK/missing_on.json" --to "$WORK/to.json"
one_line_naming missing_on.json

# animate: a .glb with the animation; valid for Khronos's validator.
"$SP" synth --rig "$RIG" --seed 5 --amplitude 0.3 --out "$WORK/k2.json" >/dev/null 2>&1
expect 0 "$SP" animate --rig "$RIG" --strokes "$WORK/s.json" "$WORK/k2.json" --times 0,0.8 --out "$WORK/anim.glb"
expect 0 "$SP" inspect --rig "$WORK/anim.glb"
grep -q '"sketchpose"' "$WORK/out" || fail "animate: no 'sketchpose' animation in the export"
expect 2 "$SP" animate --rig "$RIG" --strokes "$WORK/s.json" "$WORK/k2.json" --times 1,0.5 --out "$WORK/x.glb"
if node_tools gltf-validator; then
    node "$TOOLS/validate.js" "$WORK/anim.glb" >"$WORK/val.json" || fail "animate export does not validate: $(cat "$WORK/val.json")"
    if [ -n "$SHARED" ] && [ -f "$SHARED/gltf/CesiumMan/CesiumMan.glb" ]; then
        C="$SHARED/gltf/CesiumMan/CesiumMan.glb"
        for k in 1 2 3 4; do "$SP" synth --rig "$C" --seed "$k" --amplitude 0.4 --out "$WORK/c$k.json" >/dev/null 2>&1; done
        expect 0 "$SP" animate --rig "$C" --strokes "$WORK/c1.json" "$WORK/c2.json" "$WORK/c3.json" "$WORK/c4.json" --out "$WORK/canim.glb"
        node "$TOOLS/validate.js" "$WORK/canim.glb" >"$WORK/val.json" || fail "CesiumMan animate export does not validate: $(cat "$WORK/val.json")"
    fi
else
    echo "note: node or tests/tools/node_modules missing, the validator step was skipped"
fi

rm -rf "$WORK"
[ "$fails" -eq 0 ] || exit 1
echo "posing_cli: all checks passed"
