// The few MPI calls pcsg makes, as a table of C functions that the pcsg-mpi.so module
// (mpi_module.cpp, linked with Open MPI) exports. pcsg does not link MPI: it loads the
// module only when it was started by mpirun or srun (tools/cli/mpi_session.h), so a plain
// `pcsg render` pays nothing for MPI (no libmpi and its dependencies, ~6 ms and ~4 MB).
//
// Every call is made from one thread (the main thread: MPI_THREAD_FUNNELED). Nothing
// blocks but init, allreduceMax and finalize: sends are MPI_Isend, kept until done, and
// receiving is a probe that does not wait (Open MPI's blocking calls spin a core, which a
// rank rendering on all cores cannot spare).
#pragma once

#include <cstdint>

extern "C" {

struct PcsgMpiApi {
    int version;  // kPcsgMpiApiVersion
    // MPI_Init_thread; sets the rank and the number of ranks. 0 on success.
    int (*init)(int* rank, int* size);
    // Starts sending `bytes` bytes (kept alive by the caller until sendsPending is 0).
    int (*isend)(int dest, int tag, const void* data, int64_t bytes);
    // Completes what it can of the sends started; returns how many are still pending.
    int (*sendsPending)();
    // Whether a message has arrived (any source, any tag); sets its source, tag and size.
    int (*probe)(int* source, int* tag, int64_t* bytes);
    // Receives the probed message (source and tag as probe set them).
    int (*recv)(int source, int tag, void* data, int64_t bytes);
    // MPI_Allreduce of one int with MPI_MAX over all ranks (blocking).
    int (*allreduceMax)(int value, int* result);
    // MPI_Abort: ends every rank.
    void (*abort)(int code);
    void (*finalize)();
    // The processor (host) name.
    void (*processorName)(char* name, int capacity);
};

// The module's one exported function.
const PcsgMpiApi* pcsg_mpi_api();
}

constexpr int kPcsgMpiApiVersion = 1;
