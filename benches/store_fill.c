// The non-temporal fill that benches/compare_pinocchio.py times beside the C library's
// `memset` for its store-bound ceiling: zeros into an array a whole cache line at a time
// with non-temporal stores (straight to memory, each line neither read first nor kept in the
// caches), as the library's kernels write large outputs. On some processors this fills a
// large array much faster than `memset` (about 30 % on an Intel Xeon measured), so a ceiling
// from `memset` alone is no bound there. Built by the script with gcc as a shared library
// and called through ctypes; x86-64 only; not part of the library.
#include <emmintrin.h>
#include <stddef.h>
#include <stdint.h>

// `count` doubles from `at` set to zero: single stores up to the first 64-byte boundary,
// whole lines by non-temporal 16-byte stores, single stores for the rest, then a fence.
void fill_nt(double* at, size_t count) {
  size_t i = 0;
  while (i < count && ((uintptr_t)(at + i) & 63) != 0) at[i++] = 0.0;
  __m128d z = _mm_setzero_pd();
  for (; i + 8 <= count; i += 8) {
    _mm_stream_pd(at + i, z);
    _mm_stream_pd(at + i + 2, z);
    _mm_stream_pd(at + i + 4, z);
    _mm_stream_pd(at + i + 6, z);
  }
  for (; i < count; i++) at[i] = 0.0;
  _mm_sfence();
}
