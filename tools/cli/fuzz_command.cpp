// pcsg fuzz: differential testing of the two renderers on random systems (docs/fuzz.md).
//
// Each system comes from tools/fuzz/generator.h (a function of the campaign's seed and
// its number), is verified exactly as `pcsg verify` verifies a scene (verify_scene.h:
// the same renders, the same box filter, the same thresholds), and, when the images
// differ, is shrunk on its syntax tree (tools/fuzz/shrinker.h) while they still differ.
// Each disagreement leaves DIR/case-K/ with the shrunk system, the original, the
// images of the shrunk one (native.png, povray.png, diff.png) and what.txt, one line
// saying what differs.
#include <fmt/format.h>
#include <unistd.h>

#include <chrono>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>

#include "child_process.h"
#include "commands.h"
#include "coverage.h"
#include "generator.h"
#include "image_helper.h"
#include "renders.h"
#include "shrinker.h"
#include "verify_scene.h"

namespace pcsg::tools {

namespace fs = std::filesystem;

namespace {

struct FuzzOptions : SceneVerifyOptions {
    int count = 0;
    int first = 0;  // --first: the number of the first system (to rerun one of a campaign)
    double minutes = 0;
    std::string seedText;  // decimal or 0x hex; none: from the time
    std::string outDir;
    bool json = false;
    int shrinkTries = 150;
    double shrinkMinutes = 10;
    bool generateOnly = false;
};

struct Campaign {
    uint64_t seed = 0;
    fs::path root;
    int systems = 0, agree = 0, errors = 0;
    int flaky = 0;                      // systems that differed once and then agreed
    std::vector<std::string> disagree;  // case directories
    std::map<std::string, int> coverage;
    std::ostream* log = &std::cout;  // the per-system lines (stderr with --json)
};

bool writeText(const fs::path& path, const std::string& text) {
    std::ofstream out(path, std::ios::binary);
    out << text;
    return bool(out);
}

std::string metricsLine(const SceneResult& r) {
    if (r.metrics.width == 0) return r.message;
    const auto& m = r.metrics;
    return fmt::format(
        "{}: {:.2f}% of pixels off, mean abs error {:.4f}, largest difference "
        "{:.3f} at ({}, {})",
        r.message, 100 * m.shareOff, m.meanAbsError, m.maxError, m.maxX, m.maxY);
}

// Shrinks the system of a disagreement and writes DIR/case-K/; returns its directory.
std::string writeCase(const std::string& original, const FuzzOptions& o, Campaign& c,
                      uint64_t systemSeed) {
    const std::string name = fmt::format("case-{}", c.disagree.size() + 1);
    const fs::path dir = c.root / name, work = c.root / "work";
    std::error_code ec;
    fs::create_directories(dir, ec);
    writeText(dir / "original.pcsg", original);
    const fs::path probe = work / "shrink.pcsg";
    const fuzz::StillFails stillDiffers = [&](const std::string& text) {
        writeText(probe, text);
        const SceneResult r = verifyScene(probe.string(), "shrink", o, work);
        std::cerr << (r.status == 1 ? '+' : '.') << std::flush;
        return r.status == 1;
    };
    std::cerr << "shrinking " << name << " ";
    const fuzz::ShrinkResult s = fuzz::shrinkSystem(
        original, stillDiffers, {.maxTries = o.shrinkTries, .maxSeconds = o.shrinkMinutes * 60});
    std::cerr << "\n";
    fs::remove_all(work / "shrink", ec);
    writeText(dir / "shrunk.pcsg", s.text);
    const SceneResult r = verifyScene((dir / "shrunk.pcsg").string(), name, o, c.root);
    const std::string what = fmt::format(
        "system seed {:#018x}: {}; shrunk from {} to {} bytes ({} reductions kept of {} tried)\n",
        systemSeed, metricsLine(r), original.size(), s.text.size(), s.accepted, s.tries);
    writeText(dir / "what.txt", what);
    *c.log << "  " << name << ": " << what;
    return dir.string();
}

// Generates, verifies and (on a disagreement) shrinks system `index`.
void runSystem(int index, const FuzzOptions& o, Campaign& c) {
    const uint64_t seed = fuzz::systemSeed(c.seed, uint64_t(index));
    const std::string text = fuzz::generateSystem(seed);
    for (const std::string& f : fuzz::featuresOf(text)) ++c.coverage[f];
    const fs::path work = c.root / "work";
    const std::string dir = fmt::format("system-{}", index);
    const fs::path file = work / (dir + ".pcsg");
    writeText(file, text);
    SceneResult r = verifyScene(file.string(), dir, o, work);
    if (r.status == 1) {
        // A difference must show twice: a POV-Ray that fails once (it can time out
        // starting its threads on a loaded machine) is no disagreement.
        SceneResult again = verifyScene(file.string(), dir, o, work);
        if (again.status != 1) {
            *c.log << fmt::format("system {}: differed once ({}), but not again\n", index,
                                  metricsLine(r));
            ++c.flaky;
            r = std::move(again);
        }
    }
    ++c.systems;
    const char* verdict = r.status == 0 ? "AGREE" : (r.status == 1 ? "DIFFER" : "ERROR");
    *c.log << fmt::format("system {} (seed {:#018x}): {} ({})\n", index, seed, verdict,
                          metricsLine(r))
           << std::flush;
    std::error_code ec;
    if (r.status == 0) {
        ++c.agree;
        fs::remove_all(work / dir, ec);
        fs::remove(file, ec);
    } else if (r.status == 1) {
        c.disagree.push_back(writeCase(text, o, c, seed));
    } else {
        ++c.errors;  // kept in DIR/work for a look
    }
}

uint64_t campaignSeed(const FuzzOptions& o) {
    if (o.seedText.empty())
        return fuzz::mix64(uint64_t(std::time(nullptr)) ^ (uint64_t(getpid()) << 32));
    return std::stoull(o.seedText, nullptr, 0);
}

void printSummary(const Campaign& c, const FuzzOptions& o, double seconds) {
    if (o.json) {
        nlohmann::json j;
        j["seed"] = c.seed;
        j["systems"] = c.systems;
        j["agree"] = c.agree;
        j["errors"] = c.errors;
        j["differed_once"] = c.flaky;
        j["disagree"] = c.disagree;
        nlohmann::json cov = nlohmann::json::object();
        for (const std::string& f : fuzz::featureNames()) {
            const auto it = c.coverage.find(f);
            cov[f] = it == c.coverage.end() ? 0 : it->second;
        }
        j["coverage"] = cov;
        std::cout << j.dump(2) << "\n";
        return;
    }
    std::string uncovered;
    for (const std::string& f : fuzz::featureNames())
        if (!c.coverage.count(f)) uncovered += " " + f;
    std::cout << fmt::format(
        "seed {:#x}: {} system(s) in {:.0f} s: {} agree ({} after differing once), {} differ, {} "
        "could not run{}\n",
        c.seed, c.systems, seconds, c.agree, c.flaky, c.disagree.size(), c.errors,
        uncovered.empty() ? "; every feature covered" : "; not covered:" + uncovered);
    if (!c.disagree.empty() || c.errors > 0) std::cout << "cases in " << c.root.string() << "\n";
}

// Checks what the renders need; false (with the error printed) when something is missing.
bool prepare(FuzzOptions& o, Campaign& c) {
    try {
        c.seed = campaignSeed(o);
    } catch (const std::exception&) {
        std::cerr << "pcsg fuzz: --seed wants a whole number (decimal or 0x hex), not '"
                  << o.seedText << "'\n";
        return false;
    }
    if (!inPath("povray")) {
        std::cerr << "pcsg fuzz: " << kPovrayInstallHint << "\n";
        return false;
    }
    if (const auto helper = findImageHelper()) {
        o.imageHelper = *helper;
    } else {
        std::cerr << "pcsg fuzz: " << missingImageHelperMessage() << "\n";
        return false;
    }
    c.root = o.outDir;
    if (c.root.empty()) {
        char tmpl[] = "/tmp/pcsg-fuzz-XXXXXX";
        if (!mkdtemp(tmpl)) {
            std::cerr << "pcsg fuzz: cannot create a temporary directory\n";
            return false;
        }
        c.root = tmpl;
    }
    std::error_code ec;
    fs::create_directories(c.root / "work", ec);
    if (ec) {
        std::cerr << "pcsg fuzz: cannot create " << (c.root / "work").string() << ": "
                  << ec.message() << "\n";
        return false;
    }
    return true;
}

// --generate-only: the systems' texts into DIR/system-I.pcsg, nothing rendered.
int generateOnly(const FuzzOptions& o) {
    Campaign c;
    try {
        c.seed = campaignSeed(o);
    } catch (const std::exception&) {
        std::cerr << "pcsg fuzz: --seed wants a whole number (decimal or 0x hex), not '"
                  << o.seedText << "'\n";
        return 2;
    }
    const fs::path root = o.outDir.empty() ? fs::path(".") : fs::path(o.outDir);
    std::error_code ec;
    fs::create_directories(root, ec);
    for (int i = o.first; i < o.first + std::max(o.count, 1); ++i) {
        const fs::path file = root / fmt::format("system-{}.pcsg", i);
        if (!writeText(file, fuzz::generateSystem(fuzz::systemSeed(c.seed, uint64_t(i))))) {
            std::cerr << "pcsg fuzz: cannot write " << file.string() << "\n";
            return 2;
        }
        std::cout << file.string() << "\n";
    }
    return 0;
}

int runFuzz(FuzzOptions o) {
    if (o.generateOnly) return generateOnly(o);
    Campaign c;
    if (!prepare(o, c)) return 2;
    if (o.json) c.log = &std::cerr;
    if (o.count == 0 && o.minutes == 0) o.count = 20;
    const auto start = std::chrono::steady_clock::now();
    const auto elapsed = [&] {
        return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    };
    *c.log << fmt::format("pcsg fuzz: seed {:#x}, {}, {}x{} (--ss {}), into {}\n", c.seed,
                          o.count > 0 ? fmt::format("{} system(s)", o.count)
                                      : fmt::format("for {} minute(s)", o.minutes),
                          o.width, o.height, o.ss, c.root.string());
    for (int i = o.first; o.count == 0 || i < o.first + o.count; ++i) {
        if (o.minutes > 0 && elapsed() > o.minutes * 60) break;
        runSystem(i, o, c);
    }
    printSummary(c, o, elapsed());
    std::error_code ec;
    if (c.errors == 0) fs::remove_all(c.root / "work", ec);
    if (o.outDir.empty() && c.disagree.empty() && c.errors == 0) fs::remove_all(c.root, ec);
    if (c.errors > 0) return 2;
    return c.disagree.empty() ? 0 : 1;
}

}  // namespace

void addFuzzCommand(CLI::App& app, int& status) {
    auto o = std::make_shared<FuzzOptions>();
    o->width = 80;
    o->height = 60;
    auto* cmd = app.add_subcommand(
        "fuzz",
        "Differential testing: generate random valid PCSG systems (every primitive, "
        "transformation,\n"
        "operator, both notations, rand() and choose()), verify each exactly as `pcsg verify` "
        "does\n"
        "(native render vs POV-Ray on the export, same thresholds), and shrink every system "
        "whose\n"
        "images differ into DIR/case-K/ (shrunk.pcsg, original.pcsg, native.png, povray.png, "
        "diff.png,\n"
        "what.txt). The same seed gives the same systems on every machine. Exit status: 0 all "
        "agree,\n"
        "1 one or more differ, 2 something could not run (a system that does not render counts).");
    cmd->add_option("--count", o->count, "Run N systems (default 20)")->check(CLI::PositiveNumber);
    cmd->add_option("--minutes", o->minutes, "Run for M minutes (with --count: whichever first)")
        ->check(CLI::PositiveNumber);
    cmd->add_option("--first", o->first,
                    "Start at system I of the campaign (to rerun one: --first I --count 1)")
        ->check(CLI::NonNegativeNumber);
    cmd->add_option("--seed", o->seedText,
                    "The campaign's seed, decimal or 0x hex (default: from the time; printed)");
    addImageOptions(cmd, *o);
    addThresholdOptions(cmd, *o);
    cmd->add_option("--out", o->outDir,
                    "Write the cases here (default: a temporary directory, kept only when there "
                    "are cases)");
    cmd->add_option("--shrink-tries", o->shrinkTries,
                    "Renders at most that shrinking may spend on one case")
        ->capture_default_str()
        ->check(CLI::NonNegativeNumber);
    cmd->add_flag("--generate-only", o->generateOnly,
                  "Only write the --count systems' texts into --out DIR (default: here)");
    cmd->add_flag("--json", o->json,
                  "Print one JSON object: seed, systems, agree, disagree (case directories), "
                  "coverage (systems using each feature); the per-system lines go to stderr");
    cmd->callback([o, &status] { status = runFuzz(*o); });
}

}  // namespace pcsg::tools
