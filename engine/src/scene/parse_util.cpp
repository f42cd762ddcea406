#include "scene/parse_util.h"

#include "scene/json_syntax.h"
#include "scene/json_writer.h"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <cstdio>

namespace sdfcsg::detail {

using simdjson::dom::element_type;

void Problems::add(std::string path, std::string message, ErrorKind kind) {
    if (full()) {
        ++dropped_;
        return;
    }
    if (diagnostics_.empty()) kind_ = kind;
    if (context_ && !message.empty()) message += context_();
    diagnostics_.push_back({file_, std::move(path), std::move(message)});
}

Error Problems::error() const {
    std::vector<Diagnostic> all = diagnostics_;
    if (dropped_ > 0)
        all.push_back({file_, {}, std::to_string(dropped_) + " more problems not shown"});
    return Error(kind_, std::move(all));
}

namespace {

// Appends `text` with C0 controls, DEL and C1 controls (U+0080 to U+009F, which some terminals
// obey as ESC sequences) escaped as in JSON, and bytes that are not UTF-8 as \xNN. `quoted`
// escapes quotes and backslashes too, for text between quotes.
void appendEscaped(std::string& out, std::string_view text, bool quoted) {
    for (size_t i = 0; i < text.size();) {
        const auto b = static_cast<unsigned char>(text[i]);
        const size_t n = utf8Length(text, i);
        char buf[8];
        if (n == 0) {
            std::snprintf(buf, sizeof buf, "\\x%02x", b);
            out += buf;
            ++i;
            continue;
        }
        const unsigned c1 = n == 2 && b == 0xC2 ? static_cast<unsigned char>(text[i + 1]) : 0;
        if (b < 0x20 || b == 0x7F || (c1 >= 0x80 && c1 <= 0x9F)) {
            const char* named = b == '\n'   ? "\\n"
                                : b == '\r' ? "\\r"
                                : b == '\t' ? "\\t"
                                : b == '\b' ? "\\b"
                                : b == '\f' ? "\\f"
                                            : nullptr;
            if (named) {
                out += named;
            } else {
                std::snprintf(buf, sizeof buf, "\\u%04x", c1 ? c1 : b);
                out += buf;
            }
        } else if (quoted && (b == '"' || b == '\\')) {
            out += '\\';
            out += char(b);
        } else {
            out.append(text.substr(i, n));
        }
        i += n;
    }
}

} // namespace

std::string quote(std::string_view text) {
    constexpr size_t kMax = 40;
    size_t cut = text.size();
    if (text.size() > kMax) {
        cut = kMax - 3;
        while (cut > 0 && (static_cast<unsigned char>(text[cut]) & 0xC0) == 0x80)
            --cut;
    }
    std::string out = "\"";
    appendEscaped(out, text.substr(0, cut), true);
    return out + (cut < text.size() ? "...\"" : "\"");
}

std::string printable(std::string_view text) {
    std::string out;
    out.reserve(text.size());
    appendEscaped(out, text, false);
    return out;
}

std::string member(std::string_view path, std::string_view key) {
    if (path.empty()) return std::string(key);
    std::string out(path);
    out += '.';
    out += key;
    return out;
}

std::string item(std::string_view path, size_t index) {
    return std::string(path) + "[" + std::to_string(index) + "]";
}

std::string describe(element value) {
    switch (value.type()) {
    case element_type::STRING:
        return quote(value.get_string().value_unsafe());
    case element_type::INT64:
        return std::to_string(value.get_int64().value_unsafe());
    case element_type::UINT64:
        return std::to_string(value.get_uint64().value_unsafe());
    case element_type::DOUBLE:
        return formatNumber(value.get_double().value_unsafe());
    case element_type::BOOL:
        return value.get_bool().value_unsafe() ? "true" : "false";
    case element_type::NULL_VALUE:
        return "null";
    case element_type::OBJECT:
        return asObject(value).begin() == asObject(value).end() ? "{}" : "an object";
    case element_type::ARRAY: {
        simdjson::dom::array array = asArray(value);
        size_t size = array.size();
        if (size <= 4) {
            std::string text = "[";
            bool scalars = true;
            for (element e : array) {
                if (e.is_array() || e.is_object()) {
                    scalars = false;
                    break;
                }
                if (text.size() > 1) text += ", ";
                text += describe(e);
            }
            if (scalars && text.size() < 40) return text + "]";
        }
        return "an array of " + std::to_string(size) + (size == 1 ? " element" : " elements");
    }
    }
    return "a value";
}

namespace {

// Optimal string alignment distance: Levenshtein plus adjacent transpositions ("raidus").
size_t editDistance(std::string_view a, std::string_view b) {
    std::vector<size_t> prev2(b.size() + 1), prev(b.size() + 1), cur(b.size() + 1);
    for (size_t j = 0; j <= b.size(); ++j)
        prev[j] = j;
    for (size_t i = 1; i <= a.size(); ++i) {
        cur[0] = i;
        for (size_t j = 1; j <= b.size(); ++j) {
            size_t cost = a[i - 1] == b[j - 1] ? 0 : 1;
            cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, prev[j - 1] + cost});
            if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1])
                cur[j] = std::min(cur[j], prev2[j - 2] + 1);
        }
        std::swap(prev2, prev);
        std::swap(prev, cur);
    }
    return prev[b.size()];
}

