#!/bin/sh
# The contact sheets of docs/clouds.md "An afternoon that builds up": the 13
# frames of configs/styles/afternoon_buildup.toml over
# configs/schedules/afternoon_buildup.toml at --size 96 (the upper half of
# each preview, 4 columns), and the frames' cloud shadow maps (64 x 64 each).
# Needs build/skybake and oiiotool (OpenImageIO); BAKE=0 reuses the folder given as $1.
set -e
out=${1:-out/afternoon_sheet}
bake=${BAKE:-1}
[ "$bake" = 1 ] && build/skybake bake configs/styles/afternoon_buildup.toml --schedule configs/schedules/afternoon_buildup.toml \
  --size 96 -q --force --out "$out"
skies=""
shadows=""
for n in 0001 0002 0003 0004 0005 0006 0007 0008 0009 0010 0011 0012 0013; do
  oiiotool "$out/sky_latlong.$n.png" --cut 192x48+0+0 -o "$out/upper.$n.png"
  oiiotool "$out/sky_cloudshadow.$n.exr" --ch R,R,R --resize 64x64 --colorconvert linear sRGB -d uint8 \
    -o "$out/shadow.$n.png"
  skies="$skies $out/upper.$n.png"
  shadows="$shadows $out/shadow.$n.png"
done
# 13 frames in a 4 x 4 grid and 7 x 2 (the last cells empty).
oiiotool --create 192x48 3 -d uint8 -o "$out/blank_sky.png"
oiiotool --create 64x64 3 -d uint8 -o "$out/blank_shadow.png"
oiiotool $skies "$out/blank_sky.png" "$out/blank_sky.png" "$out/blank_sky.png" --mosaic:pad=4 4x4 \
  -o docs/clouds/afternoon_buildup.png
oiiotool $shadows "$out/blank_shadow.png" --mosaic:pad=4 7x2 -o docs/clouds/afternoon_buildup_shadows.png
