// Running as one rank of an MPI job (mpirun, or Slurm's srun): pcsg detects the launcher
// from the environment it sets and only then loads pcsg-mpi.so (tools/mpi/mpi_api.h),
// built beside pcsg when CMake found MPI. A plain `pcsg render` loads no MPI library and
// prints nothing about MPI.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

struct PcsgMpiApi;

namespace pcsg::tools {

// Whether the environment says this process is one of several ranks: Open MPI's mpirun
// (OMPI_COMM_WORLD_SIZE > 1), a PMI launcher (PMI_SIZE > 1) or srun with PMIx
// (PMIX_RANK with SLURM_STEP_NUM_TASKS > 1).
bool launchedAsRanks();

// This process's rank as the launcher's environment gives it (0 when it does not).
int launcherRank();

// A statically linked pcsg cannot load pcsg-mpi.so (Open MPI's libraries need the shared
// glibc and its dynamic loader), so under a launcher it replaces itself (exec, the same
// process for the launcher) with pcsg-dynamic, the same program linked against the shared
// glibc, from beside it. Returns only when that fails, with exit status 2 and a message.
int execDynamicTwin(char** argv);

struct MpiMessage {
    int source = 0, tag = 0;
    std::vector<std::byte> bytes;
};

class MpiSession {
  public:
    // Loads pcsg-mpi.so from beside the executable and initialises MPI; nothing, with
    // `error` set, when it cannot.
    static std::unique_ptr<MpiSession> start(std::string& error);
    ~MpiSession();  // MPI_Finalize, once every send is done

    int rank() const { return rank_; }
    int size() const { return size_; }
    std::string host() const;

    // Sends the bytes (kept here until they are sent; never blocks).
    void send(int dest, int tag, std::vector<std::byte> bytes);
    // A message that has arrived, if any (never blocks); completes finished sends.
    bool receive(MpiMessage& message);
    // The maximum of `value` over every rank (every rank must call it).
    int allreduceMax(int value);
    // Ends every rank of the job with this status.
    [[noreturn]] void abortAll(int status);

  private:
    MpiSession() = default;
    void* module_ = nullptr;
    const PcsgMpiApi* api_ = nullptr;
    int rank_ = 0, size_ = 1;
    std::vector<std::vector<std::byte>> inFlight_;
};

// A value as bytes and back (the same executable on every rank).
template <class T>
void appendBytes(std::vector<std::byte>& out, const T& value) {
    const auto* p = reinterpret_cast<const std::byte*>(&value);
    out.insert(out.end(), p, p + sizeof(T));
}

}  // namespace pcsg::tools
