// Scene generation against a loopback HTTP server inside the test process (fake_llm_server.h):
// success, the answer shapes, the repair loop, the server's rejections and the client's
// fallbacks, retries, timeouts, cancelling, Ollama's native API, the request body, where the
// key goes, and record/replay.
#include <sdfcsg/generate.h>

#include "fake_llm_server.h"
#include "scene/json_writer.h"
#include "scene/parse_util.h"
#include "scoped_env.h"

#include <gtest/gtest.h>

#include <simdjson.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <deque>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

using namespace sdfcsg;
using namespace sdfcsg::test;
using detail::jsonQuote;
namespace fs = std::filesystem;

namespace {

constexpr const char* kKey = "sk-test-5ecret-k3y-0123456789";
const std::string kSphere = R"({"version": 1, "root": {"type": "sphere", "radius": 1}})";
const std::string kBadSphere = R"({"version": 1, "root": {"type": "sphere", "radius": -1}})";
const std::string kRepairText =
    "Your scene does not load. The validator reported:\n"
    "- root.radius: expected a positive number, got -1\n"
    "Answer with the whole corrected scene as one JSON object, and nothing else.";

Scripted openAiError(int status, const std::string& message, const std::string& param = "",
                     const std::string& code = "") {
    auto orNull = [](const std::string& s) { return s.empty() ? "null" : jsonQuote(s); };
    return {status, R"({"error": {"message": )" + jsonQuote(message) +
                        R"(, "type": "invalid_request_error", "param": )" + orNull(param) +
                        R"(, "code": )" + orNull(code) + "}}"};
}

struct Generate : ::testing::Test {
    FakeServer server;
    std::vector<double> sleeps;
    std::vector<std::string> progress;

    GenerateOptions options() {
        GenerateOptions o;
        o.llm.baseUrl = server.url();
        o.llm.model = "test-model";
        o.llm.apiKey = kKey;
        o.llm.timeoutSeconds = 20;
        o.llm.retryBaseSeconds = 0.5;
        o.llm.proxy = ""; // none from the environment, in front of the loopback
        o.sleep = [this](double s) { sleeps.push_back(s); };
        o.progress = [this](const GenerateProgress& p) {
            if (!p.waiting) progress.push_back(p.message);
        };
        return o;
    }

    // The parsed body of the n-th request the server received.
    simdjson::dom::element body(size_t n) {
        auto received = server.received();
        EXPECT_GT(received.size(), n);
        bodies_.push_back(received.at(n).body);
        return parsers_.emplace_back().parse(bodies_.back());
    }

  private:
    std::deque<std::string> bodies_;
    std::deque<simdjson::dom::parser> parsers_;
};

std::string_view lastMessage(simdjson::dom::element body) {
    simdjson::dom::array messages = body["messages"];
    std::string_view content = messages.at(messages.size() - 1)["content"];
    return content;
}

bool has(simdjson::dom::element object, std::string_view key) {
    simdjson::dom::element e;
    return object[key].get(e) == simdjson::SUCCESS;
}

} // namespace

TEST_F(Generate, FirstTrySuccess) {
    server.script({openAi(kSphere)});
    GenerateStats stats;
    auto g = generateScene("a sphere", options(), &stats);
    ASSERT_TRUE(g) << g.error().str();
    EXPECT_EQ(g->scene.nodes.size(), 1u);
    EXPECT_EQ(g->json, toJson(*parseScene(kSphere)));
    EXPECT_TRUE(g->warnings.empty());
    EXPECT_TRUE(stats.valid);
    EXPECT_TRUE(stats.firstTryValid);
    EXPECT_EQ(stats.answers, 1);
    EXPECT_EQ(stats.requests, 1);
    EXPECT_EQ(stats.mode, OutputMode::JsonSchema);
    EXPECT_EQ(stats.promptTokens, 100u);
    EXPECT_EQ(stats.completionTokens, 20u);
    ASSERT_EQ(server.received().size(), 1u);
    EXPECT_EQ(server.received()[0].path, "/v1/chat/completions");
    EXPECT_EQ(progress, std::vector<std::string>{"asking test-model (json_schema)"});
}

TEST_F(Generate, FencedAndThinkWrappedAnswers) {
    server.script({openAi("<think>A sphere {radius 1}, in ```json```?</think>\nHere:\n```json\n" +
                          kSphere + "\n```\nDone."),
                   openAi("Sure, here it is: " + kSphere)});
    EXPECT_TRUE(generateScene("a sphere", options()));
    EXPECT_TRUE(generateScene("a sphere", options()));
}

TEST_F(Generate, NullMembersAreDropped) {
    // What strict structured output sends for optional keys.
    server.script({openAi(R"({"version": 1, "name": null, "camera": null, "root": {"type":
        "union", "smooth": null, "color": null, "children": [{"type": "sphere", "radius": 1,
        "translate": null, "name": "ball"}]}})")});
    auto g = generateScene("a ball", options());
    ASSERT_TRUE(g) << g.error().str();
    EXPECT_EQ(g->scene.nodes[1].name, "ball");
}

TEST_F(Generate, InvalidJsonThenRepaired) {
    const std::string broken = R"({"version": 1, "root": {"type": "sphere", "radius": 1})";
    server.script({openAi(broken), openAi(kSphere)});
    GenerateStats stats;
    auto g = generateScene("a sphere", options(), &stats);
    ASSERT_TRUE(g) << g.error().str();
    EXPECT_FALSE(stats.firstTryValid);
    EXPECT_EQ(stats.answers, 2);
    auto second = body(1);
    simdjson::dom::array messages = second["messages"];
    ASSERT_EQ(messages.size(), 4u);
    std::string_view role = messages.at(2)["role"], content = messages.at(2)["content"];
    EXPECT_EQ(role, "assistant");
    EXPECT_EQ(content, broken);
    auto problems = parseScene(broken, "answer");
    ASSERT_FALSE(problems);
    EXPECT_EQ(lastMessage(second), sceneRepairPrompt(problems.error()));
    EXPECT_NE(lastMessage(second).find("- line 1, column "), std::string_view::npos);
}

TEST_F(Generate, SemanticallyInvalidThenRepaired) {
    server.script({openAi(kBadSphere), openAi(kSphere)});
    GenerateStats stats;
    ASSERT_TRUE(generateScene("a sphere", options(), &stats));
    EXPECT_EQ(stats.answers, 2);
    EXPECT_EQ(lastMessage(body(1)), kRepairText);
    EXPECT_EQ(progress[1], "the answer does not load (1 problem); asking for a correction");
    EXPECT_EQ(progress[2], "asking test-model for a correction, round 1 of 3 (json_schema)");
}

