#include "llm/llm_http.h"

#include <curl/curl.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cstdio>
#include <memory>
#include <mutex>

namespace sdfcsg::detail {
namespace {

struct Transfer {
    const HttpPost* post;
    HttpResponse response;
    bool tooLarge = false;
    bool cancelled = false;
    std::chrono::steady_clock::time_point start = std::chrono::steady_clock::now();
    std::chrono::steady_clock::time_point lastTick = start;
};

size_t onBody(char* data, size_t size, size_t count, void* user) {
    auto* t = static_cast<Transfer*>(user);
    const size_t n = size * count;
    if (t->response.body.size() + n > t->post->maxResponseBytes) {
        t->tooLarge = true;
        return 0; // aborts the transfer
    }
    t->response.body.append(data, n);
    return n;
}

size_t onHeader(char* data, size_t size, size_t count, void* user) {
    auto* t = static_cast<Transfer*>(user);
    const size_t n = size * count;
    std::string line(data, n);
    // A new status line (after a redirect or "100 Continue") starts a new header block.
    if (line.starts_with("HTTP/")) t->response.retryAfter.clear();
    constexpr std::string_view kName = "retry-after:";
    if (line.size() > kName.size() &&
        std::equal(kName.begin(), kName.end(), line.begin(), [](char a, char b) {
            return a == std::tolower(static_cast<unsigned char>(b));
        })) {
        std::string value = line.substr(kName.size());
        auto blank = [](unsigned char c) { return std::isspace(c) != 0; };
        value.erase(value.begin(), std::find_if_not(value.begin(), value.end(), blank));
        value.erase(std::find_if_not(value.rbegin(), value.rend(), blank).base(), value.end());
        t->response.retryAfter = value;
    }
    return n;
}

int onProgress(void* user, curl_off_t, curl_off_t, curl_off_t, curl_off_t) {
    auto* t = static_cast<Transfer*>(user);
    auto now = std::chrono::steady_clock::now();
    if (t->post->tick && now - t->lastTick >= std::chrono::milliseconds(250)) {
        t->lastTick = now;
        t->post->tick(std::chrono::duration<double>(now - t->start).count());
    }
    t->cancelled = t->post->cancelled && t->post->cancelled();
    return t->cancelled ? 1 : 0; // non-zero aborts the transfer
}

struct CurlDeleter {
    void operator()(CURL* c) const { curl_easy_cleanup(c); }
};
struct ListDeleter {
    void operator()(curl_slist* l) const { curl_slist_free_all(l); }
};

long milliseconds(double seconds) {
    return std::max(1L, static_cast<long>(seconds * 1000.0));
}

} // namespace

Result<HttpResponse> httpPost(const HttpPost& post) {
    static std::once_flag init;
    std::call_once(init, [] { curl_global_init(CURL_GLOBAL_DEFAULT); });
    auto fail = [&](std::string message) {
        return Error::message(ErrorKind::Remote, post.shownUrl, std::move(message));
    };

    std::unique_ptr<CURL, CurlDeleter> curl(curl_easy_init());
    if (!curl) return fail("cannot start an HTTP request (libcurl failed to initialise)");
    curl_slist* raw = nullptr;
    raw = curl_slist_append(raw, "Content-Type: application/json");
    raw = curl_slist_append(raw, "Accept: application/json");
    raw = curl_slist_append(raw, "Expect:"); // no 100-continue round trip before the body
    std::unique_ptr<curl_slist, ListDeleter> headers(raw);
    if (!post.apiKey.empty()) {
        std::string auth = "Authorization: Bearer " + post.apiKey;
        headers.reset(curl_slist_append(headers.release(), auth.c_str()));
    }

    Transfer transfer{&post};
    char errorText[CURL_ERROR_SIZE] = {};
    CURL* c = curl.get();
    curl_easy_setopt(c, CURLOPT_URL, post.url.c_str());
    curl_easy_setopt(c, CURLOPT_POST, 1L);
    curl_easy_setopt(c, CURLOPT_POSTFIELDS, post.body.data());
    curl_easy_setopt(c, CURLOPT_POSTFIELDSIZE_LARGE, static_cast<curl_off_t>(post.body.size()));
    curl_easy_setopt(c, CURLOPT_HTTPHEADER, headers.get());
    curl_easy_setopt(c, CURLOPT_USERAGENT, "sdfcsg");
    curl_easy_setopt(c, CURLOPT_ACCEPT_ENCODING, ""); // whatever libcurl can decode
    curl_easy_setopt(c, CURLOPT_NOSIGNAL, 1L);        // timeouts without SIGALRM (threads)
    curl_easy_setopt(c, CURLOPT_TIMEOUT_MS, milliseconds(post.timeoutSeconds));
    curl_easy_setopt(c, CURLOPT_CONNECTTIMEOUT_MS, milliseconds(post.connectTimeoutSeconds));
    curl_easy_setopt(c, CURLOPT_ERRORBUFFER, errorText);
    curl_easy_setopt(c, CURLOPT_WRITEFUNCTION, onBody);
    curl_easy_setopt(c, CURLOPT_WRITEDATA, &transfer);
    curl_easy_setopt(c, CURLOPT_HEADERFUNCTION, onHeader);
    curl_easy_setopt(c, CURLOPT_HEADERDATA, &transfer);
    curl_easy_setopt(c, CURLOPT_XFERINFOFUNCTION, onProgress);
    curl_easy_setopt(c, CURLOPT_XFERINFODATA, &transfer);
    curl_easy_setopt(c, CURLOPT_NOPROGRESS, 0L);
    // An empty string turns the proxy variables off as well.
    if (post.proxy) curl_easy_setopt(c, CURLOPT_PROXY, post.proxy->c_str());

    const CURLcode code = curl_easy_perform(c);
    if (transfer.cancelled) return Error::message(ErrorKind::Cancelled, post.shownUrl, "cancelled");
    if (transfer.tooLarge)
        return fail("the answer exceeds the limit of " + std::to_string(post.maxResponseBytes) +
                    " bytes");
    if (code == CURLE_OPERATION_TIMEDOUT) {
        char seconds[32];
        std::snprintf(seconds, sizeof seconds, "%g", post.timeoutSeconds);
        return fail(std::string("no complete answer within ") + seconds +
                    " s (the request timeout)");
    }
    if (code != CURLE_OK) {
        std::string detail = errorText[0] ? errorText : curl_easy_strerror(code);
        return fail("request failed: " + detail);
    }
    curl_easy_getinfo(c, CURLINFO_RESPONSE_CODE, &transfer.response.status);
    return std::move(transfer.response);
}

} // namespace sdfcsg::detail
