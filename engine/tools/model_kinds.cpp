// Writes the modelling API's function for every node kind (sdfcsg/model.h), from the node table:
// model_kinds.h holds a free function per kind (sphere(radius), roundBox(size, radius),
// union_(children, smooth, blend), ...) and model_methods.inc the chained form of every operation
// of one child (shape.shell(thickness), shape.twist(angle), ...): their declarations, which
// model.h includes inside its class, and their definitions after the free functions. Required
// parameters come first, each in the table's order, then the optional ones, which default to
// "absent" (the loader's default). The build runs it, so a kind added to the table has its
// functions with no code written for it.
//
// Usage: model_kinds HEADER METHODS (each rewritten only when its text changes).
#include "sdfcsg/nodes.h"

#include <algorithm>
#include <fstream>
#include <iostream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

namespace {

using namespace sdfcsg;

// round_box -> roundBox; a C++ keyword gets a trailing underscore (union_).
std::string functionName(std::string_view json) {
    std::string out;
    bool upper = false;
    for (char c : json) {
        if (c == '_') {
            upper = true;
            continue;
        }
        out += upper ? char(c - 'a' + 'A') : c;
        upper = false;
    }
    return out == "union" ? "union_" : out;
}

std::string argumentName(std::string_view json) {
    static const char* const keywords[] = {"and", "or", "not", "xor", "union", "default", "const"};
    for (const char* k : keywords)
        if (json == k) return std::string(json) + "_";
    return std::string(json);
}

// The first sentence of a documentation text.
std::string_view sentence(std::string_view doc) {
    const size_t end = doc.find(". ");
    return end == std::string_view::npos ? doc : doc.substr(0, end + 1);
}

// The documentation comment: the kind's and each parameter's.
void comment(std::ostream& out, const KindInfo& kind, const char* indent) {
    out << indent << "// " << kind.name << ": " << sentence(kind.doc) << "\n";
    for (const ParamInfo* p : positionalParams(kind))
        out << indent << "//   " << p->name << (p->required ? "" : " (optional)") << ", " << p->unit
            << ": " << sentence(p->doc) << "\n";
}

// "Value radius, Value top_radius = {}" and the matching {{"radius", radius}, ...}.
void parameters(const KindInfo& kind, std::string& declared, std::string& passed) {
    for (const ParamInfo* p : positionalParams(kind)) {
        const std::string name = argumentName(p->name);
        declared += ", Value " + name + (p->required ? "" : " = {}");
        passed += std::string(passed.empty() ? "" : ", ") + "{\"" + std::string(p->name) +
                  "\", std::move(" + name + ")}";
    }
}

// A parameter list without its leading ", " (empty for a kind of no parameters).
std::string list(const std::string& withComma) {
    return withComma.substr(std::min<size_t>(2, withComma.size()));
}

bool writeIfChanged(const char* path, const std::string& text) {
    std::ifstream in(path, std::ios::binary);
    if (in && std::string(std::istreambuf_iterator<char>(in), {}) == text) return true;
    std::ofstream out(path, std::ios::binary);
    out << text;
    return bool(out);
}

} // namespace

int main(int argc, char** argv) {
    if (argc != 3) {
        std::cerr << "usage: model_kinds HEADER METHODS\n";
        return 2;
    }
    std::ostringstream header, methods;
    const char* banner = "// Generated from the node table (engine/src/scene/nodes.cpp) by "
                         "engine/tools/model_kinds.cpp. Do not edit.\n";
    header << banner
           << "// Included by sdfcsg/model.h: a function per node kind, parameters by the table's\n"
              "// names, required ones first; an optional one left out takes the loader's "
              "default.\n#pragma once\n\nnamespace sdfcsg::model {\n";
    methods << banner
            << "// Included inside sdfcsg::model::Shape: every operation of one child, "
               "chained\n// (defined in model_kinds.h).\n";
    for (const KindInfo& kind : nodeKinds()) {
        const std::string name = functionName(kind.name);
        std::string declared, passed;
        parameters(kind, declared, passed);
        const std::string where = ", Where where = Where::current()";
        const std::string type = "\"" + std::string(kind.name) + "\"";
        header << "\n";
        comment(header, kind, "");
        if (!kind.operation) {
            header << "inline Shape " << name << "(" << list(declared + where) << ") {\n"
                   << "    return shape(" << type << ", {" << passed << "}, {}, where);\n}\n";
        } else if (isTransition(kind.kind)) {
            header << "inline Shape " << name << "(Shape first, Shape second" << declared << where
                   << ") {\n    return shape(" << type << ", {" << passed
                   << "}, {std::move(first), std::move(second)}, where);\n}\n";
        } else if (kind.role == Role::Boolean) {
            header << "inline Shape " << name << "(std::vector<Shape> children" << declared << where
                   << ") {\n    return shape(" << type << ", {" << passed
                   << "}, std::move(children), where);\n}\n";
        } else {
            header << "inline Shape " << name << "(Shape child" << declared << where
                   << ") {\n    return shape(" << type << ", {" << passed
                   << "}, {std::move(child)}, where);\n}\n";
            std::string args;
            for (const ParamInfo* p : positionalParams(kind))
                args += "std::move(" + argumentName(p->name) + "), ";
            methods << "\n";
            comment(methods, kind, "");
            methods << "Shape " << name << "(" << list(declared + where) << ") const;\n";
            std::string defined;
            for (const ParamInfo* p : positionalParams(kind))
                defined += ", Value " + argumentName(p->name);
            header << "inline Shape Shape::" << name << "(" << list(defined + ", Where where")
                   << ") const {\n    return model::" << name << "(*this, " << args
                   << "where);\n}\n";
        }
    }
    // Every function above by its kind's name, for tests and bindings that go through the table.
    header << "\n// The function of kind `type` above, called with `args` picked by name (absent "
              "where "
              "missing)\n// and `children` as its operands; an unknown type goes to shape().\n"
              "inline Shape byFunction(std::string_view type, const std::vector<Arg>& args,\n"
              "                        std::vector<Shape> children, Where where = "
              "Where::current()) {\n"
              "    auto arg = [&](std::string_view name) {\n"
              "        for (const Arg& a : args)\n"
              "            if (a.name == name) return a.value;\n"
              "        return Value();\n    };\n"
              "    auto child = [&](size_t i) { return i < children.size() ? children[i] : "
              "Shape(); };\n";
    for (const KindInfo& kind : nodeKinds()) {
        std::string call;
        for (const ParamInfo* p : positionalParams(kind))
            call += "arg(\"" + std::string(p->name) + "\"), ";
        const std::string operands = !kind.operation              ? ""
                                     : isTransition(kind.kind)    ? "child(0), child(1), "
                                     : kind.role == Role::Boolean ? "children, "
                                                                  : "child(0), ";
        header << "    if (type == \"" << kind.name << "\") return " << functionName(kind.name)
               << "(" << operands << call << "where);\n";
    }
    header << "    return shape(type, args, std::move(children), where);\n}\n";
    header << "\n} // namespace sdfcsg::model\n";
    if (!writeIfChanged(argv[1], header.str()) || !writeIfChanged(argv[2], methods.str())) {
        std::cerr << "model_kinds: cannot write " << argv[1] << " or " << argv[2] << "\n";
        return 1;
    }
    return 0;
}
