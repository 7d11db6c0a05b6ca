// SPDX-License-Identifier: BSD-3-Clause
// Loops built for AVX2 as well as for the baseline, picked when the library is loaded.
#pragma once

/** \def DYNVO_VECTORIZE_FOR_AVX2
 * Put before a function whose loops the compiler vectorises: on x86-64 Linux, GCC and Clang
 * build it twice (target_clones), for AVX2 and for the baseline, and the loader picks the
 * one the CPU runs. Only the vector width differs: AVX2 alone brings no fused multiply-add,
 * and without -ffast-math no sum is reordered, so both builds give the same results bit
 * for bit. Elsewhere it expands to nothing.
 */
#if defined(__x86_64__) && defined(__linux__) &&                                       \
    (defined(__GNUC__) || defined(__clang__))
#define DYNVO_VECTORIZE_FOR_AVX2 __attribute__((target_clones("avx2", "default")))
#else
#define DYNVO_VECTORIZE_FOR_AVX2
#endif
