#include "scene/json_writer.h"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace sdfcsg::detail {

std::string formatNumber(double value) {
    char buf[32];
    // Whole numbers as integers (1000000, not 1e+06), so readers that want integers get them.
    const bool whole = value == std::trunc(value) && std::abs(value) < 1e15;
    auto [end, ec] = whole ? std::to_chars(buf, buf + sizeof buf, value, std::chars_format::fixed)
                           : std::to_chars(buf, buf + sizeof buf, value);
    return std::string(buf, end);
}

std::string formatFloat(float value) {
    char buf[32];
    auto [end, ec] = std::to_chars(buf, buf + sizeof buf, value);
    std::string text(buf, end);
    // The shortest float text could in principle round differently through double; the exact
    // double of the float never does.
    double parsed = 0.0;
    std::from_chars(text.data(), text.data() + text.size(), parsed);
    if (static_cast<float>(parsed) != value) return formatNumber(static_cast<double>(value));
    return text;
}

std::string jsonQuote(std::string_view text) {
    std::string out = "\"";
    for (char c : text) {
        switch (c) {
        case '"':
            out += "\\\"";
            break;
        case '\\':
            out += "\\\\";
            break;
        case '\n':
            out += "\\n";
            break;
        case '\r':
            out += "\\r";
            break;
        case '\t':
            out += "\\t";
            break;
        case '\b':
            out += "\\b";
            break;
        case '\f':
            out += "\\f";
            break;
        default:
            if (static_cast<unsigned char>(c) < 0x20) {
                char buf[8];
                std::snprintf(buf, sizeof buf, "\\u%04x", static_cast<unsigned>(c));
                out += buf;
            } else {
                out += c;
            }
        }
    }
    return out + "\"";
}

void JsonWriter::newline(size_t depth) {
    out_ += '\n';
    out_.append(2 * depth, ' ');
}

void JsonWriter::beforeValue() {
    if (afterKey_) {
        afterKey_ = false;
        return;
    }
    if (levels_.empty()) return;
    Level& level = levels_.back();
    if (!level.empty) out_ += level.inlined ? ", " : ",";
    if (!level.inlined) newline(levels_.size());
    level.empty = false;
}

void JsonWriter::beginObject(Layout layout) {
    beforeValue();
    out_ += '{';
    levels_.push_back({layout == Layout::Inline});
}

void JsonWriter::endObject() {
    Level level = levels_.back();
    levels_.pop_back();
    if (!level.empty && !level.inlined) newline(levels_.size());
    out_ += '}';
}

void JsonWriter::beginArray(Layout layout) {
    beforeValue();
    out_ += '[';
    levels_.push_back({layout == Layout::Inline});
}

void JsonWriter::endArray() {
    Level level = levels_.back();
    levels_.pop_back();
    if (!level.empty && !level.inlined) newline(levels_.size());
    out_ += ']';
}

void JsonWriter::key(std::string_view name) {
    beforeValue();
    out_ += jsonQuote(name);
    out_ += ": ";
    afterKey_ = true;
}

void JsonWriter::string(std::string_view text) {
    beforeValue();
    out_ += jsonQuote(text);
}

// JSON has no NaN or infinity; null makes the reader fail with a clear message instead. Zero is
// written without a sign: a reader may take "-0" for the integer 0, and no field gives -0 a
// meaning.
void JsonWriter::number(double value) {
    beforeValue();
    out_ += !std::isfinite(value) ? "null" : value == 0.0 ? "0" : formatNumber(value);
}

void JsonWriter::number(float value) {
    beforeValue();
    out_ += !std::isfinite(value) ? "null" : value == 0.0f ? "0" : formatFloat(value);
}

void JsonWriter::boolean(bool value) {
    beforeValue();
    out_ += value ? "true" : "false";
}

void JsonWriter::null() {
    beforeValue();
    out_ += "null";
}

std::string JsonWriter::finish() {
    out_ += '\n';
    return std::move(out_);
}

} // namespace sdfcsg::detail
