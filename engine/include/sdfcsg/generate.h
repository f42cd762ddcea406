// sdfcsg: scenes from plain language, through any OpenAI-compatible endpoint or Ollama.
//
// generateScene() sends a prompt made from the node kind table (the grammar, every kind with its
// units and defaults, composition rules, and examples taken from the bundled scenes), asks for
// structured output where the server offers it, and validates the answer with parseScene(), the
// same validator as for files. When the answer does not load, the validator's exact list of
// problems goes back into the conversation with a request for a corrected scene, for a number of
// rounds. A scene that does not load is never returned.
//
// Model output is untrusted: it is parsed under Limits (size, node count, nesting) as an
// untrusted scene (SceneFiles, sdfcsg/scene.h): it may name font families but no file, and its
// problems say nothing about the file system, so an answer cannot make the program write
// anything, nor learn what the machine holds. The API key is
// sent in the Authorization header only; it is never printed, logged or recorded, and where a
// server echoes it or a model repeats it, messages, recordings and scenes say "[redacted]". A
// credential typed into the base URL (user information, query values) is redacted the same way.
#pragma once

#include "sdfcsg/error.h"
#include "sdfcsg/scene.h"

#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace sdfcsg {

enum class LlmApi {
    Auto,   // Ollama's native API when the base URL's port is 11434, else OpenAI's
    OpenAI, // POST {base}/chat/completions (OpenAI, llama.cpp server, vLLM, ...)
    Ollama, // POST {base}/api/chat; its OpenAI-compatible endpoint cuts prompts at 2048 tokens
};

// How the answer is asked for. Generation starts with JsonSchema and falls back when the server
// rejects it: to JsonObject (any JSON), then to Text (code fences and <think> blocks stripped).
enum class OutputMode { JsonSchema, JsonObject, Text };
std::string_view outputModeName(OutputMode mode); // "json_schema", "json_object", "text"

struct LlmConfig {
    std::string baseUrl; // e.g. "https://api.openai.com/v1", "http://localhost:11434"
    std::string apiKey;  // may be empty (local servers)
    std::string model;   // empty: "gpt-4o-mini" on api.openai.com, an error elsewhere
    LlmApi api = LlmApi::Auto;
    double timeoutSeconds = 300; // per request, the whole answer included
    double connectTimeoutSeconds = 15;
    int maxRetries = 4;               // on HTTP 429 and 5xx
    double retryBaseSeconds = 1;      // back-off before the first retry, doubled for each next
    double maxRetryDelaySeconds = 60; // caps Retry-After and the back-off
    uint32_t maxTokens = 8192;        // answer length limit
    std::optional<float> temperature = 0.2f; // unset: the server's default
    uint32_t contextTokens = 16384; // Ollama's options.num_ctx (its default is far too small)
    // A longer HTTP answer is cut off with a Remote error. generateScene() stops at four times
    // GenerateOptions::limits.maxFileBytes if that is less (4 MiB for its default limits).
    size_t maxResponseBytes = 16u << 20;
    // The proxy of every request, as libcurl takes it ("http://proxy.example:3128"); empty: none.
    // Unset: libcurl's environment variables (http_proxy, https_proxy, all_proxy, no_proxy),
    // which libcurl reads at each request.
    std::optional<std::string> proxy;
};

// Settings from environment variables: OPENAI_BASE_URL and OPENAI_API_KEY, overridden by
// SDFCSG_LLM_BASE_URL, SDFCSG_LLM_API_KEY and SDFCSG_LLM_MODEL; SDFCSG_LLM_API ("openai" or
// "ollama") forces the API. The base URL defaults to https://api.openai.com/v1. `lookup` gives a
// variable's value, or null where it is unset; left empty, the process's environment is read
// (std::getenv), when this is called: the tools call it once, as they start.
LlmConfig llmConfigFromEnvironment(const std::function<const char*(const char* name)>& lookup = {});

// Where generateScene() sends its requests: the URL, the API and the model, defaults applied.
// A query in the base URL ("?key=...") ends every URL made from it. `url` holds whatever
// credential was typed into the base URL ("https://user:KEY@host/", "?key=KEY"); `shownUrl` is
// the same URL with those parts "[redacted]", for people, and the one that messages name.
// Errors: Usage (no model, a base URL that is not http(s)).
struct LlmEndpoint {
    std::string url;
    std::string shownUrl;
    LlmApi api = LlmApi::OpenAI;
    std::string model;
};
Result<LlmEndpoint> llmEndpoint(const LlmConfig& config);

// One HTTP exchange, as recorded and replayed. It holds no headers, and the API key is redacted
// from what it holds (a server may echo the key in a body).
struct HttpExchange {
    std::string url;
    std::string request; // request body
    long status = 0;
    std::string retryAfter; // the response's Retry-After header, if any
    std::string response;   // response body
};
// A recording as JSON ({"version": 1, "exchanges": [...]}), and back.
std::string recordingToJson(std::span<const HttpExchange> exchanges);
Result<std::vector<HttpExchange>> parseRecording(std::string_view json,
                                                 std::string_view file = "<recording>");

