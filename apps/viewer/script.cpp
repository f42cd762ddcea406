#include "script.h"

#include <sdfcsg/scene.h>

#include <charconv>
#include <cmath>
#include <optional>
#include <sstream>

namespace sdfcsg::viewer {

namespace {

// A problem with a command's arguments, as the message to report; none when they are fine.
using Problem = std::optional<std::string>;

struct Verb {
    std::string_view name;
    int minArgs, maxArgs;                  // -1: any number
    bool numeric;                          // arguments (after the first for "set") must be numbers
    std::vector<std::string_view> choices; // allowed single argument, when not empty
    std::string_view text = {};            // free text: what the text describes, for the message
    // Checks of the verb's own, after the others; they may append to the command's numbers.
    Problem (*check)(Command& c) = nullptr;
};

std::vector<std::string_view> kindNames(bool operations) {
    std::vector<std::string_view> names;
    for (const KindInfo& k : nodeKinds())
        if (k.operation == operations) names.push_back(k.name);
    return names;
}

std::vector<std::string_view> allKindNames() {
    std::vector<std::string_view> names = kindNames(false), ops = kindNames(true);
    names.insert(names.end(), ops.begin(), ops.end());
    return names;
}

// Finite numbers only: a NaN or infinite angle or factor would poison the camera for good.
bool parseFloat(const std::string& s, float& out) {
    auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), out);
    return ec == std::errc() && end == s.data() + s.size() && std::isfinite(out);
}

Problem checkZoom(Command& c) {
    if (!(c.numbers[0] > 0.0f))
        return "zoom: expected a positive factor, got \"" + c.args[0] + "\"";
    return std::nullopt;
}

// mesh extract CELLS [dc|mc [SIMPLIFY]], mesh export PATH.
Problem checkMesh(Command& c) {
    const size_t n = c.args.size();
    if (c.args[0] == "export") {
        if (n != 2) return "mesh export: expected a file name";
        return std::nullopt;
    }
    float cells = 0;
    if (!parseFloat(c.args[1], cells) || cells < 1 || cells != float(int(cells)))
        return "mesh extract: expected a whole number of cells, got \"" + c.args[1] + "\"";
    c.numbers.push_back(cells);
    // Then optionally the method and the simplification error, in cells.
    if (n > 2 && c.args[2] != "dc" && c.args[2] != "mc")
        return "mesh extract: expected the method dc or mc, got \"" + c.args[2] + "\"";
    float simplify = 0;
    if (n > 3 && (!parseFloat(c.args[3], simplify) || !(simplify > 0.0f)))
        return "mesh extract: expected a simplification error in cells greater than 0, got \"" +
               c.args[3] + "\"";
    c.numbers.push_back(simplify);
    return std::nullopt;
}

// parent NODE [INDEX].
Problem checkParent(Command& c) {
    if (c.args.size() != 2) return std::nullopt;
    float index = 0;
    if (!parseFloat(c.args[1], index) || !(index >= 0 && index < 1e6f) ||
        index != std::floor(index))
        return "parent: expected a whole number for the child's position, got \"" + c.args[1] +
               "\"";
    c.numbers.push_back(index);
    return std::nullopt;
}

const std::vector<Verb>& verbs() {
    static const std::vector<Verb> table = {
        {"select", 1, 1, false, {}},
        {"set", 1, 4, true, {}},
        {"mode", 1, 1, false, {"shaded", "normals", "depth", "steps"}},
        {"shadows", 1, 1, false, {"on", "off"}},
        {"ao", 1, 1, false, {"on", "off"}},
        {"grid", 1, 1, false, {"on", "off"}},
        {"boxes", 1, 1, false, {"none", "all", "selected"}},
        {"orbit", 2, 2, true, {}},
        {"drag", 2, 2, true, {}},
        {"zoom", 1, 1, true, {}, {}, checkZoom},
        {"frame", 0, 0, false, {}},
        {"reset", 0, 0, false, {}},
        {"undo", 0, 0, false, {}},
        {"redo", 0, 0, false, {}},
        {"save", 0, 1, false, {}},
        {"screenshot", 1, 1, false, {}},
        {"generate", 1, -1, false, {}, "the scene"},
        {"edit-scene", 1, -1, false, {}, "the change"},
        {"add", 1, 1, false, allKindNames()},
        {"remove", 0, 0, false, {}},
        {"kind", 1, 1, false, allKindNames()},
        {"op", 1, 1, false, kindNames(true)},
        {"move", 1, 1, false, {"up", "down"}},
        {"parent", 1, 2, false, {}, {}, checkParent},
        {"open", 1, 1, false, {}},
        {"pick", 2, 2, true, {}},
        {"wait-reload", 0, 0, false, {}},
        {"ui", 1, 1, false, {"on", "off"}},
        {"expect-error", 1, -1, false, {}, "the error"},
        {"expect-selected", 1, 1, false, {}},
        {"print-bounds", 1, 1, false, {}},
        {"print-notes", 0, 0, false, {}},
        {"mesh", 2, 4, false, {"extract", "export"}, {}, checkMesh},
        {"view", 1, 1, false, {"mesh", "march"}},
        {"wireframe", 1, 1, false, {"on", "off"}},
        {"thin-walls", 1, 1, false, {"on", "off"}},
    };
    return table;
}