std::string lower(std::string_view s) {
    std::string out(s);
    for (char& c : out)
        if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
    return out;
}

// "radius_top" and "top_radius" name the same thing.
bool sameWords(std::string_view a, std::string_view b) {
    auto words = [](std::string_view s) {
        std::vector<std::string_view> out;
        size_t start = 0;
        for (size_t i = 0; i <= s.size(); ++i)
            if (i == s.size() || s[i] == '_') {
                out.push_back(s.substr(start, i - start));
                start = i + 1;
            }
        std::sort(out.begin(), out.end());
        return out;
    };
    return a.find('_') != std::string_view::npos && words(a) == words(b);
}

// Words people (and language models) use for keys and types that are spelt differently here.
constexpr std::pair<std::string_view, std::string_view> kAliases[] = {
    {"position", "translate"}, {"pos", "translate"},          {"center", "translate"},
    {"centre", "translate"},   {"location", "translate"},     {"cube", "box"},
    {"ball", "sphere"},        {"subtract", "difference"},    {"subtraction", "difference"},
    {"minus", "difference"},   {"prism", "triangular_prism"}, {"triangle", "triangular_prism"},
    {"blend", "smooth"},       {"colour", "color"},           {"kind", "type"},
};

} // namespace

std::string didYouMean(std::string_view word, std::span<const std::string_view> candidates) {
    if (word.empty() || word.size() > 64) return {};
    const std::string w = lower(word);
    auto answer = [](std::string_view c) { return "; did you mean \"" + std::string(c) + "\"?"; };
    for (std::string_view c : candidates)
        if (w == c || sameWords(w, c)) return answer(c);
    std::string_view best;
    size_t bestDistance = SIZE_MAX;
    for (std::string_view c : candidates) {
        size_t d = editDistance(w, c);
        size_t prefix = 0;
        while (prefix < w.size() && prefix < c.size() && w[prefix] == c[prefix])
            ++prefix;
        // A long shared start ("translation", "rotation") counts as close too.
        bool close =
            d <= std::max<size_t>(1, c.size() / 3) || (prefix >= 4 && d <= c.size() / 2 + 2);
        if (close && d < bestDistance) {
            best = c;
            bestDistance = d;
        }
    }
    if (!best.empty()) return answer(best);
    for (auto [alias, target] : kAliases)
        if (w == alias &&
            std::find(candidates.begin(), candidates.end(), target) != candidates.end())
            return answer(target);
    return {};
}

std::string joinNames(std::span<const std::string_view> names, std::string_view last) {
    std::string out;
    for (size_t i = 0; i < names.size(); ++i) {
        if (i > 0) out += i + 1 == names.size() ? " " + std::string(last) + " " : ", ";
        out += names[i];
    }
    return out;
}

std::string expectedText(ValueType type, Check check) {
    if (type == ValueType::Points)
        return "an array of 3 to " + std::to_string(kMaxPolygonPoints) + " points [x, y]";
    if (type == ValueType::Text) return "a string";
    if (type == ValueType::Number) {
        switch (check) {
        case Check::Any:
            return "a number";
        case Check::Positive:
            return "a positive number";
        case Check::NonNegative:
            return "a non-negative number";
        case Check::NonZero:
            return "a non-zero number";
        case Check::Count:
            return "a whole number from 1 to 1000000";
        }
    }
    switch (check) {
    case Check::Any:
        return "an array of 3 numbers";
    case Check::Positive:
        return "an array of 3 positive numbers";
    case Check::NonNegative:
        return "an array of 3 non-negative numbers";
    case Check::NonZero:
        return "a non-zero vector of 3 numbers";
    case Check::Count:
        return "an array of 3 whole numbers from 1 to 1000000";
    }
    return {};
}

