// The figures a user reads (the paper's Table 1 and more) come from one record,
// printed for people and as JSON (`--json`). Every field is optional: a command fills
// in what it measured, and only filled fields are printed.
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <ostream>
#include <string>

namespace pcsg::tools {

struct Stats {
    std::string scene;
    std::optional<uint32_t> width, height;
    std::optional<uint64_t> rays;  // all rays traced (camera, shadow, reflection)
    std::optional<double> raysPerSecond;
    std::optional<uint64_t> primitiveEquivalence;  // primitives the expanded tree holds
    std::optional<uint64_t> expandedNodes;         // all nodes of the expanded tree
    std::optional<uint64_t> graphBytes;            // the cyclic graph in memory
    std::optional<uint64_t> expandedBytes;         // the expanded tree in memory
    std::optional<uint64_t> peakRssBytes;          // the command's peak resident set
    std::optional<double> seconds;                 // wall time of the main job
    std::optional<double> parseSeconds;            // compiling the scene

    nlohmann::json toJson() const;
    void print(std::ostream& out) const;  // aligned "label: value" lines
};

// This process's peak resident set size in bytes (from getrusage).
uint64_t peakRssBytes();
// The whole command's: the larger of this process's and that of any child it waited for
// (RUSAGE_CHILDREN), which is what /usr/bin/time -v reports for it.
uint64_t wholeCommandPeakRssBytes();
// "12.3 MB", "1.2 GB", "512 B".
std::string humanBytes(uint64_t bytes);

}  // namespace pcsg::tools