struct GenerateProgress {
    std::string message;  // "asking gpt-4o (json_schema)", "HTTP 429; retrying in 2 s", ...
    double seconds = 0;   // time since the current request was sent
    bool waiting = false; // a periodic update while an answer is awaited (message unchanged)
};

struct GenerateOptions {
    LlmConfig llm;
    int maxRepairs = 3; // correction rounds after the first answer
    OutputMode firstMode = OutputMode::JsonSchema;
    // Applied to every answer. Tighter than for files: a generated scene is small.
    Limits limits{1u << 20, 2048, 32};
    // Non-empty: the JSON of a scene to change (`sdfcsg edit`); the request says how.
    std::string currentScene;
    std::function<void(const GenerateProgress&)> progress;
    // Asked on the generating thread before each request, during each wait between retries,
    // and about once a second while an answer is awaited (the transfer is then aborted); true
    // stops generation with ErrorKind::Cancelled ("cancelled"). It must be quick and must not
    // block: typically it reads a flag that a Cancel button sets on another thread.
    std::function<bool()> cancelled;
    // Waits between retries; unset: the calling thread sleeps, asking `cancelled` as it goes.
    // Tests pass their own (then `cancelled` is asked after the wait).
    std::function<void(double seconds)> sleep;
    std::vector<HttpExchange>* record = nullptr;       // every exchange is appended here
    const std::vector<HttpExchange>* replay = nullptr; // answers from here, in order; no network
};

struct GenerateStats {
    OutputMode mode = OutputMode::JsonSchema; // the mode of the last request
    int requests = 0;                         // HTTP requests, retries and resends included
    int answers = 0; // answers received: the first, then one per repair round
    bool firstTryValid = false;
    bool valid = false;
    uint64_t promptTokens = 0, completionTokens = 0; // summed, as the server reports them
    double seconds = 0;
};

struct Generated {
    Scene scene;
    std::string json;                 // toJson(scene): what `sdfcsg generate` writes
    std::vector<Diagnostic> warnings; // sceneSanityWarnings(scene)
};

// Asks the model for a scene matching `request` (or, with options.currentScene, for that scene
// changed as `request` says). Blocks until done: callers with a window run it on a thread (the
// viewer's GenerateWorker). Errors: Usage (no model, bad URL, no API key for api.openai.com
// outside a replay), Remote (HTTP and network failures, refusals, answers cut off at the token
// limit), Validation (no answer loaded within options.maxRepairs rounds; the diagnostics are the
// last answer's problems), Cancelled (options.cancelled said so). `stats`, when given, is filled in
// either case.
Result<Generated> generateScene(std::string_view request, const GenerateOptions& options,
                                GenerateStats* stats = nullptr);

// One line for people: "8 nodes, valid after 1 repair round (json_schema, 2 requests,
// 8000 + 600 tokens, 4.2 s)".
std::string generationSummary(const Generated& generated, const GenerateStats& stats);

// The system prompt: the format reference, the composition rules and the examples.
std::string sceneSystemPrompt();
// The requests that the system prompt's examples answer (each example scene's description), in
// order. A request close to one of them is no fair test of the model (`sdfcsg eval-prompts`).
std::vector<std::string> sceneExampleRequests();
// The first user message for a request (and, when editing, the current scene).
std::string sceneUserPrompt(std::string_view request, std::string_view currentScene = {});
// The message that asks for a corrected scene, quoting the validator's problems.
std::string sceneRepairPrompt(const Error& problems);

// The scene JSON Schema in the form that strict structured output accepts (OpenAI's strict
// json_schema; Ollama's format), derived from sceneJsonSchema(): every object lists all its
// keys as required and allows no others, optional keys are nullable instead (null members are
// dropped before validation), oneOf becomes anyOf, const becomes enum, and value bounds
// (minimum, minItems, pattern, defaults, ...) are left to the validator. Compact JSON.
std::string sceneLlmSchema();

// The first request generateScene() would send, for --dry-run: the URL (and as LlmEndpoint
// shows it) and the body.
struct LlmRequest {
    std::string url;
    std::string shownUrl;
    std::string body;
};
Result<LlmRequest> firstLlmRequest(std::string_view request, const GenerateOptions& options);

// The JSON object in a model's answer: <think>...</think> blocks and text around a fenced code
// block or around the outermost braces removed.
std::string extractJson(std::string_view answer);

// Cheap geometric checks of a valid scene: an empty solid, a difference that removes nothing,
// parts of the top-level union that touch none of the others, absurd bounds. Each names the
// node's JSON path.
std::vector<Diagnostic> sceneSanityWarnings(const Scene& scene);

} // namespace sdfcsg
