/*
 * Wine 8 (Debian 12's wine64) has no bcryptprimitives.dll, whose ProcessPrng Rust's standard
 * library imports on Windows. This stand-in, placed beside the .exe under Wine only (never
 * shipped: real Windows 10+ has the DLL), answers it with RtlGenRandom (advapi32's
 * SystemFunction036), which Wine implements.
 *
 *   x86_64-w64-mingw32-gcc -shared -O2 -o bcryptprimitives.dll bcryptprimitives.c -ladvapi32
 */
#include <windows.h>

BOOLEAN WINAPI SystemFunction036(PVOID buffer, ULONG length);

__declspec(dllexport) BOOL WINAPI ProcessPrng(PBYTE data, SIZE_T length) {
    while (length > 0) {
        ULONG n = length > 0x10000000 ? 0x10000000 : (ULONG)length;
        if (!SystemFunction036(data, n)) return FALSE;
        data += n;
        length -= n;
    }
    return TRUE;
}
