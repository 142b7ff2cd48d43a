#!/bin/sh
# preview.sh [BUILD_DIR]: renders assets/previews/face.png, a 2x2 contact
# sheet of the face plugin (`sketchpose render --rig libsp_face.so`): the
# rest pose and three seeded random poses (`sketchpose synth --truth`, seeds
# 1-3, amplitude 45 degrees: weights up to a quarter of their range, shapes
# anywhere within bounds), the abstraction overlaid in yellow. The same
# recipe as assets/gen/previews.sh for the glTF parts.
# BUILD_DIR (default: build) must hold app/sketchpose, assets/libsp_face.so
# and assets/gen/sp-contact-sheet.
set -eu
here=$(cd "$(dirname "$0")/../.." && pwd)
build=${1:-$here/build}
sp=$build/app/sketchpose
rig=$build/assets/libsp_face.so
sheet=$build/assets/gen/sp-contact-sheet
for tool in "$sp" "$rig" "$sheet"; do
    [ -e "$tool" ] || { echo "preview.sh: $tool is missing (build first)" >&2; exit 1; }
done
out=$here/assets/previews
mkdir -p "$out"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
"$sp" render --rig "$rig" --out "$tmp/face-0.png" --size 560x420 >/dev/null
for seed in 1 2 3; do
    "$sp" synth --rig "$rig" --seed "$seed" --out "$tmp/s.json" --truth "$tmp/t.json" >/dev/null
    "$sp" render --rig "$rig" --pose "$tmp/t.json" --out "$tmp/face-$seed.png" --size 560x420 >/dev/null
done
"$sheet" --out "$out/face.png" --cols 2 "$tmp/face-0.png" "$tmp/face-1.png" "$tmp/face-2.png" "$tmp/face-3.png"
echo "$out/face.png"
