#include "mpi_session.h"

#include <dlfcn.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <stdexcept>

#include "child_process.h"
#include "mpi_api.h"

namespace pcsg::tools {

namespace {

int envInt(const char* name, int fallback) {
    const char* v = std::getenv(name);
    if (!v || !*v) return fallback;
    char* end = nullptr;
    const long n = std::strtol(v, &end, 10);
    return *end == '\0' ? static_cast<int>(n) : fallback;
}

}  // namespace

bool launchedAsRanks() {
    if (envInt("OMPI_COMM_WORLD_SIZE", 1) > 1 || envInt("PMI_SIZE", 1) > 1) return true;
    return std::getenv("PMIX_RANK") && envInt("SLURM_STEP_NUM_TASKS", 1) > 1;
}

int launcherRank() {
    for (const char* name : {"OMPI_COMM_WORLD_RANK", "PMI_RANK", "PMIX_RANK"})
        if (const int r = envInt(name, -1); r >= 0) return r;
    return 0;
}

int execDynamicTwin(char** argv) {
    const std::filesystem::path twin =
        std::filesystem::path(selfExecutable()).parent_path() / "pcsg-dynamic";
    execv(twin.c_str(), argv);
    if (launcherRank() == 0)
        std::cerr << "pcsg: cannot run " << twin.string()
                  << ", which a static pcsg needs under mpirun or srun: " << std::strerror(errno)
                  << "\n";
    return 2;
}

std::unique_ptr<MpiSession> MpiSession::start(std::string& error) {
    const std::filesystem::path module =
        std::filesystem::path(selfExecutable()).parent_path() / "pcsg-mpi.so";
    std::unique_ptr<MpiSession> s(new MpiSession);
    s->module_ = dlopen(module.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!s->module_) {
        const char* why = dlerror();
        error = std::filesystem::exists(module)
                    ? "cannot load " + module.string() + ": " + (why ? why : "?")
                    : "this pcsg was built without MPI (no pcsg-mpi.so beside it): install "
                      "libopenmpi-dev and build again";
        return nullptr;
    }
    using Entry = const PcsgMpiApi* (*)();
    auto entry = reinterpret_cast<Entry>(dlsym(s->module_, "pcsg_mpi_api"));
    s->api_ = entry ? entry() : nullptr;
    if (!s->api_ || s->api_->version != kPcsgMpiApiVersion) {
        error = module.string() + " is not the module of this pcsg: build again";
        return nullptr;
    }
    if (s->api_->init(&s->rank_, &s->size_) != 0) {
        error = "MPI_Init failed";
        return nullptr;
    }
    return s;
}

MpiSession::~MpiSession() {
    if (!api_) return;
    api_->finalize();
    inFlight_.clear();
    // The module stays loaded: Open MPI's libraries do not support being unloaded.
}

std::string MpiSession::host() const {
    char name[256];
    api_->processorName(name, sizeof name);
    return name;
}

void MpiSession::send(int dest, int tag, std::vector<std::byte> bytes) {
    if (api_->sendsPending() == 0) inFlight_.clear();
    inFlight_.push_back(std::move(bytes));
    const auto& b = inFlight_.back();
    if (api_->isend(dest, tag, b.data(), static_cast<int64_t>(b.size())) != 0)
        throw std::runtime_error("MPI_Isend failed");
}

bool MpiSession::receive(MpiMessage& message) {
    if (api_->sendsPending() == 0) inFlight_.clear();
    int64_t bytes = 0;
    if (!api_->probe(&message.source, &message.tag, &bytes)) return false;
    message.bytes.resize(static_cast<size_t>(bytes));
    if (api_->recv(message.source, message.tag, message.bytes.data(), bytes) != 0)
        throw std::runtime_error("MPI_Recv failed");
    return true;
}

int MpiSession::allreduceMax(int value) {
    int result = value;
    if (api_->allreduceMax(value, &result) != 0) throw std::runtime_error("MPI_Allreduce failed");
    return result;
}

void MpiSession::abortAll(int status) {
    api_->abort(status);
    std::_Exit(status);
}

}  // namespace pcsg::tools
