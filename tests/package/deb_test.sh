#!/usr/bin/env bash
# The Debian packages, as a farm node gets them (ctest deb_package, label
# package): cpack builds the .debs from BUILD_DIR, their Depends must be
# satisfiable here (dpkg --dry-run -i: nothing is installed), the packages
# are unpacked into a temporary root (dpkg -x), and the skybake they hold
# bakes the default style they hold, with the module found beside its own
# install; then `cmake --install` into a prefix that cannot be written must
# stop with a clear message and install nothing; last, as root, the packages
# are installed with dpkg -i, bake from /usr/bin/skybake, and are purged.
#   bash tests/package/deb_test.sh BUILD_DIR
set -euo pipefail
build="$(cd "$1" && pwd)"
work="$(mktemp -d "${TMPDIR:-/tmp}/skybake-deb.XXXXXX")"
trap 'rm -rf "$work"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }

# 1. The packages.
(cd "$work" && cpack --config "$build/CPackConfig.cmake" -B "$work/packages" >"$work/cpack.log" 2>&1) ||
  { cat "$work/cpack.log"; fail "cpack"; }
tool=$(ls "$work"/packages/skybake_*.deb 2>/dev/null | head -1)
[ -n "$tool" ] || { ls -l "$work/packages"; fail "no skybake_*.deb"; }
echo "package: $(basename "$tool") ($(stat -c %s "$tool") bytes)"
depends=$(dpkg-deb -f "$tool" Depends)
echo "Depends: $depends"
# The libraries the binary links (dpkg-shlibdeps) and the Vulkan driver it needs at run time.
for lib in libvulkan1 libopenexr libdeflate0 libpng16-16 libzstd1 libssl3 libnova libstdc++6 mesa-vulkan-drivers; do
  case "$depends" in *"$lib"*) ;; *) fail "Depends lacks $lib" ;; esac
done
case "$depends" in *openimageio*) fail "the tool's package depends on OpenImageIO" ;; esac
dpkg-deb -c "$tool" | awk '{print $6}' > "$work/contents"
for f in ./usr/bin/skybake ./usr/share/skybake/configs/default.toml ./usr/share/doc/skybake/README.md; do
  grep -qx "$f" "$work/contents" || fail "$f is not in the package"
done
module=$(ls "$work"/packages/skybake-oiio_*.deb 2>/dev/null | head -1 || true)
if [ -n "$module" ]; then
  echo "package: $(basename "$module"), Depends: $(dpkg-deb -f "$module" Depends)"
  case "$(dpkg-deb -f "$module" Depends)" in *libopenimageio*) ;; *) fail "the module's package lacks libopenimageio" ;; esac
fi
python_deb=$(ls "$work"/packages/python3-skybake_*.deb 2>/dev/null | head -1 || true)
if [ -f "$build/CMakeCache.txt" ] && grep -q '^SKYBAKE_PYTHON_MINOR:INTERNAL=' "$build/CMakeCache.txt"; then
  [ -n "$python_deb" ] || fail "the build has the Python module but cpack made no python3-skybake package"
fi
if [ -n "$python_deb" ]; then
  py_depends=$(dpkg-deb -f "$python_deb" Depends)
  echo "package: $(basename "$python_deb"), Depends: $py_depends"
  for dep in "skybake (=" "python3 (>= 3." "python3 (<< 3." python3-numpy; do
    case "$py_depends" in *"$dep"*) ;; *) fail "python3-skybake's Depends lack $dep" ;; esac
  done
  # Where Debian's python3 looks (/usr/lib/python3/dist-packages), not the /usr/local layout.
  dpkg-deb -c "$python_deb" | awk '{print $6}' > "$work/python_contents"
  grep -q '^\./usr/lib/python3/dist-packages/skybake\.cpython-3[0-9]*-[a-z0-9_-]*\.so$' "$work/python_contents" ||
    { dpkg-deb -c "$python_deb"; fail "the module is not in /usr/lib/python3/dist-packages"; }
fi
dpkg --dry-run -i "$tool" ${module:+"$module"} ${python_deb:+"$python_deb"} >"$work/dpkg.log" 2>&1 ||
  { cat "$work/dpkg.log"; fail "dpkg -i would fail"; }

# 2. Unpacked into a root of its own: a bake with what the package holds.
for deb in "$tool" ${module:+"$module"} ${python_deb:+"$python_deb"}; do dpkg -x "$deb" "$work/root"; done
"$work/root/usr/bin/skybake" --version
(cd "$work" && "$work/root/usr/bin/skybake" bake "$work/root/usr/share/skybake/configs/default.toml" --size 16 -q \
   --vulkan-validation --out "$work/out") || fail "the packaged skybake did not bake"
for f in sky_px.exr sky_latlong.exr sky_latlong.png sky.glb manifest.json; do
  [ -s "$work/out/$f" ] || fail "the bake wrote no $f"
