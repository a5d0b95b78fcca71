/* Test harness only, never shipped: Windows 10 and later provide bcryptprimitives.dll, whose
 * ProcessPrng the Rust standard library uses for random hash seeds. Debian's Wine 8 lacks it, so
 * the wine test puts this stand-in next to its master, built on BCryptGenRandom. */
#include <windows.h>
#include <bcrypt.h>

__declspec(dllexport) BOOL WINAPI ProcessPrng(PBYTE data, SIZE_T len) {
  return BCryptGenRandom(NULL, data, (ULONG)len, BCRYPT_USE_SYSTEM_PREFERRED_RNG) == 0;
}
