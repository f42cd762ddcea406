// A blocking HTTP POST through libcurl, for the language model client (llm_generate.cpp).
// Proxies come from HttpPost::proxy, or else from the standard variables (http_proxy,
// https_proxy, no_proxy), as libcurl reads them by default.
#pragma once

#include "sdfcsg/error.h"

#include <functional>
#include <optional>
#include <string>

namespace sdfcsg::detail {

struct HttpPost {
    std::string url;
    std::string shownUrl; // the URL in messages: url with any credential in it redacted
    std::string body;     // JSON
    std::string apiKey;   // sent as "Authorization: Bearer KEY" when not empty, nowhere else
    double timeoutSeconds = 300;
    double connectTimeoutSeconds = 15;
    size_t maxResponseBytes = 16u << 20; // a longer answer is cut off with an error
    std::optional<std::string> proxy;    // LlmConfig::proxy
    // Called about four times a second while the answer is awaited, with the seconds elapsed.
    std::function<void(double)> tick;
    // Asked as often as libcurl reports progress (about once a second while nothing arrives);
    // true aborts the transfer with an error of kind Cancelled.
    std::function<bool()> cancelled;
};

struct HttpResponse {
    long status = 0;
    std::string body;
    std::string retryAfter; // the Retry-After header, if any
};

// Any HTTP status is a response; only transport failures (no connection, timeout, oversize
// answer) are errors, of kind Remote, naming shownUrl, and a cancel (kind Cancelled).
Result<HttpResponse> httpPost(const HttpPost& post);

} // namespace sdfcsg::detail
