// The conversation with a language model: request bodies for OpenAI Chat Completions and
// Ollama's native /api/chat, the answers' shapes, retries and the known 400s, output mode
// fallbacks, and the repair loop around parseScene().
#include "sdfcsg/generate.h"

#include "llm/llm_http.h"
#include "scene/json_writer.h"
#include "scene/parse_util.h"

#include <simdjson.h>

#include <curl/curl.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <thread>

namespace sdfcsg {
namespace {

using detail::asArray;
using detail::asObject;
using detail::formatFloat;
using detail::formatNumber;
using detail::jsonQuote;
using detail::printable;
namespace dom = simdjson::dom;
using Clock = std::chrono::steady_clock;

constexpr std::string_view kAnswerFile = "answer";
// An HTTP answer holds one scene, escaped as a JSON string (quotes and newlines double), and
// perhaps the model's reasoning: four times the scene limit leaves room for both, and a server
// cannot make a client whose scenes are limited to 1 MiB read 16 MiB.
constexpr size_t kResponsesPerScene = 4;
// How much of an oversized answer goes back in a repair round.
constexpr size_t kEchoExcerpt = 1000;

struct Message {
    std::string role;
    std::string content;
};

// What the server has shown it accepts; each rejection is answered once.
struct RequestState {
    OutputMode mode = OutputMode::JsonSchema;
    bool maxCompletionTokens = false; // newer OpenAI models refuse max_tokens
    bool temperature = true;          // reasoning models refuse any but the default
};

std::string seconds(double s) {
    char text[32];
    std::snprintf(text, sizeof text, "%g", std::round(s * 10.0) / 10.0);
    return text;
}

// "1 request", "2 requests".
std::string counted(size_t n, std::string_view noun) {
    return std::to_string(n) + " " + std::string(noun) + (n == 1 ? "" : "s");
}

// The first `size` bytes of `text` or a little fewer, cut between UTF-8 sequences.
std::string_view head(std::string_view text, size_t size) {
    if (text.size() <= size) return text;
    while (size > 0 && (static_cast<unsigned char>(text[size]) & 0xC0) == 0x80)
        --size;
    return text.substr(0, size);
}

Error remote(const std::string& url, std::string message) {
    return Error::message(ErrorKind::Remote, url, std::move(message));
}

// The same error as an aborted transfer's (llm_http.cpp), whenever the request is stopped.
Error cancelledAt(const std::string& url) {
    return Error::message(ErrorKind::Cancelled, url, "cancelled");
}

// host:port of a URL, for Ollama's default port.
int urlPort(std::string_view url) {
    size_t scheme = url.find("://");
    std::string_view rest = scheme == std::string_view::npos ? url : url.substr(scheme + 3);
    rest = rest.substr(0, rest.find('/'));
    if (rest.starts_with('[')) rest = rest.substr(std::min(rest.find(']'), rest.size())); // IPv6
    size_t colon = rest.rfind(':');
    if (colon == std::string_view::npos) return url.starts_with("https") ? 443 : 80;
    return std::atoi(std::string(rest.substr(colon + 1)).c_str());
}

// Servers quote what they received; an API key must not reach a terminal or a log that way.
std::string redactKey(std::string text, const std::string& key) {
    if (key.size() >= 4)
        for (size_t at; (at = text.find(key)) != std::string::npos;)
            text.replace(at, key.size(), "[redacted]");
    // OpenAI quotes a masked key ("sk-proj-****...AbCd") in its 401 message.
    for (size_t at = 0; (at = text.find("sk-", at)) != std::string::npos;) {
        if (at > 0 && !std::isspace(static_cast<unsigned char>(text[at - 1]))) {
            at += 3;
            continue;
        }
        // Key characters only, so that a key quoted in JSON leaves the quotes and braces intact.
        size_t end = at;
        while (end < text.size() && (std::isalnum(static_cast<unsigned char>(text[end])) ||
                                     text[end] == '-' || text[end] == '_' || text[end] == '*'))
            ++end;
        text.replace(at, end - at, "[redacted]");
        at += 10;
    }
    return text;
}

// A part of a base URL that may hold a credential, as it appears there, and what shows instead.
struct UrlSecret {
    std::string text, shown;
};

// A key typed into the base URL: its user information ("https://user:KEY@host") and its query's
// values ("?key=KEY"), each in its context ("user:KEY@", "key=KEY") and, where a server may quote
// it alone, bare (from 4 characters: shorter ones would blank out unrelated text). Compound
// forms first, so that they are replaced whole.
std::vector<UrlSecret> urlSecrets(std::string_view url) {
    std::vector<UrlSecret> compound, bare;
    auto addBare = [&](std::string_view part) {
        if (part.size() >= 4) bare.push_back({std::string(part), "[redacted]"});
    };
    const size_t scheme = url.find("://");
    const size_t start = scheme == std::string_view::npos ? 0 : scheme + 3;
    const size_t end = std::min(url.find_first_of("/?#", start), url.size());
    if (const size_t at = url.substr(start, end - start).rfind('@'); at != std::string_view::npos) {
        const std::string_view info = url.substr(start, at);
        compound.push_back({std::string(info) + "@", "[redacted]@"});
        const size_t colon = info.find(':');
        addBare(info.substr(0, colon));
        if (colon != std::string_view::npos) addBare(info.substr(colon + 1));
    }
    if (const size_t q = url.find('?', end); q != std::string_view::npos) {
        std::string_view query = url.substr(q + 1);
        query = query.substr(0, query.find('#'));
        while (!query.empty()) {
            const std::string_view piece = query.substr(0, query.find('&'));
            query.remove_prefix(std::min(query.size(), piece.size() + 1));
            const size_t eq = piece.find('=');
            if (eq == std::string_view::npos) {
                addBare(piece);
            } else if (eq + 1 < piece.size()) {
                compound.push_back(
                    {std::string(piece), std::string(piece.substr(0, eq)) + "=[redacted]"});
                addBare(piece.substr(eq + 1));
            }
        }
    }
    compound.insert(compound.end(), bare.begin(), bare.end());
    return compound;
}

// The API key and any credential in the base URL, wherever a message, a recording or a scene
// would carry them.
std::string redact(std::string text, const LlmConfig& config) {
    text = redactKey(std::move(text), config.apiKey);
    for (const UrlSecret& s : urlSecrets(config.baseUrl))
        for (size_t at = 0; (at = text.find(s.text, at)) != std::string::npos; at += s.shown.size())
            text.replace(at, s.text.size(), s.shown);
    return text;
}

bool isOpenAi(std::string_view url) {
    return url.find("://api.openai.com") != std::string_view::npos;
}

Result<LlmEndpoint> resolve(const LlmConfig& config) {
    std::string base = config.baseUrl.empty() ? "https://api.openai.com/v1" : config.baseUrl;
    // A query (?key=...) stays at the end of every URL made from the base; a fragment is never
    // sent.
    std::string query;
    if (const size_t q = base.find_first_of("?#"); q != std::string::npos) {
        if (base[q] == '?') query = base.substr(q, base.find('#', q) - q);
        base.resize(q);
    }
    while (base.ends_with('/'))
        base.pop_back();
    if (!base.starts_with("http://") && !base.starts_with("https://"))
        return Error::message(ErrorKind::Usage, "<llm>",
                              "the base URL must start with http:// or https://, got " +
                                  detail::quote(redact(base + query, config)));
    LlmEndpoint e;
    e.api = config.api != LlmApi::Auto ? config.api
            : urlPort(base) == 11434   ? LlmApi::Ollama
                                       : LlmApi::OpenAI;
    if (e.api == LlmApi::Ollama) {
        // Ollama's OpenAI-compatible /v1 silently cuts prompts at 2048 tokens: use /api/chat.
        for (std::string_view suffix : {"/v1", "/api"})
            if (base.ends_with(suffix)) base.resize(base.size() - suffix.size());
        e.url = base + "/api/chat" + query;
    } else {
        e.url = base + "/chat/completions" + query;
    }
    e.shownUrl = redact(e.url, config);
    e.model = config.model;
    if (e.model.empty()) {
        if (!isOpenAi(base))
            return Error::message(ErrorKind::Usage, "<llm>",
                                  "no model given: set SDFCSG_LLM_MODEL or pass --model");
        e.model = "gpt-4o-mini";
    }
    return e;
}

std::string messagesJson(const std::vector<Message>& messages) {
    std::string out = "[";
    for (const Message& m : messages) {
        if (out.size() > 1) out += ",";
        out += R"({"role":)" + jsonQuote(m.role) + R"(,"content":)" + jsonQuote(m.content) + "}";
    }
    return out + "]";
}

std::string requestBody(const LlmEndpoint& e, const LlmConfig& config,
                        const std::vector<Message>& messages, const RequestState& state) {
    std::string out =
        R"({"model":)" + jsonQuote(e.model) + R"(,"messages":)" + messagesJson(messages);
    if (e.api == LlmApi::Ollama) {
        out += R"(,"stream":false)";
        if (state.mode == OutputMode::JsonSchema) out += R"(,"format":)" + sceneLlmSchema();
        if (state.mode == OutputMode::JsonObject) out += R"(,"format":"json")";
        out += R"(,"options":{"num_ctx":)" + std::to_string(config.contextTokens) +
               R"(,"num_predict":)" + std::to_string(config.maxTokens);
        if (config.temperature && state.temperature)
            out += R"(,"temperature":)" + formatFloat(*config.temperature);
        return out + "}}";
    }
    if (config.temperature && state.temperature)
        out += R"(,"temperature":)" + formatFloat(*config.temperature);
    out += state.maxCompletionTokens ? R"(,"max_completion_tokens":)" : R"(,"max_tokens":)";
    out += std::to_string(config.maxTokens);
    if (state.mode == OutputMode::JsonSchema)
        out += R"(,"response_format":{"type":"json_schema","json_schema":{"name":"sdfcsg_scene",)"
               R"("strict":true,"schema":)" +
               sceneLlmSchema() + "}}";
    if (state.mode == OutputMode::JsonObject) out += R"(,"response_format":{"type":"json_object"})";
    return out + "}";
}

// Servers put the reason for an error in different places: OpenAI and llama.cpp in
// error.message (OpenAI also names the parameter in error.param), Ollama in error, vLLM in
// message.
struct ServerError {
    std::string message;
    std::string param;
    std::string code;
};

ServerError serverError(std::string_view body) {
    ServerError out;
    dom::parser parser;
    dom::element top;
    if (parser.parse(body.data(), body.size()).get(top) || !top.is_object()) {
        out.message = head(body, 300);
        return out;
    }
    std::string_view text;
    dom::element error;
    if (!top["error"].get(error)) {
        if (!error.get(text)) {
            out.message = text;
        } else if (error.is_object()) {
            if (!error["message"].get(text)) out.message = text;
            if (!error["param"].get(text)) out.param = text;
            if (!error["code"].get(text)) out.code = text;
        }
    } else if (!top["message"].get(text)) {
        out.message = text;
        if (!top["param"].get(text)) out.param = text;
    }
    if (out.message.empty()) out.message = head(body, 300);
    return out;
}

// The strings of a loaded scene. The answer's text was redacted before it was parsed, but a key
// written with JSON escapes ("\u0073k-...") reads back as the key itself.
void redactStrings(Scene& scene, const LlmConfig& key) {
    scene.name = redact(std::move(scene.name), key);
    scene.description = redact(std::move(scene.description), key);
    for (Node& node : scene.nodes)
        node.name = redact(std::move(node.name), key);
}

// Seconds to wait for a Retry-After value: delta-seconds, or an HTTP date.
std::optional<double> retryAfterSeconds(const std::string& value) {
    if (value.empty()) return std::nullopt;
    char* end = nullptr;
    double s = std::strtod(value.c_str(), &end);
    if (end != value.c_str() && *end == '\0' && s >= 0.0 && std::isfinite(s)) return s;
    time_t when = curl_getdate(value.c_str(), nullptr);
    if (when < 0) return std::nullopt;
    return std::max(0.0, std::difftime(when, std::time(nullptr)));
}

struct Answer {
    std::string content;
    std::string finishReason;
    std::string refusal;
    uint64_t promptTokens = 0, completionTokens = 0;
};

Result<Answer> readAnswer(const LlmEndpoint& e, std::string_view body, const LlmConfig& key) {
    dom::parser parser;
    dom::element top;
    auto unexpected = [&](const std::string& what) {
        return remote(e.shownUrl, "unexpected answer (" + what +
                                      "): " + printable(redact(std::string(head(body, 200)), key)));
    };
    if (parser.parse(body.data(), body.size()).get(top) || !top.is_object())
        return unexpected("not a JSON object");
    Answer a;
    std::string_view text;
    uint64_t count = 0;
    dom::element message;
    if (e.api == LlmApi::Ollama) {
        if (top["message"].get(message) || !message.is_object())
            return unexpected("no \"message\"");
        if (!top["done_reason"].get(text)) a.finishReason = text;
        if (!top["prompt_eval_count"].get(count)) a.promptTokens = count;
        if (!top["eval_count"].get(count)) a.completionTokens = count;
    } else {
        dom::element choices, choice;
        if (top["choices"].get(choices) || !choices.is_array() ||
            asArray(choices).at(0).get(choice) || choice["message"].get(message))
            return unexpected("no \"choices[0].message\"");
        if (!choice["finish_reason"].get(text)) a.finishReason = text;
        if (!top["usage"]["prompt_tokens"].get(count)) a.promptTokens = count;
        if (!top["usage"]["completion_tokens"].get(count)) a.completionTokens = count;
    }
    if (!message["content"].get(text)) a.content = text;
    if (!message["refusal"].get(text)) a.refusal = text;
    return a;
}

// Drops object members whose value is null: the strict schema makes optional keys nullable,
// and null is never a valid value in a scene. Text that is not JSON is returned unchanged, for
// the parser to report with line and column.
void writeWithoutNulls(std::string& out, dom::element e) {
    switch (e.type()) {
    case dom::element_type::OBJECT: {
        out += '{';
        bool first = true;
        for (auto [key, value] : asObject(e)) {
            if (value.is_null()) continue;
            if (!first) out += ',';
            first = false;
            out += jsonQuote(key) + ":";
            writeWithoutNulls(out, value);
        }
        out += '}';
        break;
    }
    case dom::element_type::ARRAY: {
        out += '[';
        bool first = true;
        for (dom::element item : asArray(e)) {
            if (!first) out += ',';
            first = false;
            writeWithoutNulls(out, item);
        }
        out += ']';
        break;
    }
    case dom::element_type::STRING:
        out += jsonQuote(e.get_string().value_unsafe());
        break;
    case dom::element_type::INT64:
        out += std::to_string(e.get_int64().value_unsafe());
        break;
    case dom::element_type::UINT64:
        out += std::to_string(e.get_uint64().value_unsafe());
        break;
    case dom::element_type::DOUBLE:
        out += formatNumber(e.get_double().value_unsafe());
        break;
    case dom::element_type::BOOL:
        out += e.get_bool().value_unsafe() ? "true" : "false";
        break;
    case dom::element_type::NULL_VALUE:
        out += "null";
        break;
    }
}

std::string withoutNulls(const std::string& text, const Limits& limits) {
    if (text.size() > limits.maxFileBytes || text.find("null") == std::string::npos) return text;
    dom::parser parser;
    // Recursion in writeWithoutNulls is bounded by this depth (about two levels per operation).
    if (parser.allocate(std::max<size_t>(text.size(), 64), 2 * size_t(limits.maxDepth) + 16))
        return text;
    dom::element top;
    if (parser.parse(text).get(top)) return text;
    std::string out;
    writeWithoutNulls(out, top);
    return out;
}

// The HTTP answer limit: LlmConfig::maxResponseBytes, or less where the scene limit is small.
size_t responseLimit(const GenerateOptions& options) {
    const size_t scene = options.limits.maxFileBytes;
    if (scene > SIZE_MAX / kResponsesPerScene) return options.llm.maxResponseBytes;
    return std::min(options.llm.maxResponseBytes, kResponsesPerScene * scene);
}

// The assistant turn of a repair round. Every later request carries it again, so an answer
// larger than a scene may be (which the validator refused for its size alone) goes back as an
// excerpt: in full, a 10 MB answer made the three repair requests 10, 21 and 31 MB long.
std::string echoedAnswer(const std::string& content, const Limits& limits) {
    if (content.size() <= limits.maxFileBytes) return content;
    return std::string(head(content, kEchoExcerpt)) +
           "\n[the rest of this answer is left out: " + std::to_string(content.size()) +
           " bytes in all, more than a scene may have (" + std::to_string(limits.maxFileBytes) +
           ")]";
}

// One conversation: sends requests, retries, adapts to the server, counts.
class Conversation {
  public:
    Conversation(LlmEndpoint endpoint, const GenerateOptions& options, GenerateStats& stats)
        : e_(std::move(endpoint)), options_(options), stats_(stats) {
        state_.mode = options.firstMode;
    }