const Verb* findVerb(const std::string& name) {
    for (const Verb& v : verbs())
        if (v.name == name) return &v;
    return nullptr;
}

// The checks that the table's columns ask for, in order, then the verb's own.
Problem checkCommand(const Verb& verb, Command& c) {
    const int n = int(c.args.size());
    if (!verb.text.empty() && n == 0)
        return c.verb + ": expected a description of " + std::string(verb.text);
    if (n < verb.minArgs || (verb.maxArgs >= 0 && n > verb.maxArgs))
        return c.verb + ": expected " +
               (verb.minArgs == verb.maxArgs
                    ? std::to_string(verb.minArgs)
                    : std::to_string(verb.minArgs) + " to " + std::to_string(verb.maxArgs)) +
               " arguments, got " + std::to_string(n);
    if (!verb.choices.empty()) {
        bool ok = false;
        std::string options;
        for (std::string_view choice : verb.choices) {
            ok = ok || choice == c.args[0];
            options += (options.empty() ? "" : ", ") + std::string(choice);
        }
        if (!ok) return c.verb + ": expected one of " + options + ", got \"" + c.args[0] + "\"";
    }
    if (verb.numeric)
        for (size_t i = c.verb == "set" ? 1 : 0; i < c.args.size(); ++i) {
            float v;
            if (!parseFloat(c.args[i], v))
                return c.verb + ": expected a finite number, got \"" + c.args[i] + "\"";
            c.numbers.push_back(v);
        }
    return verb.check ? verb.check(c) : std::nullopt;
}

// The verb, its arguments and the rest of the line as text, without the comment; false for a
// line that holds no command.
bool splitLine(std::string line, Command& c) {
    if (auto hash = line.find('#'); hash != std::string::npos) line.resize(hash);
    std::istringstream words(line);
    if (!(words >> c.verb)) return false;
    if (const auto at = words.tellg(); at >= 0) {
        c.text = line.substr(size_t(at));
        c.text.erase(0, c.text.find_first_not_of(" \t\r"));
        c.text.erase(c.text.find_last_not_of(" \t\r") + 1);
    }
    for (std::string w; words >> w;)
        c.args.push_back(w);
    return true;
}

} // namespace

Result<std::vector<Command>> parseScript(std::string_view text, std::string_view file) {
    std::vector<Command> commands;
    std::vector<Diagnostic> problems;
    std::istringstream in{std::string(text)};
    std::string line;
    int number = 0;
    while (std::getline(in, line)) {
        ++number;
        Command c;
        c.line = number;
        if (!splitLine(line, c)) continue;
        Problem problem;
        if (const Verb* verb = findVerb(c.verb)) {
            problem = checkCommand(*verb, c);
        } else {
            std::string known;
            for (const Verb& v : verbs())
                known += (known.empty() ? "" : ", ") + std::string(v.name);
            problem = "unknown command \"" + c.verb + "\" (known: " + known + ")";
        }
        if (!problem) {
            commands.push_back(std::move(c));
            continue;
        }
        Diagnostic d{std::string(file), {}, std::move(*problem)};
        d.line = number;
        d.column = 1;
        problems.push_back(std::move(d));
    }
    if (!problems.empty()) return Error(ErrorKind::Usage, std::move(problems));
    return commands;
}

} // namespace sdfcsg::viewer
