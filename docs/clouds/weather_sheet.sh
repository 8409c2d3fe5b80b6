#!/bin/sh
# The before/after pictures of docs/clouds.md "Weather without repetition":
# configs/styles/cumulus_noon.toml as it is (non-repeating) and with
# `tiling = true` in its layer (the tiles read as they are, as before), each
# with a 120 km cloud shadow map (512 texels, the Sun at 65 deg) and its
# upper-hemisphere preview at --size 192. Left: tiling; right: non-repeating.
# Needs build/skybake and oiiotool (OpenImageIO); writes into $1 (default
# out/weather_sheet) and docs/clouds/weather_before_after.png.
set -e
out=${1:-out/weather_sheet}
mkdir -p "$out"
shadow='
[cloud_shadow]
enabled = true
resolution = 512
extent_m = 120000.0
steps = 16
ground = false
'
sed 's/^\[\[cloud_layer\]\]$/[[cloud_layer]]\ntiling = true/' configs/styles/cumulus_noon.toml > "$out/tiling.toml"
cp configs/styles/cumulus_noon.toml "$out/free.toml"
for s in tiling free; do
  printf '%s' "$shadow" >> "$out/$s.toml"
  build/skybake bake "$out/$s.toml" --size 192 -q --force --out "$out/$s"
  oiiotool "$out/$s/sky_latlong.png" --cut 384x96+0+0 -o "$out/$s.upper.png"
  oiiotool "$out/$s/sky_cloudshadow.exr" --ch R,R,R --resize 384x384 --colorconvert linear sRGB -d uint8 \
    -o "$out/$s.shadow.png"
done
# Upper halves on top, shadow maps below, 6 px apart (--paste puts the image
# below the top of the stack onto the top).
oiiotool "$out/tiling.upper.png" --create 774x486 3 -d uint8 --paste +0+0 \
  "$out/free.upper.png" --swap --paste +390+0 \
  "$out/tiling.shadow.png" --swap --paste +0+102 \
  "$out/free.shadow.png" --swap --paste +390+102 -o docs/clouds/weather_before_after.png
