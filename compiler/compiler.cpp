// compileSource and compileFile: the three phases in a row. See compiler.h.
#include "compiler.h"

#include <fmt/format.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "builder.h"
#include "fast_code.h"
#include "fold_constants.h"
#include "lexer.h"
#include "parser.h"

namespace pcsg {

std::optional<Graph> compileSource(std::string_view fileName, std::string_view text,
                                   Diagnostics& diags, const CompileOptions& options) {
    const size_t errorsBefore = diags.count();
    const uint32_t file = diags.addFile(std::string(fileName), text);
    if (text.size() > kMaxSourceBytes) {
        diags.error(FileLoc{file, 0, 0},
                    fmt::format("the file is too large ({} bytes; the limit is {} MB)", text.size(),
                                kMaxSourceBytes >> 20));
        return std::nullopt;
    }
    const Source src(text, file);
    const TokenStream tokens = lex(src, diags);
    if (!tokens.complete) return std::nullopt;  // the rest of the file was not read
    if (diags.count() == errorsBefore && tokens.tokens.size() == 1) {
        diags.error(FileLoc{file, 1, 1},
                    "the file is empty: a scene needs at least an axiom, "
                    "such as 'sphere'");
        return std::nullopt;
    }
    const Ast ast = parse(src, tokens, diags);
    if (diags.errors().size() >= Diagnostics::kMaxErrors) return std::nullopt;
    // The builder's checks run even after syntax errors (they are told what was dropped),
    // so that one run reports as many independent errors as it can.
    std::optional<Graph> g = build(src, tokens, ast, diags);
    if (diags.count() != errorsBefore) return std::nullopt;
    if (g && options.foldConstants) foldConstantParameters(*g);
    if (g) buildFastCode(*g);  // last: it translates the code as it now stands
    return g;
}

std::optional<Graph> compileFile(const std::string& path, std::string& storage,
                                 Diagnostics& diags) {
    storage.clear();
    std::error_code ec;
    if (std::filesystem::is_directory(path, ec)) {
        const uint32_t file = diags.addFile(path, storage);
        diags.error(FileLoc{file, 0, 0}, "cannot read the file: it is a directory");
        return std::nullopt;
    }
    std::ifstream in(path, std::ios::binary);
    auto fail = [&](const std::string& why) -> std::optional<Graph> {
        const uint32_t file = diags.addFile(path, storage);
        diags.error(FileLoc{file, 0, 0}, why);
        return std::nullopt;
    };
    if (!in) return fail(fmt::format("cannot open the file: {}", std::strerror(errno)));
    in.seekg(0, std::ios::end);
    const std::streamoff size = in.tellg();
    if (size < 0) return fail("cannot read the file (is it a directory?)");
    if (static_cast<uint64_t>(size) > kMaxSourceBytes)
        return fail(fmt::format("the file is too large ({} bytes; the limit is {} MB)", size,
                                kMaxSourceBytes >> 20));
    in.seekg(0, std::ios::beg);
    storage.resize(static_cast<size_t>(size));
    if (size > 0 && !in.read(storage.data(), size)) {
        storage.clear();
        return fail("cannot read the file (is it a directory?)");
    }
    return compileSource(path, storage, diags);
}

}  // namespace pcsg
