#!/usr/bin/env bash
# Cross-builds splatgl for Windows on this Linux machine (mingw-w64, target
# x86_64-pc-windows-gnu) and stages what a Windows user gets, in OUT (default
# target/windows/<profile>):
#   splatgl.exe                    the command (viewer included: glutin's WGL)
#   splatgl.dll, libsplatgl.dll.a  the C library and its import library (imports "splatgl.dll")
#   splatgl.def                    its exports (MSVC: `lib /def:splatgl.def /machine:x64`)
#   splatgl.h                      the header (crates/splatgl-capi/include)
#   legacy_host.exe                examples/c/legacy_host.c built against splatgl.dll
# and, for running these under Wine only (never shipped), wine/bcryptprimitives.dll.
#
#   scripts/windows/build.sh [--release] [OUT]
#
# Needs: rustup target x86_64-pc-windows-gnu, gcc-mingw-w64-x86-64 (.ci/run installs both).
set -euo pipefail
cd "$(dirname "$0")/../.."
profile=dev dir=debug
if [ "${1:-}" = --release ]; then
  profile=release dir=release
  shift
fi
target_dir="${CARGO_TARGET_DIR:-target}"
out=${1:-$target_dir/windows/$dir}
triple=x86_64-pc-windows-gnu
cc=x86_64-w64-mingw32-gcc
for tool in "$cc" x86_64-w64-mingw32-dlltool x86_64-w64-mingw32-objdump; do
  command -v "$tool" >/dev/null || { echo "scripts/windows/build.sh: $tool not found (apt install gcc-mingw-w64-x86-64)" >&2; exit 2; }
done

cargo build --locked --quiet --target "$triple" --profile "$profile" -p splatgl-cli -p splatgl-capi
built="$target_dir/$triple/$dir"
mkdir -p "$out/wine"
cp "$built/splatgl.exe" "$out/splatgl.exe"
# cargo names the DLL after the crate; C hosts link -lsplatgl, as cargo-c names it.
cp "$built/splatgl_capi.dll" "$out/splatgl.dll"
cp crates/splatgl-capi/include/splatgl.h "$out/splatgl.h"

# The exports: the header's functions, which must be exactly the DLL's.
{
  echo "LIBRARY splatgl.dll"
  echo "EXPORTS"
  grep -oE '\bsplatgl_[a-z0-9_]+\(' "$out/splatgl.h" | tr -d '(' | sort -u
} > "$out/splatgl.def"
exports=$(x86_64-w64-mingw32-objdump -p "$out/splatgl.dll" |
  awk '/\[Ordinal\/Name Pointer\] Table/ { t = 1; next } t && NF == 0 { t = 0 } t { print $NF }' | sort)
if [ "$exports" != "$(tail -n +3 "$out/splatgl.def")" ]; then
  echo "scripts/windows/build.sh: splatgl.dll's exports differ from splatgl.h's functions:" >&2
  diff <(echo "$exports") <(tail -n +3 "$out/splatgl.def") >&2 || true
  exit 1
fi
x86_64-w64-mingw32-dlltool -d "$out/splatgl.def" -D splatgl.dll -l "$out/libsplatgl.dll.a"

# The legacy C host, as a C programmer on Windows builds it against the shipped files.
"$cc" -std=c99 -Wall -Wextra -Werror -I"$out" -Iexamples/c examples/c/legacy_host.c \
  -L"$out" -lsplatgl -lopengl32 -lgdi32 -o "$out/legacy_host.exe"

# Wine 8 lacks bcryptprimitives.dll (Rust's std imports ProcessPrng from it).
"$cc" -shared -O2 -o "$out/wine/bcryptprimitives.dll" scripts/windows/bcryptprimitives.c -ladvapi32
echo "scripts/windows/build.sh: $out"
