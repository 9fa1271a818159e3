#pragma once
/// Ending a program under a memory limit without hanging in exit().
///
/// OpenBLAS (CHOLMOD's BLAS) starts a worker thread per core when it is
/// loaded, before main(); each worker first allocates a 128 MiB buffer and,
/// when that fails, retries for ever. Under an address-space or data limit
/// below that (RLIMIT_AS or RLIMIT_DATA, e.g. `ulimit -v 70000`), every
/// program linked with it then hangs in exit(), whatever it did before
/// (`--help`, an error, std::bad_alloc): OpenBLAS's shutdown, a library
/// destructor run by exit(), joins the worker. Setting OpenBLAS to one thread
/// in main() is too late (the worker exists and stays stuck), and the
/// environment (OPENBLAS_NUM_THREADS) is read before main().

namespace icd::experiments {

/// Called first in main() (guarded_main and benchmark_preamble do): when an
/// address-space or data limit is set, registers an exit handler that
/// flushes the standard streams and ends the process with _exit(status)
/// before the libraries' destructors run. Static objects constructed before
/// the call are then not destroyed. Without such a limit it does nothing.
/// Idempotent.
void exit_without_library_shutdown_under_memory_limits();

}  // namespace icd::experiments
