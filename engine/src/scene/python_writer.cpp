// toPython (sdfcsg/model.h): a scene as a Python program of the module sdfcsg's modelling API,
// written from the scene's own JSON and the node table, so that every kind is written the way
// the module makes it, with nothing to add for a new kind.
#include "sdfcsg/model.h"

#include "scene/json_writer.h"
#include "scene/parse_util.h"
#include "sdfcsg/nodes.h"

#include <simdjson.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <functional>
#include <map>
#include <optional>
#include <set>

namespace sdfcsg::model {
namespace {

using detail::asArray;
using detail::asObject;
using detail::jsonQuote;
using simdjson::dom::element;
using simdjson::dom::element_type;

// Lines are broken where a call would run past this column.
constexpr size_t kWidth = 100;
constexpr size_t kIndent = 4;

// Python's reserved words, which cannot be the names of keyword arguments or variables.
bool isKeyword(std::string_view word) {
    static const std::set<std::string_view> keywords = {
        "False", "None",     "True",  "and",    "as",   "assert", "async",  "await",    "break",
        "class", "continue", "def",   "del",    "elif", "else",   "except", "finally",  "for",
        "from",  "global",   "if",    "import", "in",   "is",     "lambda", "nonlocal", "not",
        "or",    "pass",     "raise", "return", "try",  "while",  "with",   "yield"};
    return keywords.count(word) != 0;
}

bool isIdentifier(std::string_view word) {
    if (word.empty() || std::isdigit(static_cast<unsigned char>(word[0]))) return false;
    return std::all_of(
               word.begin(), word.end(),
               [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; }) &&
           !isKeyword(word);
}

// A JSON value as a Python literal: strings as JSON quotes them (Python reads the same escapes),
// numbers as the scene writer writes them, true/false/null as Python's.
std::string literal(element value) {
    switch (value.type()) {
    case element_type::ARRAY: {
        std::string out = "[";
        for (element item : asArray(value))
            out += (out.size() > 1 ? ", " : "") + literal(item);
        return out + "]";
    }
    case element_type::OBJECT: {
        std::string out = "{";
        for (auto [key, item] : asObject(value))
            out += (out.size() > 1 ? ", " : "") + jsonQuote(key) + ": " + literal(item);
        return out + "}";
    }
    case element_type::STRING:
        return jsonQuote(value.get_string().value_unsafe());
    case element_type::BOOL:
        return value.get_bool().value_unsafe() ? "True" : "False";
    case element_type::NULL_VALUE:
        return "None";
    default:
        return detail::jsonText(value);
    }
}

// name=value, or for a name Python cannot take as a keyword, **{"name": value}.
std::string keyword(std::string_view name, const std::string& value) {
    if (isIdentifier(name)) return std::string(name) + "=" + value;
    return "**{" + jsonQuote(name) + ": " + value + "}";
}

// The call f(args) on one line from `column`, or with its arguments one a line below it, indented
// a step from `indent`.
std::string call(const std::string& function, const std::vector<std::string>& args, size_t indent,
                 std::optional<size_t> column = std::nullopt) {
    std::string line = function + "(";
    for (size_t i = 0; i < args.size(); ++i)
        line += (i ? ", " : "") + args[i];
    line += ")";
    const bool multiline = std::any_of(args.begin(), args.end(), [](const std::string& a) {
        return a.find('\n') != std::string::npos;
    });
    if (!multiline && column.value_or(indent) + line.size() <= kWidth) return line;
    const std::string inner(indent + kIndent, ' ');
    std::string out = function + "(\n";
    for (const std::string& a : args)
        out += inner + a + ",\n";
    return out + std::string(indent, ' ') + ")";
}

class Writer {
  public:
    explicit Writer(element root) : document_(root) {}