    Result<Answer> ask(const std::vector<Message>& messages, const std::string& what) {
        const LlmConfig& config = options_.llm;
        int retries = 0;
        for (;;) {
            if (cancelled()) return cancelledAt(e_.shownUrl);
            stats_.mode = state_.mode;
            const std::string body = requestBody(e_, config, messages, state_);
            const std::string status = what + " (" + std::string(outputModeName(state_.mode)) + ")";
            progress(status, 0.0, false);
            ++stats_.requests;
            auto response = exchange(body, status);
            if (!response) return response.error();
            const long code = response->status;
            if (code >= 200 && code < 300) return readAnswer(e_, response->body, config);

            const ServerError error = serverError(response->body);
            const std::string reason =
                "HTTP " + std::to_string(code) + ": " + printable(redact(error.message, config));
            if ((code == 429 && error.code != "insufficient_quota") || code >= 500) {
                if (retries >= config.maxRetries)
                    return remote(e_.shownUrl, reason + " (gave up after " +
                                                   counted(size_t(retries) + 1, "attempt") + ")");
                double delay = config.retryBaseSeconds * std::pow(2.0, retries);
                if (auto after = retryAfterSeconds(response->retryAfter)) delay = *after;
                delay = std::min(delay, config.maxRetryDelaySeconds);
                ++retries;
                progress(reason + "; retrying in " + seconds(delay) + " s (attempt " +
                             std::to_string(retries + 1) + " of " +
                             std::to_string(config.maxRetries + 1) + ")",
                         0.0, false);
                if (options_.replay == nullptr) wait(delay);
                continue;
            }
            if ((code == 400 || code == 422) && adapt(error)) continue;
            if (code == 401 || code == 403)
                return remote(e_.shownUrl,
                              reason + " (check SDFCSG_LLM_API_KEY or OPENAI_API_KEY)");
            if (code == 404)
                return remote(e_.shownUrl, reason + " (check the base URL and the model name)");
            return remote(e_.shownUrl, reason);
        }
    }

