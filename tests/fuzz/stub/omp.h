#pragma once
// A single-threaded stand-in for the OpenMP runtime API, for the fuzz build only (see
// tests/fuzz/CMakeLists.txt): without -fopenmp the pragmas are ignored and these are the answers
// a one-thread runtime would give.
inline int omp_get_max_threads() { return 1; }
inline int omp_get_thread_num() { return 0; }
inline int omp_get_num_threads() { return 1; }
inline int omp_in_parallel() { return 0; }
