// Fuzz target: a language model's HTTP answer -> the scene in it -> validation, through the
// public generateScene() with a one-exchange replay, so no network is involved and every step a
// real answer takes is taken: the response shape (OpenAI's or Ollama's), error bodies and status
// codes, refusals and finish reasons, code fences and <think> blocks, null members, the limits on
// untrusted scenes and the validator. The first byte picks the API and the status; the rest is
// the response body.
//
// Whatever the answer, the result is a scene that loads again from its own JSON, or an Error
// with a message, and the API key appears in no message, warning or scene (a hostile server may
// echo it back). No message or warning holds a control character, which could drive the
// terminal it is printed on.
#include <sdfcsg/generate.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

namespace {

constexpr const char* kKey = "sk-fuzz-0123456789abcdef";

[[noreturn]] void fail(const char* what, const std::string& detail) {
    std::fprintf(stderr, "fuzz_llm: %s\n%s\n", what, detail.c_str());
    std::abort();
}

bool printable(const std::string& text) {
    return std::none_of(text.begin(), text.end(), [](char c) {
        const auto b = static_cast<unsigned char>(c);
        return b < 0x20 || b == 0x7f;
    });
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    if (size == 0) return 0;
    static const long kStatus[] = {200, 200, 200, 200, 400, 401, 429, 500};
    const uint8_t pick = data[0];
    std::vector<sdfcsg::HttpExchange> replay(1);
    replay[0].status = kStatus[pick & 7];
    replay[0].response.assign(reinterpret_cast<const char*>(data + 1), size - 1);
    if (pick & 8) replay[0].retryAfter = "0";

    sdfcsg::GenerateOptions options;
    options.llm.baseUrl = pick & 16 ? "http://127.0.0.1:11434" : "http://127.0.0.1:8080/v1";
    options.llm.apiKey = kKey;
    options.llm.model = "fuzz";
    options.maxRepairs = 0; // one answer: a repair round would find the replay exhausted
    options.sleep = [](double) {};
    if (pick & 32) options.currentScene = R"({"version": 1, "root": {"type": "sphere"}})";
    options.replay = &replay;

    auto generated = sdfcsg::generateScene("a fuzzed request", options);
    if (!generated) {
        if (generated.error().diagnostics.empty()) fail("an error without a message", "");
        const std::string text = generated.error().str();
        if (text.find(kKey) != std::string::npos) fail("the API key is in an error", text);
        for (const sdfcsg::Diagnostic& d : generated.error().diagnostics)
            if (!printable(d.str())) fail("a control character in an error", d.str());
        return 0;
    }
    if (generated->json.find(kKey) != std::string::npos)
        fail("the API key is in the scene", generated->json);
    for (const sdfcsg::Diagnostic& warning : generated->warnings)
        if (warning.str().find(kKey) != std::string::npos || !printable(warning.str()))
            fail("the API key or a control character is in a warning", warning.str());
    auto again = sdfcsg::parseScene(generated->json, "fuzz.json", options.limits);
    if (!again) fail("a generated scene does not load again", again.error().str());
    return 0;
}
