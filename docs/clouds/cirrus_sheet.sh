#!/bin/sh
# The picture of docs/clouds.md "Cirrus": upper halves of the previews at
# --size 256 (512 x 128 each), 6 px apart, top to bottom:
#   1. configs/styles/cumulus_noon.toml (the cumulus beside it),
#   2. configs/styles/high_cirrus.toml baked by $BEFORE (a skybake built
#      before cirrus had streaks; the row is left out when BEFORE is unset),
#   3. configs/styles/high_cirrus.toml now (type = "cirrus": streaks, ice phase),
#   4. configs/styles/cirrus_uncinus.toml.
# Then the +Y (zenith) faces of rows 3 and 4 side by side, 256 x 256 each,
# exposed alike. Needs build/skybake and oiiotool (OpenImageIO); writes into
# $1 (default out/cirrus_sheet) and docs/clouds/cirrus_beside_cumulus.png.
set -e
out=${1:-out/cirrus_sheet}
mkdir -p "$out"
bake() {  # binary style name
  "$1" bake "configs/styles/$2.toml" --size 256 -q --force --out "$out/$3" \
    --set output.cube_strip=false >/dev/null
  oiiotool "$out/$3/sky_latlong.png" --cut 512x128+0+0 -o "$out/$3.upper.png"
}
bake build/skybake cumulus_noon cumulus
rows="$out/cumulus.upper.png"
if [ -n "$BEFORE" ]; then
  bake "$BEFORE" high_cirrus high_cirrus_before
  rows="$rows $out/high_cirrus_before.upper.png"
fi
bake build/skybake high_cirrus high_cirrus
bake build/skybake cirrus_uncinus cirrus_uncinus
rows="$rows $out/high_cirrus.upper.png $out/cirrus_uncinus.upper.png"
for s in high_cirrus cirrus_uncinus; do
  oiiotool "$out/$s/sky_py.exr" --mulc 0.00012 --clamp:min=0:max=1 --colorconvert linear sRGB -d uint8 \
    -o "$out/$s.zenith.png"
done
n=$(echo $rows | wc -w)
height=$((n * 134 + 256))
set -- $rows
cmd="oiiotool --create 518x$height 3 -d uint8"
y=0
for r in "$@"; do
  cmd="$cmd $r --swap --paste +0+$y"
  y=$((y + 134))
done
cmd="$cmd $out/high_cirrus.zenith.png --swap --paste +0+$y $out/cirrus_uncinus.zenith.png --swap --paste +262+$y"
$cmd -o docs/clouds/cirrus_beside_cumulus.png
