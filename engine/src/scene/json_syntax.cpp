#include "scene/json_syntax.h"

#include <simdjson.h>

#include <cstdio>
#include <vector>

namespace sdfcsg::detail {
namespace {

bool isDigit(char c) {
    return c >= '0' && c <= '9';
}
bool isHex(char c) {
    return isDigit(c) || (c >= 'a' && c <= 'f') || (c >= 'A' && c <= 'F');
}
bool isWordChar(char c) {
    return isDigit(c) || (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_';
}
bool isSpace(char c) {
    return c == ' ' || c == '\t' || c == '\n' || c == '\r';
}

std::string hexByte(unsigned char b) {
    char buf[8];
    std::snprintf(buf, sizeof buf, "0x%02X", b);
    return buf;
}

// What sits at text[i], for "got ..." in messages.
std::string show(std::string_view text, size_t i) {
    if (i >= text.size()) return "end of input";
    auto b = static_cast<unsigned char>(text[i]);
    if (b < 0x20 || b == 0x7F) {
        char buf[32];
        std::snprintf(buf, sizeof buf, "control character U+%04X", b);
        return buf;
    }
    if (b == '\'') return "\"'\"";
    if (size_t n = utf8Length(text, i)) return "'" + std::string(text.substr(i, n)) + "'";
    return "byte " + hexByte(b);
}

// A token for a message, cut short when long.
std::string clip(std::string_view token) {
    if (token.size() > 40) return std::string(token.substr(0, 37)) + "...";
    return std::string(token);
}
std::string quoted(std::string_view token) {
    return "\"" + clip(token) + "\"";
}

unsigned hex4(std::string_view text, size_t i) {
    unsigned v = 0;
    for (size_t k = i; k < i + 4; ++k) {
        char c = text[k];
        v = v * 16 + (isDigit(c) ? c - '0' : (c | 0x20) - 'a' + 10);
    }
    return v;
}

class Scanner {
  public:
    Scanner(std::string_view text, size_t maxDepth, bool checkNumberRange)
        : s_(text), maxDepth_(maxDepth), checkRange_(checkNumberRange) {}

    std::optional<SyntaxProblem> run();

  private:
    enum class Expect { Value, ValueOrClose, Key, KeyOrClose, Colon, CommaOrClose, End };

    std::optional<SyntaxProblem> fail(size_t at, std::string message) {
        return SyntaxProblem{at, std::move(message)};
    }
    std::optional<SyntaxProblem> string();
    std::optional<SyntaxProblem> number();
    std::optional<SyntaxProblem> word(size_t start);
    void afterValue() { expect_ = stack_.empty() ? Expect::End : Expect::CommaOrClose; }

    std::string_view s_;
    size_t maxDepth_;
    bool checkRange_;
    size_t i_ = 0;
    Expect expect_ = Expect::Value;
    bool afterComma_ = false;
    std::vector<size_t> stack_; // offsets of the open '{' and '['
    simdjson::dom::parser numberParser_;
};

std::optional<SyntaxProblem> Scanner::run() {
    const size_t n = s_.size();
    for (;;) {
        while (i_ < n && isSpace(s_[i_]))
            ++i_;
        if (i_ == n) {
            if (expect_ == Expect::End) return std::nullopt;
            if (stack_.empty()) return fail(i_, "expected a JSON value, got end of input");
            int line = 0, column = 0;
            lineColumn(s_, stack_.back(), line, column);
            return fail(i_, std::string("unexpected end of input: the ") +
                                (s_[stack_.back()] == '{' ? "object" : "array") +
                                " opened at line " + std::to_string(line) + ", column " +
                                std::to_string(column) + " is not closed");
        }
        const char c = s_[i_];
        const bool comma = afterComma_;
        afterComma_ = false;
        switch (expect_) {
        case Expect::End:
            return fail(i_, "expected end of input after the JSON value, got " + show(s_, i_));
        case Expect::Colon:
            if (c != ':') return fail(i_, "expected ':' after the key, got " + show(s_, i_));
            ++i_;
            expect_ = Expect::Value;
            break;
        case Expect::CommaOrClose: {
            const bool object = s_[stack_.back()] == '{';
            if (c == ',') {
                ++i_;
                expect_ = object ? Expect::Key : Expect::Value;
                afterComma_ = true;
            } else if (c == (object ? '}' : ']')) {
                ++i_;
                stack_.pop_back();
                afterValue();
            } else {
                return fail(i_, std::string("expected ',' or '") + (object ? '}' : ']') +
                                    "' after " +
                                    (object ? "an object member" : "an array element") + ", got " +
                                    show(s_, i_));
            }
            break;
        }
        case Expect::Key:
        case Expect::KeyOrClose:
            if (c == '}' && expect_ == Expect::KeyOrClose) {
                ++i_;
                stack_.pop_back();
                afterValue();
                break;
            }
            if (c == '}' && comma)
                return fail(i_,
                            "expected a key after ',', got '}' (trailing commas are not allowed)");
            if (c != '"') return fail(i_, "expected a key in double quotes, got " + show(s_, i_));
            if (auto problem = string()) return problem;
            expect_ = Expect::Colon;
            break;
        case Expect::Value:
        case Expect::ValueOrClose:
            if (c == ']' && expect_ == Expect::ValueOrClose) {
                ++i_;
                stack_.pop_back();
                afterValue();
            } else if (c == ']' && comma) {
                return fail(
                    i_, "expected a value after ',', got ']' (trailing commas are not allowed)");
            } else if (c == '{' || c == '[') {
                if (stack_.size() >= maxDepth_) {
                    return SyntaxProblem{i_,
                                         "nesting too deep: more than " +
                                             std::to_string(maxDepth_) +
                                             " levels of arrays and objects",
                                         true};
                }
                stack_.push_back(i_++);
                expect_ = c == '{' ? Expect::KeyOrClose : Expect::ValueOrClose;
            } else if (c == '"') {
                if (auto problem = string()) return problem;
                afterValue();
            } else if (c == '-' || isDigit(c)) {
                if (auto problem = number()) return problem;
                afterValue();
            } else if (isWordChar(c)) {
                if (auto problem = word(i_)) return problem;
                afterValue();
            } else {
                return fail(i_, "expected a value, got " + show(s_, i_) +
                                    (c == '\'' ? " (strings use double quotes)" : ""));
            }
            break;
        }
    }
}

std::optional<SyntaxProblem> Scanner::string() {
    const size_t open = i_;
    size_t j = i_ + 1;
    for (;;) {
        if (j >= s_.size()) return fail(open, "unterminated string: no closing '\"'");
        const auto b = static_cast<unsigned char>(s_[j]);
        if (b == '"') break;
        if (b == '\n' || b == '\r')
            return fail(open, "unterminated string: a string must end on the line it starts "
                              "(write a line break as \\n)");
        if (b < 0x20) return fail(j, show(s_, j) + " in a string must be escaped");
        if (b >= 0x80) {
            size_t len = utf8Length(s_, j);
            if (len == 0) return fail(j, "invalid UTF-8 byte " + hexByte(b) + " in a string");
            j += len;
            continue;
        }
        if (b != '\\') {
            ++j;
            continue;
        }
        if (j + 1 >= s_.size()) return fail(open, "unterminated string: no closing '\"'");
        const char e = s_[j + 1];
        if (e == '"' || e == '\\' || e == '/' || e == 'b' || e == 'f' || e == 'n' || e == 'r' ||
            e == 't') {
            j += 2;
            continue;
        }
        if (e != 'u') {
            std::string what = (static_cast<unsigned char>(e) > 0x20 && e != 0x7F)
                                   ? "'\\" + std::string(1, e) + "'"
                                   : "'\\' followed by " + show(s_, j + 1);
            return fail(
                j, "invalid escape " + what +
                       " in a string; expected one of \\\" \\\\ \\/ \\b \\f \\n \\r \\t \\uXXXX");
        }
        auto hexAt = [&](size_t k) {
            return k + 6 <= s_.size() && s_[k] == '\\' && s_[k + 1] == 'u' && isHex(s_[k + 2]) &&
                   isHex(s_[k + 3]) && isHex(s_[k + 4]) && isHex(s_[k + 5]);
        };
        if (!hexAt(j)) {
            size_t end = j + 2;
            while (end < s_.size() && end < j + 6 && isWordChar(s_[end]))
                ++end;
            return fail(j, "invalid unicode escape " + quoted(s_.substr(j, end - j)) +
                               "; expected \\u and four hex digits");
        }
        unsigned cp = hex4(s_, j + 2);
        if (cp >= 0xD800 && cp <= 0xDBFF && hexAt(j + 6) && hex4(s_, j + 8) >= 0xDC00 &&
            hex4(s_, j + 8) <= 0xDFFF) {
            j += 12;
            continue;
        }
        if (cp >= 0xD800 && cp <= 0xDFFF)
            return fail(j, "unpaired surrogate " + quoted(s_.substr(j, 6)) + " in a string");
        j += 6;
    }
    i_ = j + 1;
    return std::nullopt;
}

std::optional<SyntaxProblem> Scanner::number() {
    const size_t start = i_;
    size_t j = i_;
    auto token = [&] {
        size_t end = start + 1;
        while (end < s_.size() &&
               (isWordChar(s_[end]) || s_[end] == '.' || s_[end] == '+' || s_[end] == '-'))
            ++end;
        return quoted(s_.substr(start, end - start));
    };
    if (s_[j] == '-') {
        ++j;
        if (j < s_.size() && (s_[j] == 'I' || s_[j] == 'i' || s_[j] == 'N' || s_[j] == 'n')) {
            i_ = j;
            return word(start);
        }
    }
    if (j >= s_.size() || !isDigit(s_[j]))
        return fail(start, "invalid number " + token() + ": expected a digit after '-'");
    if (s_[j] == '0' && j + 1 < s_.size() && isDigit(s_[j + 1]))
        return fail(start, "invalid number " + token() + ": leading zeros are not allowed");
    while (j < s_.size() && isDigit(s_[j]))
        ++j;
    if (j < s_.size() && s_[j] == '.') {
        ++j;
        if (j >= s_.size() || !isDigit(s_[j]))
            return fail(start, "invalid number " + token() + ": expected a digit after '.'");
        while (j < s_.size() && isDigit(s_[j]))
            ++j;
    }
    if (j < s_.size() && (s_[j] == 'e' || s_[j] == 'E')) {
        ++j;
        if (j < s_.size() && (s_[j] == '+' || s_[j] == '-')) ++j;
        if (j >= s_.size() || !isDigit(s_[j]))
            return fail(start, "invalid number " + token() + ": expected a digit in the exponent");
        while (j < s_.size() && isDigit(s_[j]))
            ++j;
    }
    if (checkRange_) {
        // Ask simdjson itself, so "out of range" means exactly what it refused.
        simdjson::dom::element ignored;
        std::string_view digits = s_.substr(start, j - start);
        if (numberParser_.parse(digits.data(), digits.size()).get(ignored))
            return fail(start, "number " + clip(digits) + " is out of range");
    }
    i_ = j;
    return std::nullopt;
}

// A bare word where a value belongs; `start` includes a leading '-' ("-Infinity").
std::optional<SyntaxProblem> Scanner::word(size_t start) {
    size_t j = i_;
    while (j < s_.size() && isWordChar(s_[j]))
        ++j;
    std::string_view w = s_.substr(i_, j - i_);
    if (w == "true" || w == "false" || w == "null") {
        i_ = j;
        return std::nullopt;
    }
    std::string lower;
    for (char c : w)
        lower += static_cast<char>(c | 0x20);
    std::string_view shown = s_.substr(start, j - start);
    if (lower == "nan" || lower == "inf" || lower == "infinity")
        return fail(start, clip(shown) + " is not a JSON number; numbers must be finite");
    for (std::string_view literal : {"true", "false", "null"})
        if (lower == literal || (lower.size() < literal.size() && literal.starts_with(lower)))
            return fail(start,
                        "invalid literal " + quoted(shown) + "; expected true, false or null");
    return fail(start,
                "expected a value, got " + clip(shown) + " (strings must be in double quotes)");
}

} // namespace

size_t utf8Length(std::string_view text, size_t i) {
    auto at = [&](size_t k) { return static_cast<unsigned char>(text[k]); };
    unsigned char b = at(i);
    size_t n = b < 0x80 ? 1 : (b >> 5) == 0x6 ? 2 : (b >> 4) == 0xE ? 3 : (b >> 3) == 0x1E ? 4 : 0;
    if (n == 0 || i + n > text.size()) return 0;
    uint32_t cp = n == 1 ? b : n == 2 ? (b & 0x1F) : n == 3 ? (b & 0x0F) : (b & 0x07);
    for (size_t k = 1; k < n; ++k) {
        if ((at(i + k) & 0xC0) != 0x80) return 0;
        cp = (cp << 6) | (at(i + k) & 0x3F);
    }
    static constexpr uint32_t kMin[] = {0, 0, 0x80, 0x800, 0x10000};
    if (cp < kMin[n] || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF)) return 0;
    return n;
}

std::optional<SyntaxProblem> findSyntaxProblem(std::string_view text, size_t maxDepth,
                                               bool checkNumberRange) {
    return Scanner(text, maxDepth, checkNumberRange).run();
}

void lineColumn(std::string_view text, size_t offset, int& line, int& column) {
    line = 1;
    column = 1;
    for (size_t i = 0; i < offset && i < text.size(); ++i) {
        if (text[i] == '\n') {
            ++line;
            column = 1;
        } else if ((static_cast<unsigned char>(text[i]) & 0xC0) != 0x80) {
            ++column;
        }
    }
}

} // namespace sdfcsg::detail