  private:
    // Answers a 400 that names something the server does not support, once each.
    bool adapt(const ServerError& error) {
        auto names = [&](std::string_view word) {
            return error.param == word || error.message.find(word) != std::string::npos;
        };
        if (e_.api == LlmApi::OpenAI && !state_.maxCompletionTokens && names("max_tokens")) {
            state_.maxCompletionTokens = true;
            progress("the server refuses max_tokens; resending with max_completion_tokens", 0.0,
                     false);
            return true;
        }
        if (state_.temperature && options_.llm.temperature && names("temperature")) {
            state_.temperature = false;
            progress("the server refuses the temperature; resending without it", 0.0, false);
            return true;
        }
        const bool format = names("response_format") || names("json_schema") ||
                            names("json_object") || names("schema") ||
                            (e_.api == LlmApi::Ollama && names("format"));
        if (format && state_.mode != OutputMode::Text) {
            OutputMode next =
                state_.mode == OutputMode::JsonSchema ? OutputMode::JsonObject : OutputMode::Text;
            progress("the server rejects " + std::string(outputModeName(state_.mode)) +
                         " output; falling back to " + std::string(outputModeName(next)),
                     0.0, false);
            state_.mode = next;
            return true;
        }
        return false;
    }

    Result<detail::HttpResponse> exchange(const std::string& body, const std::string& status) {
        if (options_.replay) {
            if (replayed_ >= options_.replay->size())
                return remote(e_.shownUrl, "the recording holds " +
                                               counted(options_.replay->size(), "exchange") +
                                               ", and a further request was made");
            const HttpExchange& x = (*options_.replay)[replayed_++];
            if (options_.record) keep(x);
            return detail::HttpResponse{x.status, x.response, x.retryAfter};
        }
        detail::HttpPost post;
        post.url = e_.url;
        post.shownUrl = e_.shownUrl;
        post.body = body;
        post.apiKey = options_.llm.apiKey;
        post.timeoutSeconds = options_.llm.timeoutSeconds;
        post.connectTimeoutSeconds = options_.llm.connectTimeoutSeconds;
        post.proxy = options_.llm.proxy;
        post.maxResponseBytes = responseLimit(options_);
        post.tick = [&](double elapsed) { progress(status, elapsed, true); };
        post.cancelled = options_.cancelled;
        auto response = detail::httpPost(post);
        if (response && options_.record)
            keep({e_.url, body, response->status, response->retryAfter, response->body});
        return response;
    }