TEST_F(Generate, RepairLimitReached) {
    server.script({openAi(kBadSphere), openAi(kBadSphere), openAi(kBadSphere), openAi(kSphere)});
    GenerateOptions o = options();
    o.maxRepairs = 2;
    GenerateStats stats;
    auto g = generateScene("a sphere", o, &stats);
    ASSERT_FALSE(g);
    EXPECT_EQ(g.error().kind, ErrorKind::Validation);
    EXPECT_EQ(g.error().str(),
              "answer: no answer loaded after 2 repair rounds; the last one's problems:\n"
              "answer: root.radius: expected a positive number, got -1");
    EXPECT_EQ(stats.answers, 3);
    EXPECT_FALSE(stats.valid);
    EXPECT_EQ(server.received().size(), 3u);
}

// No text is no scene file: the message says so, instead of "expected a JSON value, got end of
// input".
TEST_F(Generate, AnswerWithoutTextSaysSo) {
    GenerateOptions o = options();
    o.maxRepairs = 0;
    for (const char* content : {"null", "42", R"([{"type": "text"}])", R"("  ")"}) {
        SCOPED_TRACE(content);
        server.script({{200, std::string(R"({"choices": [{"index": 0, "message": {"role":
            "assistant", "content": )") +
                                 content + R"(}, "finish_reason": "stop"}]})"}});
        auto g = generateScene("a sphere", o);
        ASSERT_FALSE(g);
        EXPECT_EQ(g.error().str(), "answer: no answer loaded after 0 repair rounds; the last "
                                   "one's problems:\nanswer: the model returned no text");
    }
    server.script({{200, R"({"message": {"role": "assistant"}, "done": true})"},
                   {200, R"({"message": {"role": "assistant", "content": )" + jsonQuote(kSphere) +
                             R"(}, "done": true})"}});
    o.maxRepairs = 1;
    o.llm.baseUrl = server.url("");
    o.llm.api = LlmApi::Ollama;
    ASSERT_TRUE(generateScene("a sphere", o));
    EXPECT_EQ(progress.back(), "asking test-model for a correction, round 1 of 1 (json_schema)");
    EXPECT_EQ(lastMessage(body(server.received().size() - 1)),
              "Your scene does not load. The validator reported:\n- the model returned no "
              "text\nAnswer with the whole corrected scene as one JSON object, and nothing else.");
}

// One of a thing is said in the singular.
TEST_F(Generate, CountsInTheSingular) {
    server.script({openAi(kSphere)});
    GenerateStats stats;
    auto g = generateScene("a sphere", options(), &stats);
    ASSERT_TRUE(g);
    EXPECT_TRUE(generationSummary(*g, stats).starts_with(
        "1 node, valid on the first try (json_schema, 1 request, 100 + 20 "
        "tokens, "))
        << generationSummary(*g, stats);
    stats.firstTryValid = false;
    stats.answers = 2;
    EXPECT_NE(generationSummary(*g, stats).find("valid after 1 repair round ("), std::string::npos);

    GenerateOptions o = options();
    o.maxRepairs = 1;
    server.script({openAi(kBadSphere), openAi(kBadSphere)});
    g = generateScene("a sphere", o);
    ASSERT_FALSE(g);
    EXPECT_EQ(g.error().diagnostics[0].message,
              "no answer loaded after 1 repair round; the last one's problems:");

    o.llm.maxRetries = 0;
    server.script({{503, "Service Unavailable"}});
    g = generateScene("a sphere", o);
    ASSERT_FALSE(g);
    EXPECT_EQ(g.error().diagnostics[0].message,
              "HTTP 503: Service Unavailable (gave up after 1 attempt)");

    std::vector<HttpExchange> one = {{"", "", 200, "", openAi(kBadSphere).body}};
    o.replay = &one;
    g = generateScene("a sphere", o);
    ASSERT_FALSE(g);
    EXPECT_EQ(g.error().diagnostics[0].message,
              "the recording holds 1 exchange, and a further request was made");
}

TEST_F(Generate, UntrustedAnswerLimits) {
    // Too many nodes, and a key that would name a file: both refused by the validator.
    std::string many = R"({"version": 1, "root": {"type": "union", "children": [)";
    for (int i = 0; i < 10; ++i)
        many += std::string(i ? "," : "") + R"({"type": "sphere", "radius": 1})";
    many += "]}}";
    server.script({openAi(many), openAi(R"({"version": 1, "include": "/etc/passwd", "root":
        {"type": "sphere", "radius": 1}})")});
    GenerateOptions o = options();
    o.maxRepairs = 1;
    o.limits.maxNodes = 5;
    auto g = generateScene("spheres", o);
    ASSERT_FALSE(g);
    EXPECT_NE(lastMessage(body(1)).find("nodes"), std::string_view::npos);
    EXPECT_NE(g.error().str().find("unknown key \"include\""), std::string::npos)
        << g.error().str();
}

// The answer's size is limited before it is read whole: the transfer stops at the limit.
TEST_F(Generate, AnswerLargerThanTheLimitIsRefused) {
    server.script({openAi(std::string(R"({"version": 1, "name": ")") + std::string(3000, 'x') +
                          R"(", "root": {"type": "sphere", "radius": 1}})")});
    GenerateOptions o = options();
    o.llm.maxResponseBytes = 2048;
    auto g = generateScene("a sphere", o);
    ASSERT_FALSE(g);
    EXPECT_EQ(g.error().kind, ErrorKind::Remote);
    EXPECT_EQ(g.error().str(),
              server.url() + "/chat/completions: the answer exceeds the limit of 2048 bytes");
}

// An answer too large for a scene goes back in the repair round as an excerpt, since every later
// request carries it again; an HTTP answer beyond four times the scene limit is not read at all.
TEST_F(Generate, OversizedAnswerIsNotEchoedBack) {
    GenerateOptions o = options();
    o.limits.maxFileBytes = 4096;
    const std::string big = R"({"version": 1, "name": ")" + std::string(12000, 'x') +
                            R"(", "root": {"type": "sphere", "radius": 1}})";
    server.script({openAi(big), openAi(big), openAi(kSphere)});
    GenerateStats stats;
    auto g = generateScene("a sphere", o, &stats);
    ASSERT_TRUE(g) << g.error().str();
    EXPECT_EQ(stats.answers, 3);
    auto received = server.received();
    ASSERT_EQ(received.size(), 3u);
    EXPECT_LT(received[1].body.size(), received[0].body.size() + 2000);
    EXPECT_LT(received[2].body.size(), received[0].body.size() + 4000);
    simdjson::dom::array messages = body(1)["messages"];
    ASSERT_EQ(messages.size(), 4u);
    std::string_view echoed = messages.at(2)["content"];
    EXPECT_EQ(echoed, big.substr(0, 1000) +
                          "\n[the rest of this answer is left out: " + std::to_string(big.size()) +
                          " bytes in all, more than a scene may have (4096)]");
    EXPECT_EQ(lastMessage(body(1)),
              "Your scene does not load. The validator reported:\n"
              "- file too large: " +
                  std::to_string(big.size()) +
                  " bytes (the limit is 4096 bytes)\n"
                  "Answer with the whole corrected scene as one JSON object, and nothing else.");

    server.script({openAi(std::string(20000, ' ') + kSphere)});
    g = generateScene("a sphere", o);
    ASSERT_FALSE(g);
    EXPECT_EQ(g.error().str(),
              server.url() + "/chat/completions: the answer exceeds the limit of 16384 bytes");
}

