#!/usr/bin/env bash
# Runs a Windows program under Debian's wine64 in the project's own Wine prefix
# (target/wineprefix, made on first use: about 10 s), with the ProcessPrng stand-in that
# scripts/windows/build.sh builds installed into its system32. GL goes through Wine's WGL to the
# X server's GLX (Mesa llvmpipe under Xvfb): DISPLAY must name an X server.
#
#   scripts/windows/wine.sh PROGRAM.exe [ARGS...]
set -euo pipefail
root="$(cd "$(dirname "$0")/../.." && pwd)"
target_dir="${CARGO_TARGET_DIR:-$root/target}"
export WINEPREFIX="${WINEPREFIX:-$target_dir/wineprefix}"
export WINEDEBUG="${WINEDEBUG:--all}"
export PATH="/usr/lib/wine:$PATH"
command -v wine64 >/dev/null || { echo "scripts/windows/wine.sh: wine64 not found (apt install wine64)" >&2; exit 2; }
stub="$target_dir/windows/debug/wine/bcryptprimitives.dll"
[ -f "$stub" ] || stub="$target_dir/windows/release/wine/bcryptprimitives.dll"
sys32="$WINEPREFIX/drive_c/windows/system32"
if [ ! -f "$sys32/bcryptprimitives.dll" ]; then
  [ -f "$stub" ] || { echo "scripts/windows/wine.sh: run scripts/windows/build.sh first" >&2; exit 2; }
  # One prefix set-up at a time (tests start several programs at once).
  exec 9>"$target_dir/wineprefix.lock"
  flock 9
  if [ ! -f "$sys32/bcryptprimitives.dll" ]; then
    # No Mono or Gecko: their install prompts would wait for a click.
    WINEDLLOVERRIDES="mscoree=;mshtml=" wine64 wineboot -i >/dev/null 2>&1
    wineserver -w
    cp "$stub" "$sys32/bcryptprimitives.dll"
  fi
  flock -u 9
fi
exec wine64 "$@"