    // A recording is a file that gets shared: a key that the server echoed (in a 400 that
    // quotes the request's headers, say) or that the model repeated does not go into it.
    void keep(HttpExchange x) {
        const LlmConfig& key = options_.llm;
        x.url = redact(std::move(x.url), key);
        x.request = redact(std::move(x.request), key);
        x.retryAfter = redact(std::move(x.retryAfter), key);
        x.response = redact(std::move(x.response), key);
        options_.record->push_back(std::move(x));
    }

    bool cancelled() const { return options_.cancelled && options_.cancelled(); }

    // A back-off of up to a minute must not hold up a Cancel button.
    void wait(double delay) {
        if (options_.sleep) return options_.sleep(delay);
        const Clock::time_point end = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                                         std::chrono::duration<double>(delay));
        while (Clock::now() < end && !cancelled())
            std::this_thread::sleep_for(
                std::min<Clock::duration>(end - Clock::now(), std::chrono::milliseconds(50)));
    }

    void progress(const std::string& message, double elapsed, bool waiting) {
        if (options_.progress) options_.progress(GenerateProgress{message, elapsed, waiting});
    }

    LlmEndpoint e_;
    const GenerateOptions& options_;
    GenerateStats& stats_;
    RequestState state_;
    size_t replayed_ = 0;
};

std::vector<Message> firstMessages(std::string_view request, const GenerateOptions& options) {
    return {{"system", sceneSystemPrompt()},
            {"user", sceneUserPrompt(request, options.currentScene)}};
}

} // namespace

