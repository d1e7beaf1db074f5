#pragma once
// A hot function compiled twice, for x86-64-v3 (AVX2, FMA) and for baseline x86-64, the
// copy chosen when the program loads by what the CPU has (GCC's target_clones): faster
// where it can be, and the build still runs on any x86-64 machine. Off under the
// sanitizers, whose instrumentation and load-time resolvers do not mix well.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && !defined(__SANITIZE_ADDRESS__) && \
    !defined(__SANITIZE_THREAD__)
#define LUMAR_AVX2_CLONES __attribute__((target_clones("arch=x86-64-v3", "default")))
#else
#define LUMAR_AVX2_CLONES
#endif