done
grep -q '"complete": true' "$work/out/manifest.json" || fail "manifest not complete"
if [ -n "$module" ]; then
  # The gallery needs the module: found beside the packaged binary's install.
  mkdir -p "$work/styles" && cp "$work/root/usr/share/skybake/configs/default.toml" "$work/styles/"
  # (The loader's log names the module it opened: the package's, not the build tree's.)
  LD_DEBUG=files "$work/root/usr/bin/skybake" gallery "$work/styles" --size 8 -q --out "$work/gallery" \
    >"$work/gallery.log" 2>&1 || { tail -20 "$work/gallery.log"; fail "the packaged gallery did not run"; }
  [ -s "$work/gallery/gallery.png" ] || fail "no gallery.png"
  grep -q "file=$work/root/usr/lib/[a-z0-9_/-]*skybake/libskybake_oiio.so" "$work/gallery.log" ||
    { grep libskybake_oiio "$work/gallery.log" | head -3; fail "the gallery did not load the packaged module"; }
fi

if [ -n "$python_deb" ]; then
  # The packaged module, imported by Debian's python3 from the package's folder alone, bakes.
  (cd "$work" && PYTHONPATH="$work/root/usr/lib/python3/dist-packages" SKYBAKE_VULKAN_VALIDATION=1 /usr/bin/python3 - \
     "$work/root/usr/share/skybake/configs/default.toml" "$work/py_out" "$work/root" <<'PY'
import sys
import skybake
assert skybake.__file__.startswith(sys.argv[3] + "/usr/lib/python3/dist-packages/"), skybake.__file__
result = skybake.bake(skybake.load_style(sys.argv[1]), out=sys.argv[2], size=16, arrays=True)
frame = result.frames[0]
assert frame.latlong.shape == (16, 32, 3), frame.latlong.shape
assert result.manifest["complete"] is True
print("python3-skybake:", skybake.__version__, "baked", len(result.frames), "frame, sun at %.1f deg" % frame.sun_elevation_deg)
PY
  ) || fail "the packaged Python module did not bake"
fi

# 3. An install prefix that cannot be written: a clear error, nothing installed.
touch "$work/plain-file"
if cmake --install "$build" --prefix "$work/plain-file/skybake" >"$work/install.log" 2>&1; then
  fail "cmake --install into a prefix under a regular file succeeded"
fi
grep -q "cannot install skybake into $work/plain-file/skybake" "$work/install.log" ||
  { cat "$work/install.log"; fail "no clear message"; }
grep -q "Installing:" "$work/install.log" && fail "something was installed"
[ ! -e "$work/plain-file/skybake" ] || fail "the prefix was created"
sed -n 's/^ *\(CMake Error.*\|cannot install.*\)$/\1/p' "$work/install.log" | head -3
# 4. Installed on this machine as a farm node installs it (dpkg -i), a bake from /usr/bin/skybake,
#    then purged (dpkg --purge) with nothing left behind. As root only, and only where no skybake is
#    installed already: the test never replaces or removes a skybake it did not install.
if [ "$(id -u)" != 0 ]; then
  echo "dpkg -i: not tried (not root); the packages were checked unpacked above"
elif dpkg-query -W -f='${Status}' skybake 2>/dev/null | grep -q "ok installed" || [ -e /usr/bin/skybake ]; then
  echo "dpkg -i: not tried: a skybake is installed here already (/usr/bin/skybake), and the test does not replace it"
else
  names="skybake${module:+ skybake-oiio}${python_deb:+ python3-skybake}"
  trap 'dpkg --purge $names >/dev/null 2>&1 || true; rm -rf "$work"' EXIT
  dpkg -i "$tool" ${module:+"$module"} ${python_deb:+"$python_deb"} >"$work/dpkg_install.log" 2>&1 ||
    { cat "$work/dpkg_install.log"; fail "dpkg -i"; }
  /usr/bin/skybake --version
  (cd "$work" && /usr/bin/skybake bake /usr/share/skybake/configs/default.toml --size 16 -q --vulkan-validation \
     --out "$work/installed_out") || fail "the installed skybake did not bake"
  [ -s "$work/installed_out/sky_latlong.exr" ] || fail "the installed skybake wrote no sky_latlong.exr"
  if [ -n "$python_deb" ]; then
    (cd "$work" && /usr/bin/python3 -c 'import skybake; assert skybake.__file__.startswith("/usr/lib/python3/dist-packages/")') ||
      fail "Debian's python3 does not import the installed module"
  fi
  # --purge: a package with maintainer scripts (ldconfig for the module) stays "rc" after -r alone.
  dpkg --purge $names >"$work/dpkg_remove.log" 2>&1 || { cat "$work/dpkg_remove.log"; fail "dpkg --purge"; }
  trap 'rm -rf "$work"' EXIT
  for f in /usr/bin/skybake /usr/share/skybake /usr/lib/skybake /usr/share/doc/skybake; do
    [ ! -e "$f" ] || fail "dpkg --purge left $f"
  done
  ls /usr/lib/python3/dist-packages/skybake.* >/dev/null 2>&1 && fail "dpkg --purge left the Python module"
  for name in $names; do
    dpkg-query -W -f='${db:Status-Abbrev}' "$name" 2>/dev/null | grep -q . && fail "dpkg still knows $name after --purge"
  done
  echo "dpkg -i $names, a bake from /usr/bin/skybake, dpkg --purge: nothing left"
fi
echo "deb package: OK"
