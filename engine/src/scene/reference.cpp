// The scene format reference in Markdown, made from the node kind table so it cannot drift.
#include "sdfcsg/scene.h"

#include <cstdio>

namespace sdfcsg {
namespace {

std::string number(float v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", double(v));
    return buf;
}

std::string describeValue(const ParamInfo& p) {
    if (p.type == ValueType::Choice) {
        std::string names;
        for (std::string_view c : p.choices)
            names += (names.empty() ? "\"" : ", \"") + std::string(c) + "\"";
        return names;
    }
    if (p.type == ValueType::Text) return "string";
    if (p.type == ValueType::Points) return "[[x, y], ...]";
    std::string kind = p.type == ValueType::Vec3 ? "[x, y, z]" : "number";
    switch (p.check) {
    case Check::Any:
        break;
    case Check::Positive:
        kind += p.type == ValueType::Vec3 ? ", each > 0" : ", > 0";
        break;
    case Check::NonNegative:
        kind += p.type == ValueType::Vec3 ? ", each >= 0" : ", >= 0";
        break;
    case Check::NonZero:
        kind += ", not zero";
        break;
    case Check::Count:
        kind += p.type == ValueType::Vec3 ? ", each a whole number >= 1" : ", whole >= 1";
        break;
    }
    if (p.maximum < 3.4e38f) kind += ", <= " + number(p.maximum);
    return kind;
}

std::string fallback(const ParamInfo& p) {
    if (p.required) return "required";
    if (p.type == ValueType::Choice)
        return "default \"" + std::string(p.choices[size_t(p.fallback[0])]) + "\"";
    if (p.type == ValueType::Number) return "default " + number(p.fallback[0]);
    if (p.type == ValueType::Text) return "default \"\"";
    return "default [" + number(p.fallback[0]) + ", " + number(p.fallback[1]) + ", " +
           number(p.fallback[2]) + "]";
}

} // namespace

std::string sceneFormatReference() {
    std::string out;
    out += "Keys every node may have:\n\n| key | meaning |\n|---|---|\n";
    for (const CommonKey& k : commonNodeKeys())
        out += "| `" + std::string(k.name) + "` | " + std::string(k.doc) + " |\n";
    out += "\n| type | fields (unit; constraint; default) | meaning |\n|---|---|---|\n";
    for (const KindInfo& kind : nodeKinds()) {
        std::string fields;
        for (const ParamInfo& p : kind.params) {
            if (!fields.empty()) fields += "<br>";
            fields += "`" + std::string(p.name) + "` (" + std::string(p.unit) + "; " +
                      describeValue(p) + "; " + fallback(p) + "): " + std::string(p.doc);
        }
        out += "| `" + std::string(kind.name) + "` | " + fields + " | " + std::string(kind.doc) +
               "<br>Example: `" + exampleNodeJson(kind) + "` |\n";
    }
    return out;
}

} // namespace sdfcsg
