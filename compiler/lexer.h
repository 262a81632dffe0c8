// The lexer: .pcsg text -> tokens (docs/language.md sections 1 and 2).
//
// Three steps, each linear in the input:
//  1. scan: bytes -> raw tokens (comments and blanks dropped, each token knowing whether
//     it is the first on its line);
//  2. #define (macros.h): collect the object-like macros and expand their uses as tokens;
//  3. the newline rule: insert a Newline token where a line break ends a statement (or
//     separates items inside `{ }`), so the parser never looks at line breaks itself.
//
// Tokens do not own text: they point into the source (a macro's expansion points into
// its #define body), so a token is 12 bytes whatever it spells.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "diagnostics.h"
#include "graph.h"
#include "primitive_table.h"

namespace pcsg {

// One source text and its line table: byte offsets -> FileLoc.
class Source {
  public:
    Source(std::string_view text, uint32_t file);
    std::string_view text() const { return text_; }
    uint32_t file() const { return file_; }
    // 1-based line and column (in bytes) of a byte offset; an offset at or past the end
    // lies on the last line.
    FileLoc loc(uint32_t offset) const;

  private:
    std::string_view text_;
    uint32_t file_;
    std::vector<uint32_t> lineStarts_;
};

enum class Tok : uint8_t {
    End,        // end of the file
    Newline,    // a line break that ends a statement or separates items in { }
    Semicolon,  // ;
    Comma,      // ,
    Colon,      // :
    LParen,
    RParen,
    LBrace,
    RBrace,
    LBracket,    // [ (colour_map entries in material blocks)
    RBracket,    // ]
    Arrow,       // -> or →
    Union,       // | or ∪
    Intersect,   // & or ∩
    Difference,  // '\'
    Assign,      // =
    Eq,
    Ne,
    Lt,
    Le,
    Gt,
    Ge,
    Plus,
    Minus,
    Star,
    Slash,
    Percent,
    Caret,
    Bang,
    AndAnd,
    OrOr,
    Number,
    Ident,
    Keyword,
    Hash,  // # (only in raw tokens: #define lines never reach the parser)
};

enum class Kw : uint8_t {
    None,
    // scene directives
    Camera,
    Light,
    Background,
    Material,
    Settings,
    Fog,
    SkySphere,
    // CSG
    Paint,
    Move,
    Translate,
    Scale,
    UScale,
    RotX,
    RotY,
    RotZ,
    Rot,
    ZShear,
    FlipYZ,
    FlipXZ,
    FlipXY,
    Matrix,
    // the primitives, in PrimitiveKind order (their names are primitive_table.h's)
    Sphere,
    Cube,
    Cylinder,
    Cone,
    Tetrahedron,
    Torus,
    Plane,
    Empty,
    Tri1,
    Tri2,
    Triangle,
    // expressions
    If,
    Rand,
    Choose,
    Pi,
    E,
    Clock,  // the time (section 11): read-only values
    Frame,
    Sin,
    Cos,
    Tan,
    Asin,
    Acos,
    Atan,
    Atan2,
    Sqrt,
    Exp,
    Ln,
    Log10,
    Pow,
    Abs,
    Floor,
    Ceil,
    Min,
    Max,
    Mod,
    Clamp,
};

// Token flags.
enum : uint8_t {
    kLineStart = 1,  // the first token on its source line
    kInteger = 2,    // a Number spelled with digits only (a rule number)
    kTopLevel = 4,   // a Newline or ';' that ends a statement (not inside brackets)
    kForced = 8,     // a Newline the lexer inserted to close unbalanced brackets
};

struct Token {
    Tok kind = Tok::End;
    uint8_t flags = 0;
    Kw kw = Kw::None;
    uint8_t pad = 0;
    uint32_t offset = 0;  // into the source text
    uint32_t length = 0;

    bool is(Tok t) const { return kind == t; }
    bool isKw(Kw k) const { return kind == Tok::Keyword && kw == k; }
};

struct TokenStream {
    std::vector<Token> tokens;  // always ends with Tok::End
    // False when lexing stopped early (a NUL byte, an unterminated comment or #define
    // block, a runaway macro expansion): the tokens are then only a prefix of the file.
    bool complete = true;
};

// Where the macros of a file went, for pcsg fmt, which prints each use of a macro as its
// name and each #define as written: the #define lines and blocks, every use of a macro
// outside them (a use inside another macro's body is part of that macro's expansion),
// and for each token of the stream the use it came from.
struct MacroOrigins {
    static constexpr uint32_t kNone = UINT32_MAX;
    struct Range {
        uint32_t begin, end;  // source offsets
    };
    std::vector<Range> defines;   // from the '#' to the end of the body's last token
    std::vector<Range> uses;      // the macro's name where it is used
    std::vector<uint32_t> useOf;  // per token of the stream: an index in uses, or kNone
};

// Lexes `src` and expands its macros. Errors go to `diags`; the stream is usable (ends
// with End) even then, so that the parser can report more errors. With `origins`, also
// says where the macros went.
TokenStream lex(const Source& src, Diagnostics& diags, MacroOrigins* origins = nullptr);

// The keyword of a primitive (the Kw values of the primitives follow PrimitiveKind).
constexpr Kw primitiveKeyword(PrimitiveKind k) {
    return static_cast<Kw>(static_cast<int>(Kw::Sphere) + static_cast<int>(k));
}
static_assert(primitiveKeyword(PrimitiveKind::Triangle) == Kw::Triangle);

// The spelling of a token ("end of line" for a Newline): for messages.
std::string describe(const Source& src, const Token& t);
std::string_view spelling(const Source& src, const Token& t);
// A name from the input as a message quotes it: at most 64 bytes.
std::string clip(std::string_view name);
// The keyword spelled by an identifier, or Kw::None.
Kw keywordOf(std::string_view word);
std::string_view keywordName(Kw k);

// Size limits (docs/language.md section 8: never crash or hang, whatever the input).
inline constexpr size_t kMaxSourceBytes = size_t(256) << 20;  // 256 MB
// Macro expansion may add at most this many tokens to a file's own.
inline constexpr size_t kMaxMacroTokens = size_t(1) << 20;

}  // namespace pcsg