TEST_F(Generate, FinishReasonLength) {
    server.script({openAi(R"({"version": 1, "root": {"type": "uni)", "length")});
    auto g = generateScene("a sphere", options());
    ASSERT_FALSE(g);
    EXPECT_EQ(g.error().kind, ErrorKind::Remote);
    EXPECT_EQ(g.error().str(), server.url() + "/chat/completions: the answer was cut off at the "
                                              "token limit (8192 tokens); ask for a simpler scene "
                                              "or raise the limit");
}

TEST_F(Generate, Refusal) {
    server.script({{200, R"({"choices": [{"index": 0, "message": {"role": "assistant",
        "content": null, "refusal": "I'm sorry, I can't help with that."}, "finish_reason":
        "stop"}]})"}});
    auto g = generateScene("something", options());
    ASSERT_FALSE(g);
    EXPECT_EQ(g.error().kind, ErrorKind::Remote);
    EXPECT_EQ(g.error().diagnostics[0].message,
              "the model refused: I'm sorry, I can't help with that.");
}

TEST_F(Generate, ResponseFormatRejectedThenJsonMode) {
    server.script({openAiError(400,
                               "Invalid parameter: 'response_format' of type 'json_schema' is not "
                               "supported with this model.",
                               "response_format"),
                   openAi(kSphere)});
    GenerateStats stats;
    ASSERT_TRUE(generateScene("a sphere", options(), &stats));
    EXPECT_EQ(stats.mode, OutputMode::JsonObject);
    std::string_view first = body(0)["response_format"]["type"];
    std::string_view second = body(1)["response_format"]["type"];
    EXPECT_EQ(first, "json_schema");
    EXPECT_EQ(second, "json_object");
    EXPECT_EQ(progress[1], "the server rejects json_schema output; falling back to json_object");
}

TEST_F(Generate, JsonModeRejectedThenText) {
    // llama.cpp-style error objects, without a param.
    server.script(
        {{400,
          R"({"error": {"code": 400, "message": "Unsupported response_format type: json_schema", "type": "invalid_request_error"}})"},
         {400,
          R"({"error": {"code": 400, "message": "'response_format' must be one of 'text'", "type": "invalid_request_error"}})"},
         openAi("```json\n" + kSphere + "\n```")});
    GenerateStats stats;
    ASSERT_TRUE(generateScene("a sphere", options(), &stats));
    EXPECT_EQ(stats.mode, OutputMode::Text);
    EXPECT_EQ(stats.requests, 3);
    EXPECT_FALSE(has(body(2), "response_format"));
}

TEST_F(Generate, MaxTokensRejectedThenResent) {
    server.script({openAiError(400,
                               "Unsupported parameter: 'max_tokens' is not supported with this "
                               "model. Use 'max_completion_tokens' instead.",
                               "max_tokens", "unsupported_parameter"),
                   openAiError(400,
                               "Unsupported value: 'temperature' does not support 0.2 with this "
                               "model. Only the default (1) value is supported.",
                               "temperature", "unsupported_value"),
                   openAi(kSphere)});
    GenerateStats stats;
    ASSERT_TRUE(generateScene("a sphere", options(), &stats));
    EXPECT_EQ(stats.requests, 3);
    EXPECT_TRUE(has(body(0), "max_tokens"));
    EXPECT_TRUE(has(body(0), "temperature"));
    EXPECT_FALSE(has(body(1), "max_tokens"));
    EXPECT_EQ(uint64_t(body(1)["max_completion_tokens"]), 8192u);
    EXPECT_TRUE(has(body(1), "temperature"));
    EXPECT_FALSE(has(body(2), "temperature"));
    EXPECT_TRUE(has(body(2), "max_completion_tokens"));
    std::string_view mode = body(2)["response_format"]["type"];
    EXPECT_EQ(mode, "json_schema");
}

TEST_F(Generate, Unauthorized) {
    server.script({openAiError(401,
                               "Incorrect API key provided: sk-test-****6789. You can find your "
                               "API key at https://platform.openai.com/account/api-keys.",
                               "", "invalid_api_key")});
    auto g = generateScene("a sphere", options());
    ASSERT_FALSE(g);
    EXPECT_EQ(g.error().kind, ErrorKind::Remote);
    EXPECT_EQ(g.error().str(), server.url() +
                                   "/chat/completions: HTTP 401: Incorrect API key provided: "
                                   "[redacted]. You can find your API key at "
                                   "https://platform.openai.com/account/api-keys. (check "
                                   "SDFCSG_LLM_API_KEY or OPENAI_API_KEY)");
    EXPECT_EQ(server.received().size(), 1u); // not retried
}

