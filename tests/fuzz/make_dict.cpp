// Writes a libFuzzer dictionary of the scene format's words, from the node kind table, so the
// fuzzers spend their time on scenes rather than on discovering key names.
#include <sdfcsg/nodes.h>

#include <cstdio>
#include <set>
#include <string>
#include <string_view>

namespace {

std::set<std::string> seen; // several kinds share parameter names

void word(std::string_view w) {
    if (seen.insert(std::string(w)).second)
        std::printf("\"\\\"%.*s\\\"\"\n", int(w.size()), w.data());
}

} // namespace

int main() {
    // Keys outside the node table: the scene object, camera, lights, definitions and uses, and
    // the legacy format.
    for (std::string_view w :
         {"version",     "root",       "camera",    "eye",       "target",     "up",
          "fov",         "lights",     "direction", "intensity", "background", "description",
          "definitions", "parameters", "node",      "use",       "definition", "nodes",
          "left",        "right",      "param1",    "param2"})
        word(w);
    for (const sdfcsg::CommonKey& key : sdfcsg::commonNodeKeys())
        word(key.name);
    for (const sdfcsg::KindInfo& kind : sdfcsg::nodeKinds()) {
        word(kind.name);
        for (const sdfcsg::ParamInfo& param : kind.params)
            word(param.name);
    }
    // Written as libFuzzer reads them: \\ is a backslash, \" a quote.
    for (std::string_view t : {"true", "false", "null", "1e38", "-0", "0.5", "[0, 0, 0]",
                               "\\\\u0000", "\\\\ud800", "\\\"#", "\\\"$"})
        std::printf("\"%.*s\"\n", int(t.size()), t.data());
    return 0;
}
