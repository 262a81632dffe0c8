// pcsg-mpi.so: the MPI calls of mpi_api.h over Open MPI (or any MPI), loaded by pcsg with
// dlopen only when it runs under mpirun or srun.
#include <mpi.h>

#include <algorithm>
#include <climits>
#include <cstring>
#include <vector>

#include "mpi_api.h"

namespace {

std::vector<MPI_Request> pending;

int init(int* rank, int* size) {
    int provided = 0;
    if (MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided) != MPI_SUCCESS) return 1;
    MPI_Comm_rank(MPI_COMM_WORLD, rank);
    MPI_Comm_size(MPI_COMM_WORLD, size);
    return 0;
}

int isend(int dest, int tag, const void* data, int64_t bytes) {
    if (bytes > INT_MAX) return 1;
    MPI_Request request;
    const int rc =
        MPI_Isend(data, static_cast<int>(bytes), MPI_BYTE, dest, tag, MPI_COMM_WORLD, &request);
    if (rc == MPI_SUCCESS) pending.push_back(request);
    return rc == MPI_SUCCESS ? 0 : 1;
}

int sendsPending() {
    auto done = [](MPI_Request& r) {
        int flag = 0;
        MPI_Test(&r, &flag, MPI_STATUS_IGNORE);
        return flag != 0;
    };
    pending.erase(std::remove_if(pending.begin(), pending.end(), done), pending.end());
    return static_cast<int>(pending.size());
}

int probe(int* source, int* tag, int64_t* bytes) {
    int flag = 0;
    MPI_Status status;
    MPI_Iprobe(MPI_ANY_SOURCE, MPI_ANY_TAG, MPI_COMM_WORLD, &flag, &status);
    if (!flag) return 0;
    int count = 0;
    MPI_Get_count(&status, MPI_BYTE, &count);
    *source = status.MPI_SOURCE;
    *tag = status.MPI_TAG;
    *bytes = count;
    return 1;
}

int recv(int source, int tag, void* data, int64_t bytes) {
    if (bytes > INT_MAX) return 1;
    return MPI_Recv(data, static_cast<int>(bytes), MPI_BYTE, source, tag, MPI_COMM_WORLD,
                    MPI_STATUS_IGNORE) == MPI_SUCCESS
               ? 0
               : 1;
}

int allreduceMax(int value, int* result) {
    return MPI_Allreduce(&value, result, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD) == MPI_SUCCESS ? 0
                                                                                             : 1;
}

void abortAll(int code) {
    MPI_Abort(MPI_COMM_WORLD, code);
}

void finalize() {
    while (sendsPending() > 0) {
    }
    MPI_Finalize();
}

void processorName(char* name, int capacity) {
    if (capacity <= 0) return;
    char buffer[MPI_MAX_PROCESSOR_NAME + 1] = {};
    int length = 0;
    MPI_Get_processor_name(buffer, &length);
    const int n = std::min(capacity - 1, std::max(0, length));
    std::memcpy(name, buffer, static_cast<size_t>(n));
    name[n] = '\0';
}

const PcsgMpiApi api{kPcsgMpiApiVersion, init,     isend,    sendsPending, probe, recv,
                     allreduceMax,       abortAll, finalize, processorName};

}  // namespace

extern "C" __attribute__((visibility("default"))) const PcsgMpiApi* pcsg_mpi_api() {
    return &api;
}