// A server that quotes the key back, in a body that is no answer and in a scene key: neither
// message carries it (fuzz_llm found the first). Nor does a recording of a server that echoes
// the Authorization header, or a scene whose model repeated the key.
TEST_F(Generate, KeyEchoedByTheServerIsRedacted) {
    server.script({{200, std::string("<html>bad key ") + kKey + "</html>"}});
    auto g = generateScene("a sphere", options());
    ASSERT_FALSE(g);
    EXPECT_EQ(g.error().str(), server.url() + "/chat/completions: unexpected answer (not a JSON "
                                              "object): <html>bad key [redacted]</html>");

    auto o = options();
    o.maxRepairs = 0;
    server.script({openAi(std::string(R"({"version": 1, "root": {"type": "sphere", ")") + kKey +
                          R"(": 1}})")});
    g = generateScene("a sphere", o);
    ASSERT_FALSE(g);
    EXPECT_EQ(g.error().str().find(kKey), std::string::npos) << g.error().str();
    EXPECT_NE(g.error().str().find("[redacted]"), std::string::npos) << g.error().str();

    // The header echoed in a 400, with OpenAI's masked form of the key at the end.
    std::vector<HttpExchange> recording;
    o.record = &recording;
    Scripted echo = openAiError(
        400, "invalid header 'Authorization: $AUTHORIZATION'; the key is sk-test-****6789");
    echo.echo = true;
    server.script({echo});
    g = generateScene("a sphere", o);
    ASSERT_FALSE(g);
    const std::string expected = server.url() + "/chat/completions: HTTP 400: invalid header "
                                                "'Authorization: Bearer [redacted]'; the key is "
                                                "[redacted]";
    EXPECT_EQ(g.error().str(), expected);
    ASSERT_EQ(recording.size(), 1u);
    ASSERT_NE(server.received().back().headers.count("Authorization"), 0u);
    EXPECT_NE(recording[0].response.find("Bearer [redacted]"), std::string::npos)
        << recording[0].response;
    EXPECT_EQ(recordingToJson(recording).find(kKey), std::string::npos);
    EXPECT_EQ(recordingToJson(recording).find("sk-test-"), std::string::npos);
    // The redacted body is still the server's JSON, so a replay fails the same way.
    auto replay = parseRecording(recordingToJson(recording));
    ASSERT_TRUE(replay);
    auto r = o;
    r.record = nullptr;
    r.replay = &*replay;
    auto replayed = generateScene("a sphere", r);
    ASSERT_FALSE(replayed);
    EXPECT_EQ(replayed.error().str(), expected);

    // A model that repeats the key, as it is and with a JSON escape: the scene, the recording
    // and the next request keep none of it.
    recording.clear();
    o.maxRepairs = 1;
    server.script(
        {openAi(std::string(R"({"version": 1, "root": {"type": "sphere", "radius": -1,
        "name": ")") +
                kKey + R"("}})"),
         openAi(std::string(R"({"version": 1, "name": ")") + kKey +
                R"(", "description": "key: \u0073)" + (kKey + 1) +
                R"(", "root": {"type": "sphere", "radius": 1, "name": ")" + kKey + R"("}})")});
    g = generateScene("a sphere", o);
    ASSERT_TRUE(g) << g.error().str();
    EXPECT_EQ(g->json.find(kKey), std::string::npos) << g->json;
    EXPECT_EQ(g->scene.name, "[redacted]");
    EXPECT_EQ(g->scene.description, "key: [redacted]");
    EXPECT_EQ(g->scene.nodes[0].name, "[redacted]");
    EXPECT_EQ(g->json, toJson(g->scene));
    EXPECT_EQ(recordingToJson(recording).find(kKey), std::string::npos);
    EXPECT_EQ(server.received().back().body.find(kKey), std::string::npos);
}

// Error messages, a refusal, a body that is no answer and the validator's problems all carry
// the server's or the model's text: none reaches the terminal with an ESC sequence, a forged
// line or bytes that are not UTF-8.
TEST_F(Generate, RemoteTextCannotDriveTheTerminal) {
    const std::string url = server.url() + "/chat/completions: ";
    server.script({openAiError(400, "\x1b[2J\x1b[31mbad request\nsdfcsg: wrote scene.json")});
    auto g = generateScene("a sphere", options());
    ASSERT_FALSE(g);
    EXPECT_EQ(g.error().str(),
              url + "HTTP 400: \\u001b[2J\\u001b[31mbad request\\nsdfcsg: wrote scene.json");

    server.script({{200, "\xff\xfe<html>\x1b]0;owned\x07\xc2\x9b"
                         "31m\x7f"}});
    g = generateScene("a sphere", options());
    ASSERT_FALSE(g);
    EXPECT_EQ(g.error().str(), url + "unexpected answer (not a JSON object): "
                                     "\\xff\\xfe<html>\\u001b]0;owned\\u0007\\u009b31m\\u007f");

    server.script({{200, R"({"choices": [{"index": 0, "message": {"role": "assistant",
        "content": null, "refusal": "no\u001b[8m"}, "finish_reason": "stop"}]})"}});
    g = generateScene("a sphere", options());
    ASSERT_FALSE(g);
    EXPECT_EQ(g.error().str(), url + "the model refused: no\\u001b[8m");

    // Retried errors are shown while waiting.
    server.script({openAiError(503, "busy\r\x1b[1A"), openAi(kSphere)});
    progress.clear();
    ASSERT_TRUE(generateScene("a sphere", options()));
    ASSERT_GE(progress.size(), 2u);
    EXPECT_EQ(progress[1], "HTTP 503: busy\\r\\u001b[1A; retrying in 0.5 s (attempt 2 of 5)");

    // A scene key in the answer, quoted by the validator.
    auto o = options();
    o.maxRepairs = 0;
    server.script({openAi(R"({"version": 1, "root": {"type": "sphere", "radius": 1,
        "\u001b[2J": 1}})")});
    g = generateScene("a sphere", o);
    ASSERT_FALSE(g);
    EXPECT_EQ(g.error().diagnostics.back().str(),
              "answer: root: unknown key \"\\u001b[2J\" for a sphere; valid keys: radius, type, "
              "name, translate, rotate, scale and color");
    for (const Diagnostic& d : g.error().diagnostics)
        EXPECT_EQ(d.str().find('\x1b'), std::string::npos) << d.str();
}

TEST_F(Generate, RateLimitedHonoursRetryAfter) {
    server.script(
        {{429, R"({"error": {"message": "Rate limit reached", "code": "rate_limit_exceeded"}})",
          "3"},
         {429, R"({"error": {"message": "Rate limit reached"}})"},
         {429, R"({"error": {"message": "Rate limit reached"}})", "120"},
         openAi(kSphere)});
    GenerateStats stats;
    ASSERT_TRUE(generateScene("a sphere", options(), &stats));
    EXPECT_EQ(stats.requests, 4);
    // Retry-After, then the back-off (0.5 s doubled once), then Retry-After capped at 60 s.
    EXPECT_EQ(sleeps, (std::vector<double>{3.0, 1.0, 60.0}));
    EXPECT_EQ(progress[1], "HTTP 429: Rate limit reached; retrying in 3 s (attempt 2 of 5)");
}

