#!/bin/sh
# previews.sh [BUILD_DIR [NAME...]]: renders assets/previews/<part>.png for
# every generated part: a 2x2 contact sheet of `sketchpose render` pictures, the
# rest pose and three seeded random poses (`sketchpose synth --truth`, seeds
# 1-3, amplitude 45 degrees, shapes anywhere within bounds), the outline
# abstraction overlaid in yellow. The random poses keep the root's placement
# (tx, ty, rz, s) at rest so that the part stays in the picture. The
# characters get one sheet per abstraction: cartoon_man.png (stick figure),
# cartoon_man_outline.png, elephant.png (stick figure).
# BUILD_DIR (default: build) must hold app/sketchpose and assets/gen/sp-contact-sheet;
# NAMEs (e.g. cartoon_man cartoon_man:outline) limit the sheets made.
set -eu
here=$(cd "$(dirname "$0")/../.." && pwd)
build=${1:-$here/build}
sp=$build/app/sketchpose
sheet=$build/assets/gen/sp-contact-sheet
for tool in "$sp" "$sheet"; do
    [ -x "$tool" ] || { echo "previews.sh: $tool is missing (build first)" >&2; exit 1; }
done
out=$here/assets/previews
mkdir -p "$out"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
[ $# -gt 1 ] && shift || set -- torso tail head wings front_legs hind_legs cartoon_man cartoon_man:outline elephant
for item in "$@"; do
    part=${item%%:*}
    ab=${item#"$part"}
    ab=${ab#:}
    name=$part${ab:+_$ab}
    rig=$here/assets/$part.glb
    root=$("$sp" inspect --rig "$rig" | sed -n 's/.*"name":[[:space:]]*"\([^"]*\)".*/\1/p' | head -n 1)
    "$sp" render --rig "$rig" ${ab:+--abstraction "$ab"} --out "$tmp/$name-0.png" --size 560x420 >/dev/null
    for seed in 1 2 3; do
        "$sp" synth --rig "$rig" --seed "$seed" --out "$tmp/s.json" --truth "$tmp/t.json" >/dev/null
        grep -Ev "\"$root\.(tx|ty|rz|s)\"" "$tmp/t.json" >"$tmp/p.json"
        "$sp" render --rig "$rig" --pose "$tmp/p.json" ${ab:+--abstraction "$ab"} --out "$tmp/$name-$seed.png" --size 560x420 >/dev/null
    done
    "$sheet" --out "$out/$name.png" --cols 2 "$tmp/$name-0.png" "$tmp/$name-1.png" "$tmp/$name-2.png" "$tmp/$name-3.png"
    echo "$out/$name.png"
done
