#!/bin/sh
# render_png.sh SKETCHPOSE RIG OUT.png W H: `sketchpose render` writes a PNG
# of the asked size. Exit 77 (CTest skip) when the rig (shared data) is absent.
set -u
exe=$1 rig=$2 out=$3 w=$4 h=$5
if [ ! -f "$rig" ]; then
    echo "skip: $rig is absent"
    exit 77
fi
mkdir -p "$(dirname "$out")"
rm -f "$out"
"$exe" render --rig "$rig" --out "$out" --size "${w}x${h}" || { echo "FAIL: sketchpose render exited $?"; exit 1; }
[ -s "$out" ] || { echo "FAIL: $out was not written"; exit 1; }
# PNG signature, then the IHDR chunk: width and height as big-endian 32-bit at bytes 16..23.
sig=$(od -An -tx1 -N8 "$out" | tr -d ' \n')
[ "$sig" = "89504e470d0a1a0a" ] || { echo "FAIL: $out is not a PNG ($sig)"; exit 1; }
dims=$(od -An -tu1 -j16 -N8 "$out" | tr -s ' ' | sed 's/^ //')
set -- $dims
gw=$(( ($1 << 24) | ($2 << 16) | ($3 << 8) | $4 ))
gh=$(( ($5 << 24) | ($6 << 16) | ($7 << 8) | $8 ))
[ "$gw" -eq "$w" ] && [ "$gh" -eq "$h" ] || { echo "FAIL: $out is ${gw}x${gh}, wanted ${w}x${h}"; exit 1; }
echo "ok: $out ${gw}x${gh}"