TEST_F(Generate, QuotaExhaustedIsNotRetried) {
    server.script({openAiError(429, "You exceeded your current quota.", "", "insufficient_quota")});
    auto g = generateScene("a sphere", options());
    ASSERT_FALSE(g);
    EXPECT_EQ(g.error().diagnostics[0].message, "HTTP 429: You exceeded your current quota.");
    EXPECT_TRUE(sleeps.empty());
}

TEST_F(Generate, ServerErrorThenSuccess) {
    server.script({{500, R"({"error": {"message": "The server had an error"}})"}, openAi(kSphere)});
    GenerateStats stats;
    ASSERT_TRUE(generateScene("a sphere", options(), &stats));
    EXPECT_EQ(stats.requests, 2);
    EXPECT_EQ(sleeps, std::vector<double>{0.5});
}

TEST_F(Generate, ServerErrorsGiveUp) {
    server.script(
        {{503, "Service Unavailable"}, {502, "Bad Gateway"}, {503, "Service Unavailable"}});
    GenerateOptions o = options();
    o.llm.maxRetries = 2;
    auto g = generateScene("a sphere", o);
    ASSERT_FALSE(g);
    EXPECT_EQ(g.error().diagnostics[0].message,
              "HTTP 503: Service Unavailable (gave up after 3 attempts)");
    EXPECT_EQ(sleeps, (std::vector<double>{0.5, 1.0}));
}

// A request goes to the proxy that LlmConfig::proxy names, in absolute form; where that is
// unset, to the one that curl's standard variables name (http_proxy, for a host outside
// no_proxy), which curl reads at each request.
TEST_F(Generate, RequestsGoThroughTheProxy) {
    for (bool fromEnvironment : {false, true}) {
        SCOPED_TRACE(fromEnvironment ? "http_proxy" : "LlmConfig::proxy");
        server.script({openAi(kSphere)});
        GenerateOptions o = options();
        o.llm.baseUrl = "http://llm.example.invalid/v1";
        std::optional<ScopedEnv> proxy, noProxy;
        if (fromEnvironment) {
            o.llm.proxy.reset();
            proxy.emplace("http_proxy", server.url(""));
            noProxy.emplace("no_proxy", "127.0.0.1,localhost");
        } else {
            o.llm.proxy = server.url("");
        }
        auto g = generateScene("a sphere", o);
        ASSERT_TRUE(g) << g.error().str();
        auto received = server.received();
        ASSERT_EQ(received.size(), fromEnvironment ? 2u : 1u);
        EXPECT_EQ(received.back().path, "http://llm.example.invalid/v1/chat/completions");
    }
}

TEST_F(Generate, Timeout) {
    server.script({{200, "{}", "", true}});
    GenerateOptions o = options();
    o.llm.timeoutSeconds = 0.3;
    auto g = generateScene("a sphere", o);
    server.release();
    ASSERT_FALSE(g);
    EXPECT_EQ(g.error().kind, ErrorKind::Remote);
    EXPECT_EQ(g.error().str(), server.url() + "/chat/completions: no complete answer within "
                                              "0.3 s (the request timeout)");
}

TEST_F(Generate, CancelDuringASlowAnswer) {
    server.script({{200, "{}", "", true}}); // would answer after 20 s
    std::atomic<bool> cancel{false};
    GenerateOptions o = options();
    o.cancelled = [&] { return cancel.load(); };
    std::thread canceller([&] {
        if (server.awaitRequests(1)) cancel = true;
    });
    const auto start = std::chrono::steady_clock::now();
    auto g = generateScene("a sphere", o);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    canceller.join();
    ASSERT_FALSE(g);
    EXPECT_EQ(g.error().kind, ErrorKind::Cancelled);
    EXPECT_EQ(g.error().str(), server.url() + "/chat/completions: cancelled");
    // libcurl asks about once a second while nothing arrives; the answer would take 20 s.
    EXPECT_LT(seconds, 10.0);
}

TEST_F(Generate, CancelDuringTheRetryWait) {
    server.script({openAiError(503, "Service Unavailable"), openAi(kSphere)});
    bool cancel = false;
    GenerateOptions o = options();
    o.cancelled = [&] { return cancel; };
    o.sleep = [&](double) { cancel = true; };
    auto g = generateScene("a sphere", o);
    ASSERT_FALSE(g);
    EXPECT_EQ(g.error().kind, ErrorKind::Cancelled);
    EXPECT_EQ(server.received().size(), 1u); // the retry was never sent

    // The engine's own wait ends early too: a 60 s back-off, cancelled after the first request.
    server.script({openAiError(503, "Service Unavailable"), openAi(kSphere)});
    std::atomic<bool> later{false};
    o.sleep = nullptr;
    o.llm.retryBaseSeconds = 60;
    o.cancelled = [&] { return later.load(); };
    std::thread canceller([&] {
        if (server.awaitRequests(2)) later = true;
    });
    const auto start = std::chrono::steady_clock::now();
    g = generateScene("a sphere", o);
    canceller.join();
    ASSERT_FALSE(g);
    EXPECT_EQ(g.error().kind, ErrorKind::Cancelled);
    EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(),
              30.0);
}

TEST_F(Generate, ConnectionRefused) {
    GenerateOptions o = options();
    o.llm.baseUrl = "http://127.0.0.1:1/v1";
    auto g = generateScene("a sphere", o);
    ASSERT_FALSE(g);
    EXPECT_EQ(g.error().kind, ErrorKind::Remote);
    EXPECT_TRUE(
        g.error().str().starts_with("http://127.0.0.1:1/v1/chat/completions: request failed: "))
        << g.error().str();
}

