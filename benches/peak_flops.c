// The peak that benches/compare_pinocchio.py reports its kernels' flop rates against: double
// flops per second one core issues with fused multiply-adds at the widest vectors it has
// (512-bit where the CPU has AVX-512F, else 256-bit with FMA), measured, since neither the
// number of FMA pipes nor the clock under load can be read off /proc/cpuinfo. Built by the
// script with gcc; x86-64 only; not part of the library.
//
//   peak_flops 512|256
//
// Prints one JSON line: {"bits", "gflops"} (the best of 7 passes of 0.1 s or more).
// Twelve independent accumulators per loop iteration: more than two pipes times a
// four-cycle latency, so that the pipes, not the dependencies, bound the loop.
#include <stdio.h>
#include <string.h>
#include <time.h>

static double now(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return t.tv_sec + t.tv_nsec * 1e-9;
}

#define F512(r) "vfmadd231pd %%zmm14, %%zmm15, %%zmm" #r "\n"
#define F256(r) "vfmadd231pd %%ymm14, %%ymm15, %%ymm" #r "\n"
#define TWELVE(F) F(0) F(1) F(2) F(3) F(4) F(5) F(6) F(7) F(8) F(9) F(10) F(11)
#define CLOBBERS "xmm0", "xmm1", "xmm2", "xmm3", "xmm4", "xmm5", "xmm6", "xmm7", "xmm8", \
                 "xmm9", "xmm10", "xmm11"

__attribute__((target("avx512f"))) static void run512(long iterations) {
  __asm__ volatile("vxorpd %%zmm14, %%zmm14, %%zmm14\nvxorpd %%zmm15, %%zmm15, %%zmm15" ::
                       : "xmm14", "xmm15");
  for (long i = 0; i < iterations; i++) __asm__ volatile(TWELVE(F512)::: CLOBBERS);
  __asm__ volatile("vzeroupper");
}

__attribute__((target("avx2,fma"))) static void run256(long iterations) {
  __asm__ volatile("vxorpd %%ymm14, %%ymm14, %%ymm14\nvxorpd %%ymm15, %%ymm15, %%ymm15" ::
                       : "xmm14", "xmm15");
  for (long i = 0; i < iterations; i++) __asm__ volatile(TWELVE(F256)::: CLOBBERS);
  __asm__ volatile("vzeroupper");
}

int main(int argc, char** argv) {
  int bits = argc > 1 ? (strcmp(argv[1], "512") == 0 ? 512 : 256) : 256;
  void (*run)(long) = bits == 512 ? run512 : run256;
  double lanes = bits / 64, best = 0.0;
  long iterations = 1 << 20;
  run(iterations);  // the clock and the vector unit warmed up
  for (int pass = 0; pass < 7; pass++) {
    double t = now(), dt;
    long done = 0;
    do {
      run(iterations);
      done += iterations;
      dt = now() - t;
    } while (dt < 0.1);
    double gflops = done * 12.0 * lanes * 2.0 / dt / 1e9;
    if (gflops > best) best = gflops;
  }
  printf("{\"bits\": %d, \"gflops\": %.2f}\n", bits, best);
  return 0;
}