std::string expectedText(const ParamInfo& p) {
    if (p.type == ValueType::Choice) {
        std::string out = "one of ";
        for (size_t i = 0; i < p.choices.size(); ++i) {
            if (i > 0) out += i + 1 == p.choices.size() ? " or " : ", ";
            out += "\"" + std::string(p.choices[i]) + "\"";
        }
        return out;
    }
    std::string out = expectedText(p.type, p.check);
    if (p.type == ValueType::Number && p.check == Check::Count && p.maximum < 3.4e38f)
        return "a whole number from " + formatFloat(p.least) + " to " + formatFloat(p.maximum);
    if (p.type == ValueType::Number && p.maximum < 3.4e38f) {
        char buf[32];
        std::snprintf(buf, sizeof buf, "%g", double(p.maximum));
        out += " up to " + std::string(buf);
    }
    return out;
}

std::optional<double> readNumber(element value, const std::string& path, Check check,
                                 Problems& problems) {
    const std::string expected = expectedText(ValueType::Number, check);
    if (!value.is_number()) {
        problems.add(path, "expected " + expected + ", got " + describe(value));
        return std::nullopt;
    }
    const double v = value.get_double().value_unsafe();
    // Everything downstream is single precision; a double beyond its range would become inf.
    if (std::fabs(v) > FLT_MAX) {
        problems.add(path, "expected " + expected + ", got " + describe(value) +
                               ", which is beyond single precision (about 3.4e+38)");
        return std::nullopt;
    }
    const float f = static_cast<float>(v);
    const bool ok = check == Check::Positive      ? f > 0.0f
                    : check == Check::NonNegative ? f >= 0.0f
                    : check == Check::NonZero     ? f != 0.0f
                    : check == Check::Count       ? f >= 1.0f && f == std::floor(f) && f <= 1e6f
                                                  : true;
    if (!ok) {
        problems.add(path, "expected " + expected + ", got " + describe(value) +
                               (v != 0.0 && f == 0.0f ? ", which is 0 in single precision" : ""));
        return std::nullopt;
    }
    return v;
}

std::optional<glm::vec3> readVec3(element value, const std::string& path, Check check,
                                  Problems& problems) {
    if (!value.is_array() || asArray(value).size() != 3) {
        problems.add(path, "expected " + expectedText(ValueType::Vec3, check) + ", got " +
                               describe(value));
        return std::nullopt;
    }
    glm::vec3 v(0.0f);
    bool ok = true;
    int i = 0;
    for (element e : asArray(value)) {
        auto n =
            readNumber(e, item(path, i), check == Check::NonZero ? Check::Any : check, problems);
        if (n) v[i] = static_cast<float>(*n);
        ok = ok && n.has_value();
        ++i;
    }
    if (!ok) return std::nullopt;
    if (check == Check::NonZero && v == glm::vec3(0.0f)) {
        problems.add(path, "expected a non-zero vector, got " + describe(value));
        return std::nullopt;
    }
    return v;
}

std::optional<glm::vec3> readColor(element value, const std::string& path, Problems& problems) {
    const std::string expected = "expected a colour ([r, g, b] in 0..1 or \"#rrggbb\"), got ";
    if (value.is_string()) {
        std::string_view s = value.get_string().value_unsafe();
        auto hex = [](char c) {
            return c >= '0' && c <= '9'   ? c - '0'
                   : c >= 'a' && c <= 'f' ? c - 'a' + 10
                   : c >= 'A' && c <= 'F' ? c - 'A' + 10
                                          : -1;
        };
        bool ok = s.size() == 7 && s[0] == '#';
        for (size_t i = 1; ok && i < 7; ++i)
            ok = hex(s[i]) >= 0;
        if (!ok) {
            problems.add(path, expected + describe(value));
            return std::nullopt;
        }
        glm::vec3 c;
        for (int i = 0; i < 3; ++i)
            c[i] = (hex(s[1 + 2 * i]) * 16 + hex(s[2 + 2 * i])) / 255.0f;
        return c;
    }
    if (!value.is_array() || asArray(value).size() != 3) {
        problems.add(path, expected + describe(value));
        return std::nullopt;
    }
    glm::vec3 c(0.0f);
    bool ok = true;
    int i = 0;
    for (element e : asArray(value)) {
        const std::string p = item(path, i);
        if (!e.is_number() || !(e.get_double().value_unsafe() >= 0.0) ||
            !(e.get_double().value_unsafe() <= 1.0)) {
            problems.add(p, "expected a number in 0..1, got " + describe(e));
            ok = false;
        } else {
            c[i] = static_cast<float>(e.get_double().value_unsafe());
        }
        ++i;
    }
    if (!ok) return std::nullopt;
    return c;
}