LlmConfig llmConfigFromEnvironment(const std::function<const char*(const char* name)>& lookup) {
    auto env = [&](const char* name) -> std::string {
        const char* v = lookup ? lookup(name) : std::getenv(name);
        return v ? v : "";
    };
    LlmConfig config;
    config.baseUrl = env("SDFCSG_LLM_BASE_URL");
    if (config.baseUrl.empty()) config.baseUrl = env("OPENAI_BASE_URL");
    if (config.baseUrl.empty()) config.baseUrl = "https://api.openai.com/v1";
    config.apiKey = env("SDFCSG_LLM_API_KEY");
    if (config.apiKey.empty()) config.apiKey = env("OPENAI_API_KEY");
    config.model = env("SDFCSG_LLM_MODEL");
    const std::string api = env("SDFCSG_LLM_API");
    if (api == "openai") config.api = LlmApi::OpenAI;
    if (api == "ollama") config.api = LlmApi::Ollama;
    return config;
}

Result<LlmEndpoint> llmEndpoint(const LlmConfig& config) {
    return resolve(config);
}

Result<LlmRequest> firstLlmRequest(std::string_view request, const GenerateOptions& options) {
    auto endpoint = resolve(options.llm);
    if (!endpoint) return endpoint.error();
    RequestState state;
    state.mode = options.firstMode;
    return LlmRequest{endpoint->url, endpoint->shownUrl,
                      requestBody(*endpoint, options.llm, firstMessages(request, options), state)};
}

