// Finds where a JSON text goes wrong. simdjson reports only an error code, so when it rejects
// a document this scanner walks the text again (iteratively, with an explicit stack) to find
// the first problem's line and column and to say what was expected there.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>

namespace sdfcsg::detail {

struct SyntaxProblem {
    size_t offset; // byte offset of the problem
    std::string message;
    bool tooDeep = false; // nesting beyond maxDepth rather than bad grammar
};

// The first problem in `text` as JSON (RFC 8259, as simdjson reads it), nesting arrays and
// objects at most maxDepth deep. With checkNumberRange, numbers that simdjson cannot represent
// (1e999, integers beyond 64 bits) are problems too; that check is slower, so the caller asks
// for it only when simdjson complained about a number.
std::optional<SyntaxProblem> findSyntaxProblem(std::string_view text, size_t maxDepth,
                                               bool checkNumberRange);

// Length of the well-formed UTF-8 sequence at text[i], or 0 (RFC 3629: no overlong forms, no
// surrogates, nothing above U+10FFFF).
size_t utf8Length(std::string_view text, size_t i);

// 1-based line and column (in characters, not bytes) of a byte offset.
void lineColumn(std::string_view text, size_t offset, int& line, int& column);

} // namespace sdfcsg::detail