// A key typed into the base URL, as user information and as a query value, reaches the server
// but no message or recording: not in the URL that messages name, nor where the server quotes it.
TEST_F(Generate, KeyInTheBaseUrlIsRedacted) {
    const std::string port = server.url("").substr(std::string("http://127.0.0.1:").size());
    GenerateOptions o = options();
    o.llm.baseUrl = "http://me:url-secret-1234@127.0.0.1:" + port + "/v1/?key=query-secret-5678";
    std::vector<HttpExchange> recording;
    o.record = &recording;
    server.script({openAiError(404, "no route for /v1/chat/completions?key=query-secret-5678 "
                                    "(user me:url-secret-1234)")});
    auto g = generateScene("a sphere", o);
    ASSERT_FALSE(g);
    EXPECT_EQ(g.error().str(), "http://[redacted]@127.0.0.1:" + port +
                                   "/v1/chat/completions?key=[redacted]: HTTP 404: no route for "
                                   "/v1/chat/completions?key=[redacted] (user me:[redacted]) "
                                   "(check the base URL and the model name)");
    ASSERT_EQ(server.received().size(), 1u);
    EXPECT_EQ(server.received()[0].path, "/v1/chat/completions");
    ASSERT_EQ(recording.size(), 1u);
    EXPECT_EQ(recording[0].url,
              "http://[redacted]@127.0.0.1:" + port + "/v1/chat/completions?key=[redacted]");
    EXPECT_EQ(recordingToJson(recording).find("secret"), std::string::npos);

    o.record = nullptr;
    o.llm.baseUrl = "http://me:url-secret-1234@127.0.0.1:1/v1?key=query-secret-5678";
    g = generateScene("a sphere", o);
    ASSERT_FALSE(g);
    EXPECT_TRUE(g.error().str().starts_with(
        "http://[redacted]@127.0.0.1:1/v1/chat/completions?key=[redacted]: request failed: "))
        << g.error().str();
    EXPECT_EQ(g.error().str().find("secret"), std::string::npos) << g.error().str();

    o.llm.baseUrl = "localhost:1/v1?api_key=query-secret-5678";
    auto bad = firstLlmRequest("x", o);
    ASSERT_FALSE(bad);
    EXPECT_EQ(bad.error().diagnostics[0].message,
              "the base URL must start with http:// or "
              "https://, got \"localhost:1/v1?api_key=[redacted]\"");
    o.llm.baseUrl = "https://me:url-secret-1234@example.org/v1?key=query-secret-5678#part";
    auto request = firstLlmRequest("x", o);
    ASSERT_TRUE(request) << request.error().str();
    EXPECT_EQ(request->url,
              "https://me:url-secret-1234@example.org/v1/chat/completions?key=query-secret-5678");
    EXPECT_EQ(request->shownUrl,
              "https://[redacted]@example.org/v1/chat/completions?key=[redacted]");
}

