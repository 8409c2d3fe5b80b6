#!/usr/bin/env bash
# The pictures of docs/colour.md: each row is the latlong preview of one bake
# before (a previous build BEFORE, given with its own copy of the styles at
# OLD_CONFIGS, since it does not know output.sun) | after (build/skybake) |
# the 48-bin spectral mode, at one fixed exposure (no auto exposure).
#   bash tests/colour/pictures.sh BEFORE/skybake OLD_CONFIGS
# OLD_CONFIGS holds default.toml and styles/*.toml of that build's commit, e.g.
#   git show 49c7375:configs/default.toml > /tmp/cfg/default.toml
set -euo pipefail
cd "$(dirname "$0")/../.."
before=$1 old=$2 work=$(mktemp -d)
shot() {  # name style elevation ev100
  local common="--size 128 -q --set sun.elevation_deg=$3 --set preview.auto_exposure=false --set preview.ev100=$4
                --set output.faces=false --set output.cube_strip=false --set gltf.enabled=false"
  "$before" bake "$old/${2#configs/}" $common --out "$work/$1.before" >/dev/null
  build/skybake bake "$2" $common --out "$work/$1.after" >/dev/null
  build/skybake bake "$2" $common --set quality.wavelengths=48 --out "$work/$1.ref" >/dev/null
  oiiotool "$work/$1.before/sky_latlong.png" "$work/$1.after/sky_latlong.png" "$work/$1.ref/sky_latlong.png" \
    --mosaic 3x1 -o "docs/colour/$1.png"
}
shot clear_sun35 configs/default.toml 35 13.5
shot clear_sun5 configs/default.toml 5 11.5
shot clear_sun-3 configs/default.toml -3 7
shot cumulus_sun45 configs/styles/cumulus_noon.toml 45 13.5
shot overcast_sun30 configs/styles/overcast_stratus.toml 30 12
rm -rf "$work"
