// The diagnostics corpus: every tests/diagnostics/*.pcsg carries the errors it must get
// in comments, as clox's tests do:
//
//   S if(sine(c) > 0, 2, 1)     // expect-error: 3:6: unknown function 'sine'
//
// (line:column exactly, then a substring of the message). One test per file: the file
// must fail to compile with exactly those errors, each printed as
// "file:line:col: error: message", the source line and a caret.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "compiler.h"

namespace pcsg {
namespace {

namespace fs = std::filesystem;

fs::path corpusDir() {
    return fs::path(PCSG_SOURCE_DIR) / "tests" / "diagnostics";
}

std::vector<std::string> corpusFiles() {
    std::vector<std::string> files;
    std::error_code ec;
    for (const auto& entry : fs::directory_iterator(corpusDir(), ec))
        if (entry.path().extension() == ".pcsg") files.push_back(entry.path().filename().string());
    std::sort(files.begin(), files.end());
    return files;
}

struct Expected {
    uint32_t line, column;
    std::string message;  // a substring of the actual message
};

std::vector<Expected> expectations(const std::string& text) {
    std::vector<Expected> out;
    static const std::regex re(R"(// expect-error: (\d+):(\d+): ([^\r\n]*))");
    for (std::sregex_iterator it(text.begin(), text.end(), re), end; it != end; ++it) {
        std::string msg = (*it)[3].str();
        while (!msg.empty() && msg.back() == ' ') msg.pop_back();
        out.push_back({static_cast<uint32_t>(std::stoul((*it)[1].str())),
                       static_cast<uint32_t>(std::stoul((*it)[2].str())), msg});
    }
    return out;
}

class Corpus : public testing::TestWithParam<std::string> {};

TEST_P(Corpus, GivesExactlyTheExpectedErrors) {
    const fs::path path = corpusDir() / GetParam();
    std::string storage;
    Diagnostics diags;
    const auto graph = compileFile(path.string(), storage, diags);
    const std::vector<Expected> expected = expectations(storage);
    ASSERT_FALSE(expected.empty()) << "no '// expect-error: L:C: message' comment in " << path;
    const std::string printed = diags.format();
    EXPECT_FALSE(graph) << "the file compiled";

    std::vector<bool> used(diags.errors().size(), false);
    for (const Expected& e : expected) {
        bool found = false;
        for (size_t i = 0; i < diags.errors().size() && !found; ++i) {
            const Diagnostic& d = diags.errors()[i];
            if (used[i] || d.loc.line != e.line || d.loc.column != e.column) continue;
            if (d.message.find(e.message) == std::string::npos) continue;
            used[i] = found = true;
        }
        EXPECT_TRUE(found) << "expected " << e.line << ":" << e.column << ": " << e.message
                           << "\nbut the compiler said:\n"
                           << printed;
    }
    for (size_t i = 0; i < diags.errors().size(); ++i) {
        const Diagnostic& d = diags.errors()[i];
        EXPECT_TRUE(used[i]) << "unexpected error " << d.loc.line << ":" << d.loc.column << ": "
                             << d.message << "\n(add '// expect-error: " << d.loc.line << ":"
                             << d.loc.column << ": ...' to the file if it is right)";
        // Each error is printed as a C compiler does.
        const std::string head = path.string() + ":" + std::to_string(d.loc.line) + ":" +
                                 std::to_string(d.loc.column) + ": error: " + d.message + "\n";
        EXPECT_NE(printed.find(head), std::string::npos) << printed;
    }
    // A caret line for every error with a position.
    size_t carets = 0;
    std::istringstream lines(printed);
    for (std::string l; std::getline(lines, l);)
        if (!l.empty() && l.back() == '^' && l.find_first_not_of(" \t^") == std::string::npos)
            ++carets;
    EXPECT_EQ(carets, diags.errors().size()) << printed;
}

std::string testName(const testing::TestParamInfo<std::string>& info) {
    std::string s = fs::path(info.param).stem().string();
    for (char& c : s)
        if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
    return s;
}

INSTANTIATE_TEST_SUITE_P(Diagnostics, Corpus, testing::ValuesIn(corpusFiles()), testName);

TEST(CorpusSize, CoversTheLanguage) {
    // Every kind of bad input in docs/language.md section 8 and every compile-time error of
    // sections 1-7 has a file; the corpus only grows.
    EXPECT_GE(corpusFiles().size(), 30u);
}

}  // namespace
}  // namespace pcsg