namespace {

Result<Generated> generate(std::string_view request, const GenerateOptions& options,
                           GenerateStats* statsOut) {
    GenerateStats local;
    GenerateStats& stats = statsOut ? *statsOut : local;
    stats = GenerateStats{};
    const auto start = Clock::now();
    struct Timer { // stats.seconds on every way out
        GenerateStats& stats;
        Clock::time_point start;
        ~Timer() { stats.seconds = std::chrono::duration<double>(Clock::now() - start).count(); }
    } timer{stats, start};

    auto endpoint = resolve(options.llm);
    if (!endpoint) return endpoint.error();
    // OpenAI answers a request without a key with a 401 after a round trip; say at once what to
    // set.
    if (options.llm.apiKey.empty() && isOpenAi(endpoint->url) && options.replay == nullptr)
        return Error::message(ErrorKind::Usage, "<llm>",
                              "no API key for api.openai.com: set SDFCSG_LLM_API_KEY or "
                              "OPENAI_API_KEY, or point SDFCSG_LLM_BASE_URL (or --base-url) at "
                              "a server that needs no key");
    const std::string url = endpoint->shownUrl, model = endpoint->model;
    Conversation conversation(std::move(*endpoint), options, stats);
    std::vector<Message> messages = firstMessages(request, options);
    // The answers' problems go back to the model: they may tell nothing about this machine's
    // files (sdfcsg/scene.h, SceneFiles).
    ParseOptions untrusted;
    untrusted.limits = options.limits;
    untrusted.files.trusted = false;
    const int rounds = std::max(0, options.maxRepairs);

    for (int round = 0;; ++round) {
        const std::string what = round == 0
                                     ? "asking " + model
                                     : "asking " + model + " for a correction, round " +
                                           std::to_string(round) + " of " + std::to_string(rounds);
        auto answer = conversation.ask(messages, what);
        if (!answer) return answer.error();
        ++stats.answers;
        stats.promptTokens += answer->promptTokens;
        stats.completionTokens += answer->completionTokens;
        if (!answer->refusal.empty())
            return remote(url, "the model refused: " + printable(answer->refusal));
        if (answer->finishReason == "content_filter")
            return remote(url, "the server's content filter withheld the answer");
        if (answer->finishReason == "length")
            return remote(url, "the answer was cut off at the token limit (" +
                                   std::to_string(options.llm.maxTokens) +
                                   " tokens); ask for a simpler scene or raise the limit");

        // A model may repeat the key (a prompt injection may ask it to): it goes neither into
        // the scene nor back into the conversation.
        answer->content = redact(std::move(answer->content), options.llm);
        const std::string json = withoutNulls(extractJson(answer->content), options.limits);
        // Null content (or none, or not a string) would read as an empty scene file.
        auto scene =
            json.empty()
                ? Result<Scene>(Error::message(ErrorKind::Validation, std::string(kAnswerFile),
                                               "the model returned no text"))
                : parseScene(json, kAnswerFile, untrusted);
        if (scene) {
            stats.valid = true;
            stats.firstTryValid = round == 0;
            redactStrings(*scene, options.llm);
            Generated out;
            out.warnings = sceneSanityWarnings(*scene);
            out.json = toJson(*scene);
            out.scene = std::move(*scene);
            return out;
        }
        const Error& problems = scene.error();
        if (round >= rounds) {
            Error e = problems;
            e.kind = ErrorKind::Validation;
            e.diagnostics.insert(e.diagnostics.begin(),
                                 Diagnostic{std::string(kAnswerFile),
                                            {},
                                            "no answer loaded after " +
                                                counted(size_t(rounds), "repair round") +
                                                "; the last one's problems:"});
            return e;
        }
        if (options.progress)
            options.progress({"the answer does not load (" +
                                  counted(problems.diagnostics.size(), "problem") +
                                  "); asking for a correction",
                              0.0, false});
        messages.push_back({"assistant", echoedAnswer(answer->content, options.limits)});
        messages.push_back({"user", sceneRepairPrompt(problems)});
    }
}

} // namespace