// A model that names files as fonts learns nothing about them: whether a path exists, is a
// folder, a device or a secret, the problem that goes back in the conversation reads the same.
// A family name loads.
TEST_F(Generate, FontPathsInAnAnswerTellNothingAboutTheFileSystem) {
    const std::string home = std::getenv("HOME") ? std::getenv("HOME") : "/root";
    const std::vector<std::string> probes = {
        "/etc/passwd", "/etc/shadow",      home + "/.ssh/id_rsa",    "/etc",
        "/dev/zero",   "/nonexistent.ttf", "../../../../etc/passwd", "No Such Family"};
    auto answer = [](const std::string& font) {
        return openAi(R"({"version": 1, "root": {"type": "extrude", "height": 0.2, "children":
            [{"type": "text", "text": "Hi", "font": )" +
                      jsonQuote(font) + "}]}}");
    };
    std::vector<Scripted> script;
    for (const std::string& font : probes)
        script.push_back(answer(font));
    script.push_back(answer("DejaVu Sans"));
    server.script(script);
    auto o = options();
    o.maxRepairs = int(probes.size());
    auto g = generateScene("a sign", o);
    ASSERT_TRUE(g) << g.error().str();
    EXPECT_FALSE(g->scene.files.trusted);
    ASSERT_EQ(server.received().size(), probes.size() + 1);
    for (size_t i = 0; i < probes.size(); ++i) {
        const std::string repair(lastMessage(body(i + 1)));
        EXPECT_EQ(repair, "Your scene does not load. The validator reported:\n"
                          "- root.children[0].font: unknown font " +
                              detail::quote(probes[i]) +
                              ": name an installed font family, such as \"DejaVu Sans\", or "
                              "leave it out\n"
                              "Answer with the whole corrected scene as one JSON object, and "
                              "nothing else.");
    }
}

TEST_F(Generate, OllamaNativeApi) {
    server.script({{200, R"({"model": "test-model", "created_at": "2025-01-01T00:00:00Z",
        "message": {"role": "assistant", "content": )" +
                             jsonQuote(kSphere) + R"(}, "done": true,
        "done_reason": "stop", "prompt_eval_count": 321, "eval_count": 45})"}});
    GenerateOptions o = options();
    o.llm.baseUrl = server.url("");
    o.llm.api = LlmApi::Ollama;
    GenerateStats stats;
    auto g = generateScene("a sphere", o, &stats);
    ASSERT_TRUE(g) << g.error().str();
    EXPECT_EQ(stats.promptTokens, 321u);
    EXPECT_EQ(stats.completionTokens, 45u);
    EXPECT_EQ(server.received()[0].path, "/api/chat");
    auto request = body(0);
    EXPECT_FALSE(bool(request["stream"]));
    EXPECT_EQ(uint64_t(request["options"]["num_ctx"]), 16384u);
    EXPECT_EQ(uint64_t(request["options"]["num_predict"]), 8192u);
    EXPECT_TRUE(request["format"].is_object());
    EXPECT_FALSE(has(request, "response_format"));
    EXPECT_FALSE(has(request, "max_tokens"));

    // Ollama's error shape, and its default port chosen automatically (its /v1 cuts prompts).
    server.script({{400, R"({"error": "invalid format: expected \"json\" or a JSON schema"})"},
                   {200, R"({"message": {"role": "assistant", "content": )" + jsonQuote(kSphere) +
                             R"(}, "done": true, "done_reason": "stop"})"}});
    ASSERT_TRUE(generateScene("a sphere", o, &stats));
    std::string_view format = body(2)["format"];
    EXPECT_EQ(format, "json");
    GenerateOptions detected;
    detected.llm.baseUrl = "http://localhost:11434/v1/";
    detected.llm.model = "qwen2.5";
    auto r = firstLlmRequest("a sphere", detected);
    ASSERT_TRUE(r);
    EXPECT_EQ(r->url, "http://localhost:11434/api/chat");
}

TEST_F(Generate, EditSendsTheCurrentScene) {
    server.script({openAi(kSphere)});
    GenerateOptions o = options();
    o.currentScene = toJson(*parseScene(kSphere));
    ASSERT_TRUE(generateScene("make it bigger", o));
    EXPECT_EQ(lastMessage(body(0)), sceneUserPrompt("make it bigger", o.currentScene));
    EXPECT_TRUE(
        lastMessage(body(0)).starts_with("Here is the current scene:\n{\n  \"version\": 1"));
}

// The whole first request, byte for byte, against a checked-in file, so that any change to the
// prompt, the schema or the body shows as a change of tests/data/llm/first_request.json. On a
// difference the body sent is written to SDFCSG_TEST_OUTPUT_DIR/llm/first_request.actual.json;
// SDFCSG_UPDATE_GOLDEN=1 rewrites the checked-in file instead, as for the golden images.
TEST_F(Generate, RequestBodyGolden) {
    server.script({openAi(kSphere)});
    ASSERT_TRUE(generateScene("a red sphere", options()));
    const std::string sent = server.received().at(0).body;
    auto preview = firstLlmRequest("a red sphere", options());
    ASSERT_TRUE(preview);
    EXPECT_TRUE(preview->body == sent); // not EXPECT_EQ: it would print 40 kB twice
    EXPECT_EQ(preview->url, server.url() + "/chat/completions");

    const fs::path golden = fs::path(SDFCSG_SOURCE_DIR) / "tests/data/llm/first_request.json";
    if (const char* update = std::getenv("SDFCSG_UPDATE_GOLDEN");
        update && std::string(update) == "1") {
        std::ofstream(golden, std::ios::binary) << sent;
        std::printf("updated %s\n", golden.string().c_str());
        return;
    }
    std::ifstream in(golden, std::ios::binary);
    std::ostringstream text;
    text << in.rdbuf();
    const std::string expected = text.str();
    const fs::path actual = fs::path(SDFCSG_TEST_OUTPUT_DIR) / "llm" / "first_request.actual.json";
    fs::remove(actual);
    if (sent == expected) return;
    fs::create_directories(actual.parent_path());
    std::ofstream(actual, std::ios::binary) << sent;
    const size_t at =
        size_t(std::mismatch(sent.begin(), sent.end(), expected.begin(), expected.end()).first -
               sent.begin());
    ADD_FAILURE() << "the first request differs from " << golden << " from byte " << at
                  << ":\n  sent:     ..." << sent.substr(at > 40 ? at - 40 : 0, 120)
                  << "\n  expected: ..." << expected.substr(at > 40 ? at - 40 : 0, 120)
                  << "\n  The whole body sent is in " << actual
                  << ".\n  If the change is intended, run with SDFCSG_UPDATE_GOLDEN=1 "
                     "(SDFCSG_UPDATE_GOLDEN=1 ctest -R Generate.RequestBodyGolden).";
}

TEST_F(Generate, KeyOnlyInTheAuthorizationHeader) {
    server.script(
        {{500, R"({"error": {"message": "oops"}})"}, openAi(kBadSphere), openAi(kSphere)});
    std::vector<HttpExchange> recording;
    GenerateOptions o = options();
    o.record = &recording;
    std::vector<std::string> all;
    o.progress = [&](const GenerateProgress& p) { all.push_back(p.message); };
    ASSERT_TRUE(generateScene("a sphere", o));
    auto received = server.received();
    ASSERT_EQ(received.size(), 3u);
    for (const Received& r : received) {
        EXPECT_EQ(r.body.find(kKey), std::string::npos);
        EXPECT_EQ(r.path.find(kKey), std::string::npos);
        int authorizations = 0;
        for (const auto& [name, value] : r.headers) {
            if (name == "Authorization") {
                ++authorizations;
                EXPECT_EQ(value, std::string("Bearer ") + kKey);
            } else {
                EXPECT_EQ(value.find(kKey), std::string::npos) << name;
            }
        }
        EXPECT_EQ(authorizations, 1);
    }
    EXPECT_EQ(recordingToJson(recording).find(kKey), std::string::npos);
    for (const std::string& m : all)
        EXPECT_EQ(m.find(kKey), std::string::npos) << m;

    // No key, no header (local servers).
    server.script({openAi(kSphere)});
    o.llm.apiKey.clear();
    ASSERT_TRUE(generateScene("a sphere", o));
    EXPECT_FALSE(server.received().back().headers.count("Authorization"));
}

TEST_F(Generate, RecordReplayRoundTrip) {
    server.script({{429, R"({"error": {"message": "slow down"}})", "1"},
                   openAi(kBadSphere),
                   openAi(kSphere)});
    std::vector<HttpExchange> recorded;
    GenerateOptions o = options();
    o.record = &recorded;
    GenerateStats live;
    auto first = generateScene("a sphere", o, &live);
    ASSERT_TRUE(first) << first.error().str();
    ASSERT_EQ(recorded.size(), 3u);
    EXPECT_EQ(recorded[0].status, 429);
    EXPECT_EQ(recorded[0].retryAfter, "1");
    EXPECT_EQ(recorded[2].request, server.received()[2].body);

    const std::string json = recordingToJson(recorded);
    auto parsed = parseRecording(json, "rec.json");
    ASSERT_TRUE(parsed) << parsed.error().str();
    EXPECT_EQ(recordingToJson(*parsed), json);

    // The replay reaches no server: the URL points at a closed port.
    GenerateOptions r = options();
    r.llm.baseUrl = "http://127.0.0.1:1/v1";
    r.replay = &*parsed;
    sleeps.clear();
    GenerateStats replayed;
    auto again = generateScene("a sphere", r, &replayed);
    ASSERT_TRUE(again) << again.error().str();
    EXPECT_EQ(again->json, first->json);
    EXPECT_EQ(replayed.requests, live.requests);
    EXPECT_EQ(replayed.answers, live.answers);
    EXPECT_EQ(replayed.promptTokens, live.promptTokens);
    EXPECT_TRUE(sleeps.empty()); // a replay does not wait
    EXPECT_EQ(server.received().size(), 3u);

    // A replay that runs out says so.
    std::vector<HttpExchange> shorter(parsed->begin(), parsed->begin() + 2);
    r.replay = &shorter;
    auto cut = generateScene("a sphere", r);
    ASSERT_FALSE(cut);
    EXPECT_EQ(cut.error().diagnostics[0].message,
              "the recording holds 2 exchanges, and a further request was made");

    auto bad = parseRecording(R"({"version": 1, "exchanges": [{"url": "x"}]})", "rec.json");
    ASSERT_FALSE(bad);
    EXPECT_EQ(bad.error().str(), "rec.json: exchanges[0]: expected an object with url, request, "
                                 "status, retry_after and response");
}

TEST(GenerateConfig, Usage) {
    GenerateOptions o;
    o.llm.baseUrl = "localhost:8080";
    o.llm.model = "m";
    auto bad = firstLlmRequest("x", o);
    ASSERT_FALSE(bad);
    EXPECT_EQ(bad.error().kind, ErrorKind::Usage);
    EXPECT_EQ(bad.error().diagnostics[0].message,
              "the base URL must start with http:// or https://, got \"localhost:8080\"");
    o.llm.baseUrl = "http://localhost:8080/v1";
    o.llm.model.clear();
    auto noModel = generateScene("x", o);
    ASSERT_FALSE(noModel);
    EXPECT_EQ(noModel.error().diagnostics[0].message,
              "no model given: set SDFCSG_LLM_MODEL or pass --model");
    o.llm.baseUrl = "https://api.openai.com/v1";
    auto openai = firstLlmRequest("x", o);
    ASSERT_TRUE(openai);
    EXPECT_NE(openai->body.find(R"("model":"gpt-4o-mini")"), std::string::npos);
}

// With no key and no base URL, the request would go to api.openai.com without a key and come
// back a 401 (or fail on the network): generation says at once what to set, and sends nothing.
// A dry run still shows the request.
TEST(GenerateConfig, NoKeyForOpenAiSaysWhatToSet) {
    GenerateOptions o;
    o.llm = llmConfigFromEnvironment([](const char*) -> const char* { return nullptr; });
    o.llm.proxy = "http://127.0.0.1:1"; // were a request sent, it would fail here, not say this
    auto g = generateScene("a sphere", o);
    ASSERT_FALSE(g);
    EXPECT_EQ(g.error().kind, ErrorKind::Usage);
    EXPECT_EQ(g.error().str(), "<llm>: no API key for api.openai.com: set SDFCSG_LLM_API_KEY or "
                               "OPENAI_API_KEY, or point SDFCSG_LLM_BASE_URL (or --base-url) at a "
                               "server that needs no key");
    EXPECT_TRUE(firstLlmRequest("a sphere", o));
}

TEST(GenerateConfig, EndpointWithTheDefaultsApplied) {
    LlmConfig c;
    c.baseUrl = "https://api.openai.com/v1/";
    auto openai = llmEndpoint(c);
    ASSERT_TRUE(openai) << openai.error().str();
    EXPECT_EQ(openai->url, "https://api.openai.com/v1/chat/completions");
    EXPECT_EQ(openai->api, LlmApi::OpenAI);
    EXPECT_EQ(openai->model, "gpt-4o-mini");
    c.baseUrl = "http://127.0.0.1:11434/v1";
    c.model = "llama3.1";
    auto ollama = llmEndpoint(c);
    ASSERT_TRUE(ollama) << ollama.error().str();
    EXPECT_EQ(ollama->url, "http://127.0.0.1:11434/api/chat");
    EXPECT_EQ(ollama->api, LlmApi::Ollama);
    EXPECT_EQ(ollama->model, "llama3.1");
    c.model.clear();
    auto none = llmEndpoint(c);
    ASSERT_FALSE(none);
    EXPECT_EQ(none.error().kind, ErrorKind::Usage);
}

TEST(GenerateConfig, Environment) {
    std::map<std::string, std::string> environment;
    auto lookup = [&](const char* name) -> const char* {
        auto it = environment.find(name);
        return it == environment.end() ? nullptr : it->second.c_str();
    };
    LlmConfig c = llmConfigFromEnvironment(lookup);
    EXPECT_EQ(c.baseUrl, "https://api.openai.com/v1");
    EXPECT_EQ(c.apiKey, "");
    EXPECT_EQ(c.model, "");
    environment = {{"OPENAI_BASE_URL", "http://openai.example/v1"},
                   {"OPENAI_API_KEY", "openai-key"},
                   {"SDFCSG_LLM_MODEL", "some-model"}};
    c = llmConfigFromEnvironment(lookup);
    EXPECT_EQ(c.baseUrl, "http://openai.example/v1");
    EXPECT_EQ(c.apiKey, "openai-key");
    EXPECT_EQ(c.model, "some-model");
    EXPECT_EQ(c.api, LlmApi::Auto);
    environment["SDFCSG_LLM_BASE_URL"] = "http://local:8080/v1";
    environment["SDFCSG_LLM_API_KEY"] = "local-key";
    environment["SDFCSG_LLM_API"] = "ollama";
    c = llmConfigFromEnvironment(lookup);
    EXPECT_EQ(c.baseUrl, "http://local:8080/v1");
    EXPECT_EQ(c.apiKey, "local-key");
    EXPECT_EQ(c.api, LlmApi::Ollama);
    environment["SDFCSG_LLM_API"] = "openai";
    EXPECT_EQ(llmConfigFromEnvironment(lookup).api, LlmApi::OpenAI);
}

// Against a real endpoint, only on request: SDFCSG_LLM_LIVE=1 with SDFCSG_LLM_BASE_URL or
// OPENAI_BASE_URL, or an API key for api.openai.com.
TEST(GenerateLive, OriginalPrompt) {
    const char* live = std::getenv("SDFCSG_LLM_LIVE");
    LlmConfig config = llmConfigFromEnvironment();
    const bool configured = std::getenv("SDFCSG_LLM_BASE_URL") || std::getenv("OPENAI_BASE_URL") ||
                            !config.apiKey.empty();
    if (!live || std::string(live) != "1" || !configured)
        GTEST_SKIP() << "set SDFCSG_LLM_LIVE=1 and an endpoint (SDFCSG_LLM_BASE_URL, "
                        "SDFCSG_LLM_MODEL, SDFCSG_LLM_API_KEY) to run";
    GenerateOptions options;
    options.llm = config;
    GenerateStats stats;
    auto g = generateScene("A snowman with three stacked spheres, red round nose and a top "
                           "black hat",
                           options, &stats);
    ASSERT_TRUE(g) << g.error().str();
    EXPECT_GE(g->scene.nodes.size(), 4u);
    std::printf("live: %s, %d answers, %llu + %llu tokens, %.1f s\n",
                std::string(outputModeName(stats.mode)).c_str(), stats.answers,
                static_cast<unsigned long long>(stats.promptTokens),
                static_cast<unsigned long long>(stats.completionTokens), stats.seconds);
}
