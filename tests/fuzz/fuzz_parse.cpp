// Fuzz target: bytes -> parseScene -> validation, in both formats (the parser tells the legacy
// format by its top-level "nodes" array). Whatever the bytes, the answer is a scene or an Error
// with at least one message; a scene that loads is well formed and survives toJson and a second
// parse unchanged. Anything else aborts, and libFuzzer keeps the input.
#include <sdfcsg/scene.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>

namespace {

[[noreturn]] void fail(const char* what, const std::string& detail) {
    std::fprintf(stderr, "fuzz_parse: %s\n%s\n", what, detail.c_str());
    std::abort();
}

void checkScene(const sdfcsg::Scene& scene) {
    if (scene.nodes.empty()) fail("a scene without nodes loaded", "");
    for (size_t i = 0; i < scene.nodes.size(); ++i) {
        const sdfcsg::Node& n = scene.nodes[i];
        const bool operation = sdfcsg::kindInfo(n.kind).operation;
        if (operation == n.children.empty()) fail("children do not match the node kind", n.path);
        for (uint32_t c : n.children) // pre-order: a parent precedes its children
            if (c <= i || c >= scene.nodes.size()) fail("child index out of order", n.path);
    }
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::string_view text(reinterpret_cast<const char*>(data), size);
    auto scene = sdfcsg::parseScene(text, "fuzz.json");
    if (!scene) {
        if (scene.error().diagnostics.empty()) fail("an error without a message", "");
        (void)scene.error().str();
        return 0;
    }
    checkScene(*scene);
    const std::string json = sdfcsg::toJson(*scene);
    auto again = sdfcsg::parseScene(json, "fuzz.json");
    if (!again) fail("toJson wrote a scene that does not load", again.error().str() + "\n" + json);
    if (sdfcsg::toJson(*again) != json)
        fail("toJson and parseScene do not round-trip", json + "\n" + sdfcsg::toJson(*again));
    return 0;
}