// A server or a model may quote the key back, a hostile one on purpose (the fuzz target
// fuzz_llm found a body quoted in an error): nothing that leaves here carries it. Nor can
// remote text in a message drive the terminal it is printed on.
Result<Generated> generateScene(std::string_view request, const GenerateOptions& options,
                                GenerateStats* stats) {
    auto result = generate(request, options, stats);
    const LlmConfig& key = options.llm;
    auto clean = [&](std::vector<Diagnostic>& diagnostics) {
        for (Diagnostic& d : diagnostics) {
            d.path = printable(redact(std::move(d.path), key));
            d.message = printable(redact(std::move(d.message), key));
        }
    };
    if (result) {
        clean(result->warnings);
        return result;
    }
    Error error = result.error();
    clean(error.diagnostics);
    return error;
}

std::string generationSummary(const Generated& generated, const GenerateStats& stats) {
    const int repairs = stats.answers - 1;
    const std::string validity =
        stats.firstTryValid
            ? "valid on the first try"
            : "valid after " + counted(size_t(std::max(repairs, 0)), "repair round");
    char text[256];
    std::snprintf(text, sizeof text, "%s, %s (%.*s, %s, %llu + %llu tokens, %.1f s)",
                  counted(generated.scene.nodes.size(), "node").c_str(), validity.c_str(),
                  int(outputModeName(stats.mode).size()), outputModeName(stats.mode).data(),
                  counted(size_t(std::max(stats.requests, 0)), "request").c_str(),
                  static_cast<unsigned long long>(stats.promptTokens),
                  static_cast<unsigned long long>(stats.completionTokens), stats.seconds);
    return text;
}