    std::string program(std::string_view output) {
        const simdjson::dom::object top = asObject(document_);
        std::string out;
        element value;
        std::string title;
        if (!top["name"].get(value)) title = std::string(value.get_string().value_unsafe());
        if (!top["description"].get(value))
            title += (title.empty() ? "" : ": ") + std::string(value.get_string().value_unsafe());
        for (char& c : title)
            if (c == '\n' || c == '\r') c = ' ';
        if (!title.empty()) out += "# " + title + "\n";
        out +=
            "# The scene as a program of the sdfcsg module (docs/python.md): run, it writes the\n"
            "# scene's JSON to its first argument, else to " +
            std::string(output) + ".\nimport sys\n\nimport sdfcsg as s\n\n";

        // Definitions as parts, each after the parts its node uses.
        std::vector<std::string> order;
        if (!top["definitions"].get(value)) {
            for (auto [name, definition] : asObject(value)) {
                definitions_[std::string(name)] = definition;
                order.emplace_back(name);
            }
            for (const std::string& name : order) {
                std::string variable(name);
                while (!isIdentifier(variable) || kTaken.count(variable) ||
                       std::any_of(variables_.begin(), variables_.end(),
                                   [&](const auto& v) { return v.second == variable; }))
                    variable += "_";
                variables_[name] = variable;
            }
            for (const std::string& name : order)
                out += part(name);
        }
        // A scene made in code may have no nodes, which the loader would refuse as the file would.
        out += "root = " + (top["root"].get(value) ? std::string("s.Shape()") : node(value, 0)) +
               "\n\n";

        std::vector<std::string> args = {"root"};
        for (std::string_view key : {"name", "description", "camera", "lights", "background"})
            if (!top[key].get(value)) args.push_back(keyword(key, literal(value)));
        if (!order.empty()) {
            std::vector<std::string> parts;
            for (const std::string& name : order)
                parts.push_back(variables_.at(name));
            std::string list = "[";
            for (size_t i = 0; i < parts.size(); ++i)
                list += (i ? ", " : "") + parts[i];
            args.push_back("parts=" + list + "]");
        }
        out += "scene = " + call("s.scene", args, 0) + "\n\n";
        out += "if __name__ == \"__main__\":\n    s.save(scene, sys.argv[1] if len(sys.argv) > 1 "
               "else " +
               jsonQuote(output) + ")\n";
        return out;
    }

  private:
    // Names the program itself uses.
    inline static const std::set<std::string> kTaken = {"s", "sys", "len", "root", "scene"};

    element document_;
    std::map<std::string, element> definitions_;
    std::map<std::string, std::string> variables_; // definition -> its variable
    std::set<std::string> written_;

    // `name = s.Part(...)`, after the parts its node uses (the loader has refused cycles).
    std::string part(const std::string& name) {
        if (!written_.insert(name).second) return {};
        const simdjson::dom::object definition = asObject(definitions_.at(name));
        std::string before;
        std::function<void(element)> uses = [&](element e) {
            if (e.is_array())
                for (element item : asArray(e))
                    uses(item);
            if (!e.is_object()) return;
            element type, used;
            if (!asObject(e)["type"].get(type) && type.is_string() &&
                type.get_string().value_unsafe() == "use" && !asObject(e)["definition"].get(used) &&
                used.is_string()) {
                const std::string usedName(used.get_string().value_unsafe());
                if (definitions_.count(usedName)) before += part(usedName);
            }
            for (auto [key, child] : asObject(e))
                if (key == "children") uses(child);
        };
        uses(definition["node"].value_unsafe());
        std::vector<std::string> args = {jsonQuote(name),
                                         node(definition["node"].value_unsafe(), kIndent)};
        element parameters;
        if (!definition["parameters"].get(parameters))
            for (auto [key, value] : asObject(parameters))
                args.push_back(keyword(key, literal(value)));
        return before + variables_.at(name) + " = " + call("s.Part", args, 0) + "\n\n";
    }