std::optional<std::string> readString(element value, const std::string& path, size_t maxChars,
                                      Problems& problems) {
    if (!value.is_string()) {
        problems.add(path, "expected a string, got " + describe(value));
        return std::nullopt;
    }
    std::string_view s = value.get_string().value_unsafe();
    size_t chars = 0;
    for (char c : s)
        chars += (static_cast<unsigned char>(c) & 0xC0) != 0x80;
    if (maxChars > 0 && chars > maxChars) {
        problems.add(path, "expected a string of at most " + std::to_string(maxChars) +
                               " characters, got " + std::to_string(chars) + " characters");
        return std::nullopt;
    }
    return std::string(s);
}

std::vector<std::optional<element>> readMembers(simdjson::dom::object object,
                                                const std::string& path,
                                                std::span<const std::string_view> keys,
                                                size_t listed, std::string_view owner,
                                                Problems& problems) {
    std::vector<std::optional<element>> values(keys.size());
    for (simdjson::dom::key_value_pair kv : object) {
        auto it = std::find(keys.begin(), keys.end(), kv.key);
        if (it != keys.end()) {
            auto& slot = values[static_cast<size_t>(it - keys.begin())];
            if (slot) problems.add(path, "duplicate key " + quote(kv.key));
            slot = kv.value;
            continue;
        }
        if (problems.full()) {
            problems.add(path, {}); // only counted; spare the suggestion search
            continue;
        }
        auto shown = keys.first(listed);
        std::string hint = didYouMean(kv.key, shown);
        if (hint.empty()) hint = std::string(owner) + "; valid keys: " + joinNames(shown);
        problems.add(path, "unknown key " + quote(kv.key) + hint);
    }
    return values;
}

void writeJson(JsonWriter& w, element value, bool inlined) {
    using Layout = JsonWriter::Layout;
    struct Frame {
        bool object, inlined;
        simdjson::dom::object::iterator member, members;
        simdjson::dom::array::iterator next, end;
    };
    std::vector<Frame> stack;
    // Writes a scalar, or opens a container for the loop below to fill.
    auto visit = [&](element e, bool inside) {
        switch (e.type()) {
        case element_type::OBJECT: {
            simdjson::dom::object o = asObject(e);
            w.beginObject(inside ? Layout::Inline : Layout::Block);
            stack.push_back({true, inside, o.begin(), o.end(), {}, {}});
            return;
        }
        case element_type::ARRAY: {
            simdjson::dom::array a = asArray(e);
            bool flat = true;
            for (element item : a)
                flat = flat && !item.is_object();
            w.beginArray(inside || flat ? Layout::Inline : Layout::Block);
            stack.push_back({false, inside || flat, {}, {}, a.begin(), a.end()});
            return;
        }
        case element_type::STRING:
            w.string(e.get_string().value_unsafe());
            return;
        case element_type::INT64:
        case element_type::UINT64:
        case element_type::DOUBLE:
            w.number(e.get_double().value_unsafe());
            return;
        case element_type::BOOL:
            w.boolean(e.get_bool().value_unsafe());
            return;
        case element_type::NULL_VALUE:
            w.null();
            return;
        }
    };
    visit(value, inlined);
    while (!stack.empty()) {
        Frame& top = stack.back();
        const bool inside = top.inlined;
        if (top.object ? top.member == top.members : !(top.next != top.end)) {
            top.object ? w.endObject() : w.endArray();
            stack.pop_back();
            continue;
        }
        element e;
        if (top.object) {
            w.key(top.member.key());
            e = top.member.value();
            ++top.member;
        } else {
            e = *top.next;
            ++top.next;
        }
        visit(e, inside); // may grow the stack: `top` is not used after this
    }
}

std::string jsonText(element value) {
    JsonWriter w;
    writeJson(w, value, true);
    std::string text = w.finish();
    if (text.ends_with('\n')) text.pop_back();
    return text;
}

} // namespace sdfcsg::detail
