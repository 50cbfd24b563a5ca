#!/usr/bin/env bash
# Release artefacts, built on this Linux machine (docs/platforms.md):
#   splatgl-<version>-x86_64-linux.tar.gz
#     bin/splatgl, lib/libsplatgl.so, lib/libsplatgl.a, lib/pkgconfig/splatgl.pc,
#     include/splatgl.h, LICENSE-MIT, LICENSE-APACHE, README.md
#   splatgl-<version>-x86_64-windows.zip (mingw-w64 cross build, scripts/windows/build.sh)
#     bin/splatgl.exe, bin/splatgl.dll, lib/libsplatgl.dll.a (import library),
#     lib/splatgl.def (MSVC: `lib /def:splatgl.def /machine:x64` makes splatgl.lib),
#     include/splatgl.h, LICENSE-MIT, LICENSE-APACHE, README.md
# Each archive is listed and checked against that list before the script says where it is.
#
#   scripts/dist.sh [--dev] [OUT]     (OUT: target/dist; --dev: the dev profile, for tests)
set -euo pipefail
cd "$(dirname "$0")/.."
profile=release dir=release flag=--release
if [ "${1:-}" = --dev ]; then
  profile=dev dir=debug flag=
  shift
fi
target_dir="${CARGO_TARGET_DIR:-target}"
out=${1:-$target_dir/dist}
version=$(sed -n 's/^version = "\(.*\)"/\1/p' crates/splatgl-cli/Cargo.toml | head -1)
mkdir -p "$out"
out=$(cd "$out" && pwd)
docs=(LICENSE-MIT LICENSE-APACHE README.md)

# Linux.
echo "== $(date +%T) Linux ($profile)"
cargo build --locked --quiet --profile "$profile" -p splatgl-cli -p splatgl-capi
name="splatgl-$version-x86_64-linux"
stage="$out/$name"
rm -rf "$stage"
mkdir -p "$stage/bin" "$stage/lib/pkgconfig" "$stage/include"
cp "$target_dir/$dir/splatgl" "$stage/bin/"
# The library has no SONAME: linked as -lsplatgl it is found by this file name.
cp "$target_dir/$dir/libsplatgl_capi.so" "$stage/lib/libsplatgl.so"
cp "$target_dir/$dir/libsplatgl_capi.a" "$stage/lib/libsplatgl.a"
cp crates/splatgl-capi/include/splatgl.h "$stage/include/"
cat > "$stage/lib/pkgconfig/splatgl.pc" <<EOF
prefix=\${pcfiledir}/../..
libdir=\${prefix}/lib
includedir=\${prefix}/include

Name: splatgl
Description: Renderer for 3D Gaussian splats (glTF KHR_gaussian_splatting) for C and C++ GL hosts
Version: $version
Libs: -L\${libdir} -lsplatgl
Libs.private: -lpthread -ldl -lm
Cflags: -I\${includedir}
EOF
cp "${docs[@]}" "$stage/"
tar -C "$out" -czf "$out/$name.tar.gz" "$name"
listed=$(tar -tzf "$out/$name.tar.gz" | grep -v '/$' | sed "s|^$name/||" | sort)
want=$(printf '%s\n' bin/splatgl lib/libsplatgl.so lib/libsplatgl.a lib/pkgconfig/splatgl.pc \
  include/splatgl.h "${docs[@]}" | sort)
[ "$listed" = "$want" ] || { echo "scripts/dist.sh: $name.tar.gz holds:"$'\n'"$listed" >&2; exit 1; }

# Windows.
echo "== $(date +%T) Windows ($profile)"
win="$target_dir/windows/$dir"
./scripts/windows/build.sh $flag "$win"
name="splatgl-$version-x86_64-windows"
stage="$out/$name"
rm -rf "$stage"
mkdir -p "$stage/bin" "$stage/lib" "$stage/include"
cp "$win/splatgl.exe" "$win/splatgl.dll" "$stage/bin/"
cp "$win/libsplatgl.dll.a" "$win/splatgl.def" "$stage/lib/"
cp "$win/splatgl.h" "$stage/include/"
cp "${docs[@]}" "$stage/"
rm -f "$out/$name.zip"
(cd "$out" && zip -qr "$name.zip" "$name")
listed=$(unzip -Z1 "$out/$name.zip" | grep -v '/$' | sed "s|^$name/||" | sort)
want=$(printf '%s\n' bin/splatgl.exe bin/splatgl.dll lib/libsplatgl.dll.a lib/splatgl.def \
  include/splatgl.h "${docs[@]}" | sort)
[ "$listed" = "$want" ] || { echo "scripts/dist.sh: $name.zip holds:"$'\n'"$listed" >&2; exit 1; }

ls -l "$out"/*.tar.gz "$out"/*.zip