std::string recordingToJson(std::span<const HttpExchange> exchanges) {
    detail::JsonWriter w;
    w.beginObject();
    w.key("version");
    w.number(1.0);
    w.key("exchanges");
    w.beginArray();
    for (const HttpExchange& x : exchanges) {
        w.beginObject();
        w.key("url");
        w.string(x.url);
        w.key("request");
        w.string(x.request);
        w.key("status");
        w.number(double(x.status));
        w.key("retry_after");
        w.string(x.retryAfter);
        w.key("response");
        w.string(x.response);
        w.endObject();
    }
    w.endArray();
    w.endObject();
    return w.finish();
}

Result<std::vector<HttpExchange>> parseRecording(std::string_view json, std::string_view file) {
    const std::string name(file);
    auto bad = [&](std::string path, std::string message) {
        return Error(ErrorKind::Validation, Diagnostic{name, std::move(path), std::move(message)});
    };
    dom::parser parser;
    dom::element top, list;
    if (parser.parse(json.data(), json.size()).get(top))
        return Error::message(ErrorKind::Syntax, name, "not valid JSON");
    int64_t version = 0;
    if (top["version"].get(version) || version != 1) return bad("version", "expected 1");
    if (top["exchanges"].get(list) || !list.is_array())
        return bad("exchanges", "expected an array");
    std::vector<HttpExchange> out;
    size_t i = 0;
    for (dom::element x : asArray(list)) {
        const std::string path = detail::item("exchanges", i++);
        HttpExchange e;
        std::string_view url, request, retryAfter, response;
        int64_t status = 0;
        if (x["url"].get(url) || x["request"].get(request) || x["status"].get(status) ||
            x["retry_after"].get(retryAfter) || x["response"].get(response))
            return bad(path, "expected an object with url, request, status, retry_after and "
                             "response");
        out.push_back({std::string(url), std::string(request), long(status),
                       std::string(retryAfter), std::string(response)});
    }
    return out;
}

} // namespace sdfcsg