    // A node as an expression: its kind's call, then its name, transform and colour chained.
    std::string node(element e, size_t indent) {
        const simdjson::dom::object object = asObject(e);
        const std::string type(object["type"].get_string().value_unsafe());
        std::string out;
        if (type == "use") {
            std::vector<std::string> args;
            element parameters;
            if (!object["parameters"].get(parameters))
                for (auto [key, value] : asObject(parameters))
                    args.push_back(keyword(key, literal(value)));
            const std::string used(object["definition"].get_string().value_unsafe());
            auto it = variables_.find(used);
            out = call(it != variables_.end() ? it->second : used, args, indent);
        } else {
            out = kindCall(*findKind(type), object, indent);
        }
        element value;
        if (!object["name"].get(value)) out += ".name(" + literal(value) + ")";
        // The node's own transform is scale, then rotate, then translate: chained in that order
        // from none, the shape holds exactly these values. A "$name" in a definition is set as
        // it stands.
        for (std::string_view key : {"scale", "rotate", "translate"}) {
            if (object[key].get(value)) continue;
            if (value.is_string()) {
                out += ".set(" + jsonQuote(key) + ", " + literal(value) + ")";
                continue;
            }
            std::string xyz = literal(value);
            if (value.is_array()) xyz = xyz.substr(1, xyz.size() - 2);
            out += "." + std::string(key) + "(" + xyz + ")";
        }
        if (!object["color"].get(value)) out += ".color(" + literal(value) + ")";
        return out;
    }

    std::string kindCall(const KindInfo& kind, const simdjson::dom::object& object, size_t indent) {
        // Parameters: the required ones by position (except a Boolean's, whose positions hold
        // children), the others by keyword, in the table's order.
        std::vector<std::string> args;
        const bool boolean = kind.role == Role::Boolean;
        for (const ParamInfo* p : positionalParams(kind)) {
            element value;
            if (object[p->name].get(value)) continue;
            args.push_back(p->required && !boolean ? literal(value)
                                                   : keyword(p->name, literal(value)));
        }
        std::vector<element> children;
        element list;
        if (!object["children"].get(list))
            for (element child : asArray(list))
                children.push_back(child);
        const std::string name = pythonName(kind);
        if ((kind.role == Role::Value || kind.role == Role::Domain) && children.size() == 1) {
            // child.shell(0.05): the method, after the child's own chain.
            std::string child = node(children[0], indent);
            const size_t lastLine = child.rfind('\n');
            const size_t column =
                lastLine == std::string::npos ? indent + child.size() : child.size() - lastLine - 1;
            return child + call("." + name, args, indent, column);
        }
        if (!kind.operation) return call("s." + name, args, indent);
        std::vector<std::string> all;
        for (element child : children)
            all.push_back(node(child, indent + kIndent));
        all.insert(all.end(), args.begin(), args.end());
        return call("s." + name, all, indent);
    }
};

} // namespace

std::string pythonName(const KindInfo& kind) {
    // The module's own functions and Shape's methods (python/sdfcsg_module.cpp), which refuses
    // to load where a kind's name is taken that this list does not name.
    static const std::set<std::string_view> taken = {
        "shape",     "load",   "loads", "save",  "render", "mesh",  "evaluate",
        "scene",     "Part",   "Scene", "Shape", "Mesh",   "Error", "device_name",
        "translate", "rotate", "scale", "color", "name",   "set",   "json"};
    std::string name(kind.name);
    return taken.count(name) ? name + "_" : name;
}

std::string toPython(const Scene& scene, std::string_view output) {
    const std::string json = toJson(scene);
    simdjson::dom::parser parser;
    element document;
    // A scene's JSON is as deep as its tree, which the loader keeps within its limits.
    if (parser.allocate(json.size(), json.size() / 2 + 2) != simdjson::SUCCESS ||
        parser.parse(json).get(document) != simdjson::SUCCESS)
        return {};
    return Writer(document).program(output);
}

} // namespace sdfcsg::model
